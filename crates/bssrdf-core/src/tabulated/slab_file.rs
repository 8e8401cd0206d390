//! The slab table: its photon simulation and its data file.
//!
//! The simulation is the half-space one ([`super::simulate`]) with a second boundary: a pencil
//! beam enters an isotropically scattering slab of optical thickness d (σt = 1) at the origin
//! along −z, both faces reflect internally with the dielectric Fresnel reflectance at η, and
//! every exit is tallied by face (the entry face z = 0: reflection; the opposite face z = −d:
//! transmission), by radius from the beam's axis, and weighted by α^n for each albedo row (n
//! the number of scattering events; exact, see [`super::simulate`]). Only multiple scattering
//! (n ≥ 2) is tabulated per bin; single scattering (n = 1) per face and row as a total only,
//! and unscattered light (n = 0, which leaves along the beam's axis) per face as a total only:
//! with the mean number of scattering events per photon, they are what the closed-form
//! checks of the geometry, the Fresnel boundaries and the energy balance need
//! (`tests/slab_table.rs`). Photon `i` of plane `p` draws from its own stream keyed by (seed,
//! `SLAB_KEY` + p, i), chunks are merged in order: the file is bit-identical for a seed and a
//! photon count whatever the number of threads.
//!
//! Layout (version 1), little-endian: the magic `HBSSRDFS`, u32 version, u64 seed, u64 photons
//! per plane, u32 thicknesses, u32 η planes, u32 albedo rows, u32 radial bins; the thicknesses
//! and the η values (f64 each); then per plane (thickness-major, η-minor): u64 photons dropped
//! at the event cap, the mean number of scattering events per photon (f64), for each face the
//! unscattered fraction and its standard error (f64), for face × row the single-scattering
//! total and its standard error (f64), then
//! for face × row × bin the multiple-scattering exitance density (f32, per unit area in
//! mfp², per unit entering power) and its standard error (f32), then for face × row the
//! total (f64) and its standard error (f64), totals counting every exit, also beyond the last
//! bin.

use super::file::{
    Header, Reader, TableFileError, all_valid, densities, mean_se, pool_sparse_bins, put_f32s,
    put_f64s,
};
use super::grid::{N_BINS, bin_of};
use super::grid::{SLAB_ETAS, SLAB_ROWS, SLAB_THICKNESSES, slab_albedo_of_row};
use super::simulate::{ExitSums, Face, Stream, add_into, for_each_row_weight, in_chunks, trace};

const MAGIC: &[u8; 8] = b"HBSSRDFS";
/// Format version of the slab table.
pub const SLAB_VERSION: u32 = 1;
/// Offset of the slab planes' random keys (the half-space planes use 0..13).
const SLAB_KEY: u64 = 1 << 20;
/// Values per plane of a `[face][row][bin]` array.
const PER_PLANE: usize = 2 * SLAB_ROWS * N_BINS;

/// Sums over photons for one (thickness, η): per face, row and bin the sums of α^n and of
/// (α^n)² over multiple-scattering exits; per face and row the same over every exit; per face
/// the unscattered exits.
#[derive(Debug, Clone, PartialEq)]
struct SlabTally {
    photons: u64,
    sum: Vec<f64>,
    sum2: Vec<f64>,
    total: Vec<f64>,
    total2: Vec<f64>,
    ballistic: [u64; 2],
    single: Vec<f64>,
    single2: Vec<f64>,
    events: u64,
    capped: u64,
}

impl SlabTally {
    fn new() -> Self {
        Self {
            photons: 0,
            sum: vec![0.0; PER_PLANE],
            sum2: vec![0.0; PER_PLANE],
            total: vec![0.0; 2 * SLAB_ROWS],
            total2: vec![0.0; 2 * SLAB_ROWS],
            ballistic: [0; 2],
            single: vec![0.0; 2 * SLAB_ROWS],
            single2: vec![0.0; 2 * SLAB_ROWS],
            events: 0,
            capped: 0,
        }
    }

    fn merge(&mut self, o: &SlabTally) {
        self.photons += o.photons;
        self.capped += o.capped;
        self.events += o.events;
        for f in 0..2 {
            self.ballistic[f] += o.ballistic[f];
        }
        for (a, b) in [
            (&mut self.sum, &o.sum),
            (&mut self.sum2, &o.sum2),
            (&mut self.total, &o.total),
            (&mut self.total2, &o.total2),
            (&mut self.single, &o.single),
            (&mut self.single2, &o.single2),
        ] {
            add_into(a, b);
        }
    }
}

fn slab_chunk(
    thickness: f64,
    eta: f64,
    key: u64,
    seed: u64,
    start: u64,
    count: u64,
    ln_alpha: &[f64],
) -> SlabTally {
    let mut t = SlabTally::new();
    for i in start..start + count {
        let mut rng = Stream::new(seed, key, i);
        let ok = trace(eta, thickness, &mut rng, |n, x, face| {
            let f = usize::from(face == Face::Opposite);
            t.events += u64::from(n);
            if n == 0 {
                t.ballistic[f] += 1;
                return;
            }
            if n == 1 {
                for_each_row_weight(ln_alpha, 1, |row, w| {
                    t.single[f * SLAB_ROWS + row] += w;
                    t.single2[f * SLAB_ROWS + row] += w * w;
                });
                return;
            }
            ExitSums {
                total: &mut t.total,
                total2: &mut t.total2,
                sum: &mut t.sum,
                sum2: &mut t.sum2,
            }
            .add(ln_alpha, n, bin_of(x), f * SLAB_ROWS);
        });
        t.capped += u64::from(!ok);
    }
    t.photons = count;
    t
}

/// One (thickness, η) plane of the slab table, in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct SlabPlane {
    /// Optical thickness d (mean free paths).
    pub thickness: f64,
    /// Relative refractive index.
    pub eta: f64,
    /// Photons dropped at the event cap.
    pub capped: u64,
    /// Mean number of scattering events per photon (of the photons that left).
    pub mean_events: f64,
    /// Per face (entry, opposite): the fraction of entering power that leaves unscattered.
    pub ballistic: [f64; 2],
    /// Its standard error.
    pub ballistic_se: [f64; 2],
    /// `[face][row][bin]` multiple-scattering exitance density (1/mfp²).
    pub density: Vec<f32>,
    /// Its standard error.
    pub density_se: Vec<f32>,
    /// `[face][row]` total single-scattering exitance.
    pub single: Vec<f64>,
    /// Its standard error.
    pub single_se: Vec<f64>,
    /// `[face][row]` total multiple-scattering exitance.
    pub total: Vec<f64>,
    /// Its standard error.
    pub total_se: Vec<f64>,
}

impl SlabPlane {
    fn from_tally(thickness: f64, eta: f64, t: &SlabTally) -> Self {
        let n = t.photons as f64;
        let (density, density_se) = densities(&t.sum, &t.sum2, n);
        let (total, total_se) = (0..2 * SLAB_ROWS)
            .map(|k| mean_se(t.total[k], t.total2[k], n))
            .unzip();
        let (single, single_se) = (0..2 * SLAB_ROWS)
            .map(|k| mean_se(t.single[k], t.single2[k], n))
            .unzip();
        let b = |f: usize| {
            let c = t.ballistic[f] as f64;
            mean_se(c, c, n)
        };
        Self {
            thickness,
            eta,
            capped: t.capped,
            mean_events: t.events as f64 / (t.photons - t.capped).max(1) as f64,
            ballistic: [b(0).0, b(1).0],
            ballistic_se: [b(0).1, b(1).1],
            single,
            single_se,
            density,
            density_se,
            total,
            total_se,
        }
    }

    /// Pools sparse radial bins ([`super::file::Plane::pool_sparse_bins`]).
    pub fn pool_sparse_bins(&mut self, max_rel_se: f64) {
        pool_sparse_bins(&mut self.density, &mut self.density_se, max_rel_se);
    }

    /// Index of `(face, row, bin)` in [`SlabPlane::density`] (face 0 entry, 1 opposite).
    pub fn index(face: usize, row: usize, bin: usize) -> usize {
        (face * SLAB_ROWS + row) * N_BINS + bin
    }
}

/// The slab table with its provenance.
#[derive(Debug, Clone, PartialEq)]
pub struct SlabData {
    /// Seed of the simulation.
    pub seed: u64,
    /// Photons traced per plane.
    pub photons: u64,
    /// Planes, thickness-major ([`SLAB_THICKNESSES`]), η-minor ([`SLAB_ETAS`]).
    pub planes: Vec<SlabPlane>,
}

impl SlabData {
    /// The plane of thickness index `d` and η index `e`.
    pub fn plane(&self, d: usize, e: usize) -> &SlabPlane {
        &self.planes[d * SLAB_ETAS.len() + e]
    }

    /// Serialises the table (see the module docs).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::new();
        let axes = slab_axes();
        slab_header(&axes).put(&mut b, self.seed, self.photons);
        for p in &self.planes {
            b.extend_from_slice(&p.capped.to_le_bytes());
            b.extend_from_slice(&p.mean_events.to_le_bytes());
            put_f64s(&mut b, p.ballistic.iter().chain(&p.ballistic_se));
            put_f64s(&mut b, p.single.iter().chain(&p.single_se));
            put_f32s(&mut b, p.density.iter().chain(&p.density_se));
            put_f64s(&mut b, p.total.iter().chain(&p.total_se));
        }
        b
    }

    /// Parses a table written by [`SlabData::to_bytes`] with this crate's grid.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, TableFileError> {
        let mut r = Reader(bytes);
        let axes = slab_axes();
        let (seed, photons) = slab_header(&axes).read(&mut r)?;
        let mut planes = Vec::with_capacity(SLAB_THICKNESSES.len() * SLAB_ETAS.len());
        for &thickness in &SLAB_THICKNESSES {
            for &eta in &SLAB_ETAS {
                let capped = r.u64()?;
                let mean_events = r.f64()?;
                let ballistic = [r.f64()?, r.f64()?];
                let ballistic_se = [r.f64()?, r.f64()?];
                let single = r.f64s(2 * SLAB_ROWS)?;
                let single_se = r.f64s(2 * SLAB_ROWS)?;
                let density = r.f32s(PER_PLANE)?;
                let density_se = r.f32s(PER_PLANE)?;
                let total = r.f64s(2 * SLAB_ROWS)?;
                let total_se = r.f64s(2 * SLAB_ROWS)?;
                let finite = all_valid(density.iter().chain(&density_se))
                    && all_valid(
                        total
                            .iter()
                            .chain(&total_se)
                            .chain(&ballistic)
                            .chain(&ballistic_se)
                            .chain(&single)
                            .chain(&single_se)
                            .chain([&mean_events]),
                    );
                if !finite {
                    return Err(TableFileError("negative or non-finite value"));
                }
                planes.push(SlabPlane {
                    thickness,
                    eta,
                    capped,
                    mean_events,
                    ballistic,
                    ballistic_se,
                    single,
                    single_se,
                    density,
                    density_se,
                    total,
                    total_se,
                });
            }
        }
        r.finish()?;
        Ok(Self {
            seed,
            photons,
            planes,
        })
    }
}

#[cfg(any(test, feature = "tabulate"))]
/// Simulates one plane: `photons` photons through a slab of optical thickness `thickness` at
/// `eta`, `key` part of the random key; bit-identical for any `threads ≥ 1`.
pub fn simulate_slab_plane(
    thickness: f64,
    eta: f64,
    key: u64,
    seed: u64,
    photons: u64,
    threads: usize,
) -> SlabPlane {
    let ln_alpha: Vec<f64> = (0..SLAB_ROWS).map(|k| slab_albedo_of_row(k).ln()).collect();
    let mut total = SlabTally::new();
    for t in in_chunks(photons, threads, |start, count| {
        slab_chunk(thickness, eta, key, seed, start, count, &ln_alpha)
    }) {
        total.merge(&t);
    }
    SlabPlane::from_tally(thickness, eta, &total)
}

#[cfg(any(test, feature = "tabulate"))]
/// Simulates every plane of the slab table with `photons` photons each; `progress(i)` after
/// plane `i`. Bit-identical for a given seed and photon count whatever `threads` is. Paths
/// longer than [`super::simulate::MAX_EVENTS`] scattering events are dropped (counted per plane).
pub fn tabulate_slab(
    seed: u64,
    photons: u64,
    threads: usize,
    mut progress: impl FnMut(usize),
) -> SlabData {
    let mut planes = Vec::new();
    for &thickness in &SLAB_THICKNESSES {
        for &eta in &SLAB_ETAS {
            let i = planes.len();
            planes.push(simulate_slab_plane(
                thickness,
                eta,
                SLAB_KEY + i as u64,
                seed,
                photons,
                threads,
            ));
            progress(i);
        }
    }
    SlabData {
        seed,
        photons,
        planes,
    }
}

/// The slab table's axis values: its thicknesses, then its η planes.
fn slab_axes() -> Vec<f64> {
    SLAB_THICKNESSES.iter().chain(&SLAB_ETAS).copied().collect()
}

/// The slab table's grid dimensions: thicknesses, η planes, albedo rows, radial bins.
const SLAB_DIMS: [usize; 4] = [SLAB_THICKNESSES.len(), SLAB_ETAS.len(), SLAB_ROWS, N_BINS];

/// The slab table's header (`axes` from [`slab_axes`]).
fn slab_header(axes: &[f64]) -> Header<'_> {
    Header {
        magic: MAGIC,
        version: SLAB_VERSION,
        not_this_kind: "not a slab table file (bad magic)",
        dims: &SLAB_DIMS,
        axes,
        axes_differ: "thicknesses or refractive indices differ from this crate's",
    }
}
