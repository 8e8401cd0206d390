//! The photon simulation behind the angular coupling ([`super::angular`]) and its data file.
//!
//! **What is simulated.** Light falls on an isotropically scattering half-space (σt = 1, no
//! absorption; every exit weighted by α^n per albedo row, as in [`super::simulate`]) from
//! outside, at an external cosine μ_i drawn within one of [`N_MU`] bins of equal projected
//! solid angle (μ_i² uniform in the bin: cosine-weighted incidence, the measure of a uniform
//! sky). Each photon carries the weight 1 − F_r(μ_i) of the light that crosses the boundary,
//! is refracted, and walks as the half-space table's photons do; where it leaves, its external
//! cosine μ_o (after refraction) picks the exit bin. Azimuth is not recorded.
//!
//! **What is stored.** Per η plane, kind (single, multiple), albedo row and bin pair (j, k),
//! the mean weight per incident photon P_jk: the fraction of the power falling from bin j
//! that leaves into bin k, integrated over the whole surface (all radii). By reciprocity P
//! is symmetric in expectation (both bins carry the same projected solid angle); the
//! coupling symmetrises it when it is read.
//!
//! Layout (version 1), little-endian: the magic `HBSSRDFA`, u32 version, u64 seed, u64
//! photons per incidence bin, u32 planes, u32 albedo rows, u32 bins; the planes' η (f64
//! each); then per plane: u64 photons dropped at the event cap, then P and its standard
//! error (f32 each, kind × row × j × k).
//!
//! Determinism: photon `i` of a plane draws from its own stream keyed by (seed, plane, i) with
//! incidence bin `i mod N_MU`, and chunks are merged in order, so the file is bit-identical for
//! a given seed and photon count whatever the number of threads.

use super::file::{Header, Reader, TableFileError, all_valid, mean_se, put_f32s};
use super::grid::{N_ALBEDO, albedo_of_row};
use super::simulate::{Face, Stream, add_into, for_each_row_weight, in_chunks, trace_from};
use crate::fresnel::dielectric;

/// Bins of external cosine, equal in μ² (equal projected solid angle), for incidence and exit.
pub const N_MU: usize = 8;
/// η of the coupling's planes: every other plane of the half-space table
/// ([`super::grid::ETAS`]), whose totals the coupling is normalised by.
pub const ANGULAR_ETAS: [f64; 7] = [1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6];
/// Offset of the planes' random keys from the half-space table's (so the two simulations
/// draw unrelated numbers).
const PLANE_KEY: u64 = 1 << 20;

const MAGIC: &[u8; 8] = b"HBSSRDFA";
/// Format version.
pub const VERSION: u32 = 1;

/// Entries of one plane: kind × row × j × k.
pub const PLANE_LEN: usize = 2 * N_ALBEDO * N_MU * N_MU;

/// Index of `(kind, row, j, k)` in [`AngularPlane::p`].
#[inline]
pub fn index(kind: usize, row: usize, j: usize, k: usize) -> usize {
    ((kind * N_ALBEDO + row) * N_MU + j) * N_MU + k
}

/// One η plane of the coupling data, in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct AngularPlane {
    /// Relative refractive index.
    pub eta: f64,
    /// Photons dropped at the event cap.
    pub capped: u64,
    /// P_jk per kind and row ([`index`]): power leaving into exit bin k per unit power falling
    /// from incidence bin j (unitless).
    pub p: Vec<f32>,
    /// Its standard error.
    pub p_se: Vec<f32>,
}

/// The whole coupling data with its provenance.
#[derive(Debug, Clone, PartialEq)]
pub struct AngularData {
    /// Seed of the simulation.
    pub seed: u64,
    /// Photons traced per incidence bin and plane.
    pub photons: u64,
    /// One plane per entry of [`ANGULAR_ETAS`].
    pub planes: Vec<AngularPlane>,
}

/// The coupling file's header for a grid of `dims` (planes, rows, bins) and η planes `etas`.
fn header<'a>(dims: &'a [usize], etas: &'a [f64]) -> Header<'a> {
    Header {
        magic: MAGIC,
        version: VERSION,
        not_this_kind: "not an angular coupling file (bad magic)",
        dims,
        axes: etas,
        axes_differ: "refractive indices differ from this crate's",
    }
}

/// The bin of external cosine `mu` (μ² · [`N_MU`], clamped).
#[inline]
pub fn mu_bin(mu: f64) -> usize {
    ((mu * mu * N_MU as f64) as usize).min(N_MU - 1)
}

/// Sums of one chunk of photons.
struct Sums {
    sum: Vec<f64>,
    sum2: Vec<f64>,
    capped: u64,
}

/// Traces photons `start..start + count` of plane `plane` (index into [`ANGULAR_ETAS`]).
fn chunk(eta: f64, plane: u64, seed: u64, start: u64, count: u64, ln_alpha: &[f64]) -> Sums {
    let mut s = Sums {
        sum: vec![0.0; PLANE_LEN],
        sum2: vec![0.0; PLANE_LEN],
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
        // Refraction into the medium (η ≥ 1: never total internal reflection from outside).
        let sin_t = (1.0 - mu_i * mu_i).max(0.0).sqrt() / eta;
        let cos_t = (1.0 - sin_t * sin_t).max(0.0).sqrt();
        let ok = trace_from(
            [sin_t, 0.0, -cos_t],
            eta,
            f64::INFINITY,
            &mut rng,
            |n, _x, face, cos_in| {
                debug_assert_eq!(face, Face::Entry);
                let sin_o = eta * (1.0 - cos_in * cos_in).max(0.0).sqrt();
                let mu_o = (1.0 - sin_o * sin_o).max(0.0).sqrt();
                let (kind, k) = (usize::from(n >= 2), mu_bin(mu_o));
                for_each_row_weight(ln_alpha, n, |row, w| {
                    let (at, w) = (index(kind, row, j, k), w0 * w);
                    s.sum[at] += w;
                    s.sum2[at] += w * w;
                });
            },
        );
        s.capped += u64::from(!ok);
    }
    s
}

#[cfg(any(test, feature = "tabulate"))]
/// Simulates plane `plane` (refractive index `ANGULAR_ETAS[plane]`) with `photons` photons per
/// incidence bin on `threads` threads; bit-identical for any `threads ≥ 1`.
pub fn simulate_plane(plane: usize, seed: u64, photons: u64, threads: usize) -> AngularPlane {
    let eta = ANGULAR_ETAS[plane];
    let ln_alpha: Vec<f64> = (0..N_ALBEDO).map(|k| albedo_of_row(k).ln()).collect();
    let total = photons * N_MU as u64;
    let mut sum = vec![0.0; PLANE_LEN];
    let mut sum2 = vec![0.0; PLANE_LEN];
    let mut capped = 0;
    for c in in_chunks(total, threads, |start, count| {
        chunk(eta, plane as u64, seed, start, count, &ln_alpha)
    }) {
        add_into(&mut sum, &c.sum);
        add_into(&mut sum2, &c.sum2);
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
    AngularPlane {
        eta,
        capped,
        p,
        p_se,
    }
}

#[cfg(any(test, feature = "tabulate"))]
/// Simulates every plane (see the module docs), reporting each finished plane to `progress`.
pub fn tabulate_angular(
    seed: u64,
    photons: u64,
    threads: usize,
    mut progress: impl FnMut(usize),
) -> AngularData {
    let planes = (0..ANGULAR_ETAS.len())
        .map(|i| {
            let p = simulate_plane(i, seed, photons, threads);
            progress(i);
            p
        })
        .collect();
    AngularData {
        seed,
        photons,
        planes,
    }
}

impl AngularData {
    /// Serialises the data (see the module docs).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::new();
        let etas: Vec<f64> = self.planes.iter().map(|p| p.eta).collect();
        header(&[self.planes.len(), N_ALBEDO, N_MU], &etas).put(&mut b, self.seed, self.photons);
        for p in &self.planes {
            b.extend_from_slice(&p.capped.to_le_bytes());
            put_f32s(&mut b, p.p.iter().chain(&p.p_se));
        }
        b
    }

    /// Parses data written by [`AngularData::to_bytes`] with this crate's grid.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, TableFileError> {
        let mut r = Reader(bytes);
        let (seed, photons) =
            header(&[ANGULAR_ETAS.len(), N_ALBEDO, N_MU], &ANGULAR_ETAS).read(&mut r)?;
        let mut out = Vec::with_capacity(ANGULAR_ETAS.len());
        for eta in ANGULAR_ETAS {
            let capped = r.u64()?;
            let p = r.f32s(PLANE_LEN)?;
            let p_se = r.f32s(PLANE_LEN)?;
            if !all_valid(p.iter().chain(&p_se)) {
                return Err(TableFileError("negative or non-finite value"));
            }
            out.push(AngularPlane {
                eta,
                capped,
                p,
                p_se,
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
