//! The photon simulation behind the oblique radial shape ([`super::oblique`]) and its data
//! file: the angular coupling's simulation ([`super::angular_file`]) with the exit radius
//! recorded too.
//!
//! **What is simulated.** As for the angular coupling: light falls on an isotropically
//! scattering half-space (σt = 1, no absorption; every exit weighted by α^n per albedo row)
//! from outside at an external cosine μ_i drawn within one of [`N_MU`] bins equal in μ²,
//! weighted by 1 − F_r(μ_i), refracted, and walked as the half-space table's photons are.
//! Where it leaves, its external cosine μ_o picks the exit bin k and its distance from the
//! entry point, in mean free paths, the radial bin b ([`radial_bin`]).
//!
//! **What is stored.** Per η plane ([`OBLIQUE_ETAS`]), kind (single, multiple), albedo row
//! ([`N_ROWS`] rows, √(1 − α) geometric as the slab table's), bin pair (j, k) and radial bin
//! b: the mean weight per incident photon P_jk(b), its standard error, and the means of weight
//! × cos nφ (n = 1, 2, 3), φ the azimuth of the exit point about the entry point measured from
//! the incident light's direction of travel along the surface (the Fourier moments of the
//! forward shift). Σ_b P_jk(b) is the angular coupling's P_jk (the last radial bin is
//! unbounded), from an independent simulation.
//!
//! Layout (version 1), little-endian: the magic `HBSSRDFQ`, u32 version, u64 seed, u64
//! photons per incidence bin, u32 planes, u32 albedo rows, u32 cosine bins, u32 radial bins,
//! u32 harmonics; the planes' η (f64 each); then per plane: u64 photons dropped at the event
//! cap, then P, its standard error (f32 each, kind × row × j × k × b) and the moments (f32,
//! harmonic × kind × row × j × k × b).
//!
//! Determinism: photon `i` of a plane draws from its own stream keyed by (seed, plane, i) with
//! incidence bin `i mod N_MU`, and chunks are merged in order, so the file is bit-identical for
//! a given seed and photon count whatever the number of threads.

use super::angular_file::{N_MU, mu_bin};
use super::file::{Header, Reader, TableFileError, all_valid, mean_se, put_f32s};
use super::grid::albedo_of_row_in;
use super::simulate::{Face, Stream, add_into, for_each_row_weight, in_chunks, trace_at};
use crate::fresnel::dielectric;

/// η of the planes: every fourth plane of the half-space table ([`super::grid::ETAS`]).
pub const OBLIQUE_ETAS: [f64; 4] = [1.0, 1.2, 1.4, 1.6];
/// Fourier moments of the exit azimuth recorded (cos φ, cos 2φ, cos 3φ).
pub const N_HARMONICS: usize = 3;
/// Albedo rows: √(1 − α) geometric from [`super::grid::S_MIN`] to 1, as the slab table's.
pub const N_ROWS: usize = 16;
/// Radial bins ([`radial_bin`]).
pub const N_RADII: usize = 14;
/// Inner edge of the second radial bin (mean free paths).
pub const X_INNER: f64 = 0.1;
/// Radial bins per decade between [`X_INNER`] and [`X_OUTER`].
pub const PER_DECADE: usize = 4;
/// Inner edge of the last, unbounded, radial bin.
pub const X_OUTER: f64 = 100.0;
/// Most scattering events followed per photon: a fifth of the other tables' cap (most of the
/// simulation's time is spent in the longest paths). A path cut there weighs at most
/// e^{−5} at α = 1 − 2.5·10⁻⁴ ([`ALPHA_MAX`]); larger albedos read that row's shape.
pub const MAX_EVENTS: u32 = 20_000;
/// The largest albedo whose radial shape is read as simulated ([`MAX_EVENTS`]).
pub const ALPHA_MAX: f64 = 1.0 - 2.5e-4;
/// Offset of the planes' random keys from the other simulations' (unrelated numbers).
const PLANE_KEY: u64 = 2 << 20;

const MAGIC: &[u8; 8] = b"HBSSRDFQ";
/// Format version.
pub const VERSION: u32 = 1;

/// Entries of one plane: kind × row × j × k × b.
pub const PLANE_LEN: usize = 2 * N_ROWS * N_MU * N_MU * N_RADII;

/// Index of `(kind, row, j, k, b)` in [`ObliquePlane::p`]; harmonic h's moments are at
/// `h · PLANE_LEN + index(..)` in [`ObliquePlane::p_cos`].
#[inline]
pub fn index(kind: usize, row: usize, j: usize, k: usize, b: usize) -> usize {
    (((kind * N_ROWS + row) * N_MU + j) * N_MU + k) * N_RADII + b
}

/// Edge `b` of the radial bins (mean free paths): 0, then [`X_INNER`] · 10^((b − 1)/4) up to
/// [`X_OUTER`] (`edge(N_RADII − 1)`), and +∞ for `edge(N_RADII)`.
pub fn radial_edge(b: usize) -> f64 {
    match b {
        0 => 0.0,
        _ if b >= N_RADII => f64::INFINITY,
        _ => X_INNER * 10f64.powf((b - 1) as f64 / PER_DECADE as f64),
    }
}

/// The radial bin of an exit at `x` mean free paths from the entry point.
#[inline]
pub fn radial_bin(x: f64) -> usize {
    if x < X_INNER {
        return 0;
    }
    let b = 1 + ((x / X_INNER).log10() * PER_DECADE as f64) as usize;
    b.min(N_RADII - 1)
}

/// One η plane of the data, in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct ObliquePlane {
    /// Relative refractive index.
    pub eta: f64,
    /// Photons dropped at the event cap.
    pub capped: u64,
    /// P_jk(b) ([`index`]): power leaving into exit bin k at radial bin b per unit power
    /// falling from incidence bin j (unitless).
    pub p: Vec<f32>,
    /// Its standard error.
    pub p_se: Vec<f32>,
    /// The means of weight × cos nφ for n = 1 … [`N_HARMONICS`] (φ the exit point's azimuth
    /// from the incident light's direction of travel along the surface), same units, layout
    /// `[n − 1][kind][row][j][k][b]`.
    pub p_cos: Vec<f32>,
}

/// The whole data with its provenance.
#[derive(Debug, Clone, PartialEq)]
pub struct ObliqueData {
    /// Seed of the simulation.
    pub seed: u64,
    /// Photons traced per incidence bin and plane.
    pub photons: u64,
    /// One plane per entry of [`OBLIQUE_ETAS`].
    pub planes: Vec<ObliquePlane>,
}

fn header<'a>(dims: &'a [usize], etas: &'a [f64]) -> Header<'a> {
    Header {
        magic: MAGIC,
        version: VERSION,
        not_this_kind: "not an oblique radial shape file (bad magic)",
        dims,
        axes: etas,
        axes_differ: "refractive indices differ from this crate's",
    }
}

struct Sums {
    sum: Vec<f64>,
    sum2: Vec<f64>,
    sum_cos: Vec<f64>,
    capped: u64,
}

fn chunk(eta: f64, plane: u64, seed: u64, start: u64, count: u64, ln_alpha: &[f64]) -> Sums {
    let mut s = Sums {
        sum: vec![0.0; PLANE_LEN],
        sum2: vec![0.0; PLANE_LEN],
        sum_cos: vec![0.0; N_HARMONICS * PLANE_LEN],
        capped: 0,
    };
    for i in start..start + count {
        let j = (i % N_MU as u64) as usize;
        let mut rng = Stream::new(seed, PLANE_KEY + plane, i);
        let mu_i = ((j as f64 + rng.uniform()) / N_MU as f64).min(1.0).sqrt();
        let w0 = 1.0 - dielectric(mu_i, eta);
        if w0 <= 0.0 {
            continue;
        }
        // Refraction into the medium, travelling along +x at the surface.
        let sin_t = (1.0 - mu_i * mu_i).max(0.0).sqrt() / eta;
        let cos_t = (1.0 - sin_t * sin_t).max(0.0).sqrt();
        let ok = trace_at(
            [sin_t, 0.0, -cos_t],
            eta,
            f64::INFINITY,
            MAX_EVENTS,
            &mut rng,
            |n, [x, y], face, cos_in| {
                debug_assert_eq!(face, Face::Entry);
                let sin_o = eta * (1.0 - cos_in * cos_in).max(0.0).sqrt();
                let mu_o = (1.0 - sin_o * sin_o).max(0.0).sqrt();
                let r = (x * x + y * y).sqrt();
                let c1 = if r > 0.0 { x / r } else { 0.0 };
                let cos_n = [c1, 2.0 * c1 * c1 - 1.0, (4.0 * c1 * c1 - 3.0) * c1];
                let (kind, k, b) = (usize::from(n >= 2), mu_bin(mu_o), radial_bin(r));
                for_each_row_weight(ln_alpha, n, |row, w| {
                    let (at, w) = (index(kind, row, j, k, b), w0 * w);
                    s.sum[at] += w;
                    s.sum2[at] += w * w;
                    for (h, c) in cos_n.iter().enumerate() {
                        s.sum_cos[h * PLANE_LEN + at] += w * c;
                    }
                });
            },
        );
        s.capped += u64::from(!ok);
    }
    s
}

#[cfg(any(test, feature = "tabulate"))]
/// Simulates plane `plane` (refractive index `OBLIQUE_ETAS[plane]`) with `photons` photons per
/// incidence bin on `threads` threads; bit-identical for any `threads ≥ 1`.
pub fn simulate_plane(plane: usize, seed: u64, photons: u64, threads: usize) -> ObliquePlane {
    let eta = OBLIQUE_ETAS[plane];
    let ln_alpha: Vec<f64> = (0..N_ROWS)
        .map(|k| albedo_of_row_in(k, N_ROWS).ln())
        .collect();
    let total = photons * N_MU as u64;
    let mut sum = vec![0.0; PLANE_LEN];
    let mut sum2 = vec![0.0; PLANE_LEN];
    let mut sum_cos = vec![0.0; N_HARMONICS * PLANE_LEN];
    let mut capped = 0;
    for c in in_chunks(total, threads, |start, count| {
        chunk(eta, plane as u64, seed, start, count, &ln_alpha)
    }) {
        add_into(&mut sum, &c.sum);
        add_into(&mut sum2, &c.sum2);
        add_into(&mut sum_cos, &c.sum_cos);
        capped += c.capped;
    }
    let n = photons as f64;
    let (p, p_se) = sum
        .iter()
        .zip(&sum2)
        .map(|(&s, &s2)| {
            let (mean, se) = mean_se(s, s2, n);
            (mean as f32, se as f32)
        })
        .unzip();
    let p_cos = sum_cos.iter().map(|&s| (s / n) as f32).collect();
    ObliquePlane {
        eta,
        capped,
        p,
        p_se,
        p_cos,
    }
}

#[cfg(any(test, feature = "tabulate"))]
/// Simulates every plane (see the module docs), reporting each finished plane to `progress`.
pub fn tabulate_oblique(
    seed: u64,
    photons: u64,
    threads: usize,
    mut progress: impl FnMut(usize),
) -> ObliqueData {
    let planes = (0..OBLIQUE_ETAS.len())
        .map(|i| {
            let p = simulate_plane(i, seed, photons, threads);
            progress(i);
            p
        })
        .collect();
    ObliqueData {
        seed,
        photons,
        planes,
    }
}

impl ObliqueData {
    /// Serialises the data (see the module docs).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::new();
        let etas: Vec<f64> = self.planes.iter().map(|p| p.eta).collect();
        header(
            &[self.planes.len(), N_ROWS, N_MU, N_RADII, N_HARMONICS],
            &etas,
        )
        .put(&mut b, self.seed, self.photons);
        for p in &self.planes {
            b.extend_from_slice(&p.capped.to_le_bytes());
            put_f32s(&mut b, p.p.iter().chain(&p.p_se).chain(&p.p_cos));
        }
        b
    }

    /// Parses data written by [`ObliqueData::to_bytes`] with this crate's grid.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, TableFileError> {
        let mut r = Reader(bytes);
        let (seed, photons) = header(
            &[OBLIQUE_ETAS.len(), N_ROWS, N_MU, N_RADII, N_HARMONICS],
            &OBLIQUE_ETAS,
        )
        .read(&mut r)?;
        let mut out = Vec::with_capacity(OBLIQUE_ETAS.len());
        for eta in OBLIQUE_ETAS {
            let capped = r.u64()?;
            let p = r.f32s(PLANE_LEN)?;
            let p_se = r.f32s(PLANE_LEN)?;
            let p_cos = r.f32s(N_HARMONICS * PLANE_LEN)?;
            if !all_valid(p.iter().chain(&p_se))
                || p_cos.iter().any(|v| !v.is_finite())
                || p_cos
                    .iter()
                    .zip(p.iter().cycle())
                    .any(|(c, m)| c.abs() > *m * 1.0001)
            {
                return Err(TableFileError("negative or non-finite value"));
            }
            out.push(ObliquePlane {
                eta,
                capped,
                p,
                p_se,
                p_cos,
            });
        }
        r.finish()?;
        Ok(Self {
            seed,
            photons,
            planes: out,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radial_bins_follow_their_edges() {
        for b in 0..N_RADII {
            let (lo, hi) = (radial_edge(b), radial_edge(b + 1));
            assert_eq!(radial_bin(lo * (1.0 + 1e-12)), b, "{b}");
            if hi.is_finite() {
                assert_eq!(radial_bin(hi * (1.0 - 1e-12)), b, "{b}");
            }
        }
        assert_eq!(radial_edge(N_RADII - 1), X_OUTER);
        assert_eq!(radial_bin(1e9), N_RADII - 1);
    }

    #[test]
    fn simulation_is_independent_of_the_thread_count_and_round_trips() {
        let a = simulate_plane(3, 7, 1_000, 1);
        let b = simulate_plane(3, 7, 1_000, 3);
        assert_eq!(a, b);
        assert!(a.p.iter().any(|&v| v > 0.0));
        // The forward shift: light entering obliquely leaves ahead of its entry point.
        let data = ObliqueData {
            seed: 7,
            photons: 1_000,
            planes: vec![a; OBLIQUE_ETAS.len()]
                .into_iter()
                .zip(OBLIQUE_ETAS)
                .map(|(p, eta)| ObliquePlane { eta, ..p })
                .collect(),
        };
        let bytes = data.to_bytes();
        assert_eq!(ObliqueData::from_bytes(&bytes).as_ref(), Ok(&data));
        assert!(ObliqueData::from_bytes(&bytes[..bytes.len() - 1]).is_err());
    }
}
