//! The photon simulation that fills the table: a pencil beam entering an isotropically
//! scattering half-space, traced in optical units (σt = 1) without absorption, with every exit
//! weighted by α^n for each tabulated albedo α (n the number of scattering events), which is
//! exact because absorption only thins a path's weight and never changes its geometry.
//!
//! The beam enters at the origin along −z (normal incidence, already refracted: the profile is
//! per unit power *entering* the medium). At the boundary z = 0 a photon leaving the medium is
//! reflected back with the dielectric Fresnel reflectance for internal incidence (η = n_medium
//! / n_outside), and otherwise exits and is tallied at its exit radius. Paths of more than
//! [`MAX_EVENTS`] scattering events are dropped; at the largest tabulated albedo their weight
//! is below e^{−2.5} and their share of paths about 1 %, so the bias is ≤ 0.1 % of the total
//! (the tests compare with Chandrasekhar's exact albedo).
//!
//! Determinism: photon `i` draws from its own SplitMix64 stream keyed by (seed, plane, i), and
//! photons are summed in fixed chunks merged in chunk order, so a tally is bit-identical for a
//! given seed and photon count whatever the number of threads.

use super::grid::{N_ALBEDO, N_BINS, albedo_of_row, bin_of};
use crate::fresnel::dielectric;

/// Most scattering events followed per photon.
pub const MAX_EVENTS: u32 = 100_000;
/// Photons per chunk (the unit of parallel work and of the summation order).
pub const CHUNK: u64 = 16_384;

/// Sums over photons for one η: per albedo row and radial bin, for single (n = 1) and multiple
/// (n ≥ 2) scattering, the sum of weights and of squared weights; plus totals including exits
/// beyond the last bin.
#[derive(Debug, Clone, PartialEq)]
pub struct Tally {
    /// Photons traced.
    pub photons: u64,
    /// `[kind][row][bin]` flattened: sums of α^n (kind 0 single, 1 multiple).
    pub sum: Vec<f64>,
    /// The same for (α^n)².
    pub sum2: Vec<f64>,
    /// `[kind][row]`: totals of α^n over every exit (inside or beyond the bins).
    pub total: Vec<f64>,
    /// `[kind][row]`: totals of (α^n)².
    pub total2: Vec<f64>,
    /// Photons dropped at [`MAX_EVENTS`].
    pub capped: u64,
}

impl Tally {
    fn new() -> Self {
        Self {
            photons: 0,
            sum: vec![0.0; 2 * N_ALBEDO * N_BINS],
            sum2: vec![0.0; 2 * N_ALBEDO * N_BINS],
            total: vec![0.0; 2 * N_ALBEDO],
            total2: vec![0.0; 2 * N_ALBEDO],
            capped: 0,
        }
    }

    /// Index of `(kind, row, bin)` in [`Tally::sum`].
    pub fn index(kind: usize, row: usize, bin: usize) -> usize {
        (kind * N_ALBEDO + row) * N_BINS + bin
    }

    fn merge(&mut self, o: &Tally) {
        self.photons += o.photons;
        self.capped += o.capped;
        add_into(&mut self.sum, &o.sum);
        add_into(&mut self.sum2, &o.sum2);
        add_into(&mut self.total, &o.total);
        add_into(&mut self.total2, &o.total2);
    }
}

/// `a[i] += b[i]` for every i: merging one chunk's sums into the running ones.
pub(crate) fn add_into(a: &mut [f64], b: &[f64]) {
    for (a, b) in a.iter_mut().zip(b) {
        *a += b;
    }
}

/// Calls `tally(row, w)` with the weight w = α_row^n = exp(n·ln α_row) of an exit after `n`
/// scattering events, for every albedo row whose weight is not 0 (`ln_alpha[row] = ln α_row`):
/// how one absorption-free path stands for every tabulated albedo.
#[inline]
pub(crate) fn for_each_row_weight(ln_alpha: &[f64], n: u32, mut tally: impl FnMut(usize, f64)) {
    for (row, la) in ln_alpha.iter().enumerate() {
        let w = (f64::from(n) * la).exp();
        if w != 0.0 {
            tally(row, w);
        }
    }
}

/// SplitMix64 (Steele, Lea & Flood 2014), one stream per photon.
pub(crate) struct Stream(u64);

impl Stream {
    /// A stream whose starting state is a hash of (seed, plane, photon): streams of different
    /// photons start at unrelated points of the generator's period (a state merely offset by
    /// the photon index would make photon i + 1 replay photon i's numbers shifted by one).
    pub(crate) fn new(seed: u64, plane: u64, photon: u64) -> Self {
        let key = mix(photon ^ mix(plane ^ mix(seed)));
        Stream(key)
    }
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in (0, 1].
    pub(crate) fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) + 1) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// The SplitMix64 output function: a bijective 64-bit mix.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The face a photon leaves through: the entry face z = 0 (reflection) or, in a slab, the
/// opposite face z = −d (transmission).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Face {
    /// The face the beam entered through.
    Entry,
    /// The slab's opposite face.
    Opposite,
}

/// Traces one photon in a medium bounded by z = 0 above and, for a slab, by z = −`thickness`
/// below (`f64::INFINITY` for the half-space); calls `exit(n, x, face)` with its number of
/// scattering events, exit radius and face. Returns false if it was capped. Both faces
/// reflect with the same dielectric Fresnel reflectance. For the half-space the random numbers
/// drawn are exactly those of the half-space-only version this generalises (the built-in
/// table stays reproducible).
pub(crate) fn trace(
    eta: f64,
    thickness: f64,
    rng: &mut Stream,
    mut exit: impl FnMut(u32, f64, Face),
) -> bool {
    trace_from([0.0, 0.0, -1.0], eta, thickness, rng, |n, x, face, _| {
        exit(n, x, face)
    })
}

/// [`trace`] for a photon that starts at the origin along the unit direction `dir` (already
/// refracted into the medium, pointing into it: `dir[2] < 0`); `exit` also receives the
/// cosine of the photon's direction with the face's normal, inside the medium, as it leaves.
pub(crate) fn trace_from(
    dir: [f64; 3],
    eta: f64,
    thickness: f64,
    rng: &mut Stream,
    mut exit: impl FnMut(u32, f64, Face, f64),
) -> bool {
    trace_at(
        dir,
        eta,
        thickness,
        MAX_EVENTS,
        rng,
        |n, [x, y], face, cos| exit(n, (x * x + y * y).sqrt(), face, cos),
    )
}

/// [`trace_from`] with the exit point's position `[x, y]` on the face instead of its radius
/// (the same random numbers) and at most `max_events` scattering events (a path with more is
/// dropped: false).
pub(crate) fn trace_at(
    dir: [f64; 3],
    eta: f64,
    thickness: f64,
    max_events: u32,
    rng: &mut Stream,
    mut exit: impl FnMut(u32, [f64; 2], Face, f64),
) -> bool {
    let (mut px, mut py, mut pz) = (0.0f64, 0.0f64, 0.0f64);
    let [mut dx, mut dy, mut dz] = dir;
    let mut n = 0u32;
    loop {
        let t = -rng.uniform().ln();
        let z_new = pz + t * dz;
        let face = if z_new >= 0.0 && dz > 0.0 {
            Some((Face::Entry, 0.0))
        } else if z_new <= -thickness && dz < 0.0 {
            Some((Face::Opposite, -thickness))
        } else {
            None
        };
        if let Some((face, z_face)) = face {
            // Reaches a boundary before the next collision.
            let tb = (z_face - pz) / dz;
            px += tb * dx;
            py += tb * dy;
            pz = z_face;
            if eta != 1.0 && rng.uniform() <= dielectric(dz.abs(), 1.0 / eta) {
                dz = -dz; // internal reflection; the free path restarts (memoryless)
                continue;
            }
            exit(n, [px, py], face, dz.abs());
            return true;
        }
        px += t * dx;
        py += t * dy;
        pz = z_new;
        n += 1;
        if n > max_events {
            return false;
        }
        let z = 1.0 - 2.0 * rng.uniform();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f64::consts::TAU * rng.uniform();
        dx = r * phi.cos();
        dy = r * phi.sin();
        dz = z;
    }
}

fn chunk(eta: f64, plane: u64, seed: u64, start: u64, count: u64, ln_alpha: &[f64]) -> Tally {
    let mut t = Tally::new();
    for i in start..start + count {
        let mut rng = Stream::new(seed, plane, i);
        let ok = trace(eta, f64::INFINITY, &mut rng, |n, x, _| {
            let kind = usize::from(n >= 2);
            ExitSums {
                total: &mut t.total,
                total2: &mut t.total2,
                sum: &mut t.sum,
                sum2: &mut t.sum2,
            }
            .add(ln_alpha, n, bin_of(x), kind * N_ALBEDO);
        });
        t.capped += u64::from(!ok);
    }
    t.photons = count;
    t
}

/// The sums a table keeps per exit, borrowed from a tally: per row k the sums of the weight α^n
/// and of its square over every exit (`total`, `total2`), and per row and radial bin
/// (`sum[k·N_BINS + bin]`, `sum2`) over exits inside the last bin.
pub(super) struct ExitSums<'a> {
    pub(super) total: &'a mut [f64],
    pub(super) total2: &'a mut [f64],
    pub(super) sum: &'a mut [f64],
    pub(super) sum2: &'a mut [f64],
}

impl ExitSums<'_> {
    /// Adds an exit after `n` scattering events in radial bin `bin` (`None`: beyond the last)
    /// to the rows `first + row` with weights α_row^n = exp(n·ln α_row) (rows weighted 0 are
    /// skipped).
    #[inline]
    pub(super) fn add(&mut self, ln_alpha: &[f64], n: u32, bin: Option<usize>, first: usize) {
        for_each_row_weight(ln_alpha, n, |row, w| {
            let k = first + row;
            self.total[k] += w;
            self.total2[k] += w * w;
            if let Some(b) = bin {
                self.sum[k * N_BINS + b] += w;
                self.sum2[k * N_BINS + b] += w * w;
            }
        });
    }
}

/// Traces `photons` photons for refractive index `eta` (plane number `plane` of the table, part
/// of the random key) on `threads` threads; bit-identical for any `threads ≥ 1`.
pub fn simulate(eta: f64, plane: u64, seed: u64, photons: u64, threads: usize) -> Tally {
    let ln_alpha: Vec<f64> = (0..N_ALBEDO).map(|k| albedo_of_row(k).ln()).collect();
    let mut total = Tally::new();
    for t in in_chunks(photons, threads, |start, count| {
        chunk(eta, plane, seed, start, count, &ln_alpha)
    }) {
        total.merge(&t);
    }
    total
}

/// Runs `work(start, count)` over the chunks of [`CHUNK`] photons of `0..photons` on `threads`
/// threads and returns the chunks' results in chunk order (so that merging them in that order
/// is independent of the thread count).
pub(crate) fn in_chunks<T: Send>(
    photons: u64,
    threads: usize,
    work: impl Fn(u64, u64) -> T + Sync,
) -> Vec<T> {
    let chunks = photons.div_ceil(CHUNK);
    let threads = threads.max(1) as u64;
    let mut results: Vec<Option<T>> = (0..chunks).map(|_| None).collect();
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|w| {
                let work = &work;
                s.spawn(move || {
                    (0..chunks)
                        .filter(|c| c % threads == w)
                        .map(|c| {
                            let start = c * CHUNK;
                            let count = CHUNK.min(photons - start);
                            (c, work(start, count))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        for h in handles {
            for (c, t) in h.join().expect("simulation thread") {
                results[c as usize] = Some(t);
            }
        }
    });
    results.into_iter().flatten().collect()
}
