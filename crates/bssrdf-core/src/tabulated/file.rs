//! The table's data file: a small little-endian binary, versioned, with its provenance.
//!
//! Layout (version 1): the magic `HBSSRDFT`, then u32 version, u64 seed, u64 photons per η
//! plane, u32 planes, u32 albedo rows, u32 radial bins; the planes' η (f64 each); then per
//! plane: u64 photons dropped at the event cap, and for kind (single, multiple) × row × bin
//! the exitance density R̂ (f32, per unit area in mean free paths², per unit entering power)
//! and its standard error (f32), then for kind × row the total (f64) and its standard error
//! (f64), totals counting every exit including those beyond the last bin.

use super::grid::{ETAS, N_ALBEDO, N_BINS, annulus_area};
use super::simulate::Tally;

const MAGIC: &[u8; 8] = b"HBSSRDFT";
/// Format version.
pub const VERSION: u32 = 1;

/// One η plane of the table, in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    /// Relative refractive index.
    pub eta: f64,
    /// Photons dropped at the event cap.
    pub capped: u64,
    /// `[kind][row][bin]` exitance density R̂ (1/mfp²).
    pub density: Vec<f32>,
    /// Its standard error.
    pub density_se: Vec<f32>,
    /// `[kind][row]` total diffuse reflectance.
    pub total: Vec<f64>,
    /// Its standard error.
    pub total_se: Vec<f64>,
}

/// The whole table with its provenance.
#[derive(Debug, Clone, PartialEq)]
pub struct TableData {
    /// Seed of the simulation.
    pub seed: u64,
    /// Photons traced per plane.
    pub photons: u64,
    /// One plane per entry of [`ETAS`].
    pub planes: Vec<Plane>,
}

/// A malformed table file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("tabulated profile data: {0}")]
pub struct TableFileError(pub &'static str);

impl Plane {
    /// Mean and standard error per bin and total from a tally of `eta`.
    pub fn from_tally(eta: f64, t: &Tally) -> Self {
        let n = t.photons as f64;
        let (density, density_se) = densities(&t.sum, &t.sum2, n);
        let (total, total_se) = (0..2 * N_ALBEDO)
            .map(|k| mean_se(t.total[k], t.total2[k], n))
            .unzip();
        Self {
            eta,
            capped: t.capped,
            density,
            density_se,
            total,
            total_se,
        }
    }
}

impl Plane {
    /// Pools runs of neighbouring radial bins whose counts are too small to estimate a density
    /// (the innermost annuli are tiny, the outermost rarely reached): consecutive bins of one
    /// (kind, row) are merged until the pooled relative standard error is at most
    /// `max_rel_se`, and every bin of a run gets the run's mean density (area-weighted, so the
    /// run's energy is unchanged). Bins with a small enough error are left as they are. This
    /// removes the zeros and spikes of pure counting noise without moving energy between runs.
    pub fn pool_sparse_bins(&mut self, max_rel_se: f64) {
        pool_sparse_bins(&mut self.density, &mut self.density_se, max_rel_se);
    }
}

/// [`Plane::pool_sparse_bins`] on any series of [`N_BINS`] radial bins laid end to end
/// (`density.len()` a multiple of `N_BINS`), densities and their standard errors.
pub(crate) fn pool_sparse_bins(density: &mut [f32], density_se: &mut [f32], max_rel_se: f64) {
    for series in 0..density.len() / N_BINS {
        let base = series * N_BINS;
        let mut j = 0;
        while j < N_BINS {
            let (mut e, mut var, mut area) = (0.0, 0.0, 0.0);
            let mut k = j;
            while k < N_BINS {
                let a = annulus_area(k);
                e += f64::from(density[base + k]) * a;
                var += (f64::from(density_se[base + k]) * a).powi(2);
                area += a;
                k += 1;
                if e > 0.0 && var.sqrt() <= max_rel_se * e {
                    break;
                }
            }
            if k - j > 1 {
                for b in j..k {
                    density[base + b] = (e / area) as f32;
                    density_se[base + b] = (var.sqrt() / area) as f32;
                }
            }
            j = k;
        }
    }
}

/// Mean and standard error of the mean from a sum and a sum of squares over `n` samples.
pub(crate) fn mean_se(s: f64, s2: f64, n: f64) -> (f64, f64) {
    let m = s / n;
    (m, ((s2 / n - m * m).max(0.0) / n).sqrt())
}

/// The exitance density per bin (1/mfp²) and its standard error, from per-bin sums `sum`, `sum2`
/// of `n` photons laid out `[..][bin]` with [`N_BINS`] bins innermost: each bin's mean over
/// its annulus's area.
pub(crate) fn densities(sum: &[f64], sum2: &[f64], n: f64) -> (Vec<f32>, Vec<f32>) {
    (0..sum.len())
        .map(|i| {
            let (m, e) = mean_se(sum[i], sum2[i], n);
            let area = annulus_area(i % N_BINS);
            ((m / area) as f32, (e / area) as f32)
        })
        .unzip()
}

/// The header every table file of this crate starts with: what it is and the grid it was made
/// on, so that a file from another grid is an error and not a misread.
pub(crate) struct Header<'a> {
    /// Eight bytes naming the kind of table.
    pub(crate) magic: &'a [u8; 8],
    /// The format version.
    pub(crate) version: u32,
    /// The error for a file of another kind.
    pub(crate) not_this_kind: &'static str,
    /// The grid's dimensions (written as u32 each).
    pub(crate) dims: &'a [usize],
    /// The grid's axis values (η planes, thicknesses; f64 each).
    pub(crate) axes: &'a [f64],
    /// The error for a file whose axis values differ.
    pub(crate) axes_differ: &'static str,
}

impl Header<'_> {
    /// Appends magic, version, `seed`, `photons`, the dimensions and the axis values.
    pub(crate) fn put(&self, b: &mut Vec<u8>, seed: u64, photons: u64) {
        b.extend_from_slice(self.magic);
        b.extend_from_slice(&self.version.to_le_bytes());
        b.extend_from_slice(&seed.to_le_bytes());
        b.extend_from_slice(&photons.to_le_bytes());
        for &v in self.dims {
            b.extend_from_slice(&(v as u32).to_le_bytes());
        }
        put_f64s(b, self.axes);
    }

    /// Reads and checks what [`Header::put`] wrote; returns (seed, photons).
    pub(crate) fn read(&self, r: &mut Reader<'_>) -> Result<(u64, u64), TableFileError> {
        if r.take(8)? != self.magic {
            return Err(TableFileError(self.not_this_kind));
        }
        if r.u32()? != self.version {
            return Err(TableFileError("unsupported version"));
        }
        let (seed, photons) = (r.u64()?, r.u64()?);
        for &want in self.dims {
            if r.u32()? as usize != want {
                return Err(TableFileError("grid differs from this crate's"));
            }
        }
        for &want in self.axes {
            if r.f64()? != want {
                return Err(TableFileError(self.axes_differ));
            }
        }
        Ok((seed, photons))
    }
}

/// Appends `values` little-endian.
pub(crate) fn put_f64s<'a>(b: &mut Vec<u8>, values: impl IntoIterator<Item = &'a f64>) {
    for v in values {
        b.extend_from_slice(&v.to_le_bytes());
    }
}

/// Appends `values` little-endian.
pub(crate) fn put_f32s<'a>(b: &mut Vec<u8>, values: impl IntoIterator<Item = &'a f32>) {
    for v in values {
        b.extend_from_slice(&v.to_le_bytes());
    }
}

/// True when every value is finite and non-negative (what a table file may hold).
pub(crate) fn all_valid<'a, T: Into<f64> + Copy + 'a>(
    values: impl IntoIterator<Item = &'a T>,
) -> bool {
    values.into_iter().all(|&v| {
        let v: f64 = v.into();
        v.is_finite() && v >= 0.0
    })
}

impl TableData {
    /// Serialises the table (see the module docs).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::new();
        let etas: Vec<f64> = self.planes.iter().map(|p| p.eta).collect();
        header(&[self.planes.len(), N_ALBEDO, N_BINS], &etas).put(&mut b, self.seed, self.photons);
        for p in &self.planes {
            b.extend_from_slice(&p.capped.to_le_bytes());
            put_f32s(&mut b, p.density.iter().chain(&p.density_se));
            put_f64s(&mut b, p.total.iter().chain(&p.total_se));
        }
        b
    }

    /// Parses a table written by [`TableData::to_bytes`] with this crate's grid.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, TableFileError> {
        let mut r = Reader(bytes);
        let (seed, photons) = header(&[ETAS.len(), N_ALBEDO, N_BINS], &ETAS).read(&mut r)?;
        let n = 2 * N_ALBEDO * N_BINS;
        let mut out = Vec::with_capacity(ETAS.len());
        for eta in ETAS {
            let capped = r.u64()?;
            let density = r.f32s(n)?;
            let density_se = r.f32s(n)?;
            let total = r.f64s(2 * N_ALBEDO)?;
            let total_se = r.f64s(2 * N_ALBEDO)?;
            let finite = all_valid(density.iter().chain(&density_se))
                && all_valid(total.iter().chain(&total_se));
            if !finite {
                return Err(TableFileError("negative or non-finite value"));
            }
            out.push(Plane {
                eta,
                capped,
                density,
                density_se,
                total,
                total_se,
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

/// The half-space table's header for a grid of `dims` (planes, rows, bins) and η planes
/// `etas`.
fn header<'a>(dims: &'a [usize], etas: &'a [f64]) -> Header<'a> {
    Header {
        magic: MAGIC,
        version: VERSION,
        not_this_kind: "not a table file (bad magic)",
        dims,
        axes: etas,
        axes_differ: "refractive indices differ from this crate's",
    }
}

pub(crate) struct Reader<'a>(pub(crate) &'a [u8]);

impl<'a> Reader<'a> {
    /// The end of the data: an error if any bytes are left over.
    pub(crate) fn finish(self) -> Result<(), TableFileError> {
        if self.0.is_empty() {
            Ok(())
        } else {
            Err(TableFileError("trailing bytes"))
        }
    }

    pub(crate) fn take(&mut self, n: usize) -> Result<&'a [u8], TableFileError> {
        if self.0.len() < n {
            return Err(TableFileError("truncated"));
        }
        let (a, b) = self.0.split_at(n);
        self.0 = b;
        Ok(a)
    }
    pub(crate) fn u32(&mut self) -> Result<u32, TableFileError> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    pub(crate) fn u64(&mut self) -> Result<u64, TableFileError> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    pub(crate) fn f32(&mut self) -> Result<f32, TableFileError> {
        Ok(f32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    pub(crate) fn f64(&mut self) -> Result<f64, TableFileError> {
        Ok(f64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    pub(crate) fn f32s(&mut self, n: usize) -> Result<Vec<f32>, TableFileError> {
        (0..n).map(|_| self.f32()).collect()
    }
    pub(crate) fn f64s(&mut self, n: usize) -> Result<Vec<f64>, TableFileError> {
        (0..n).map(|_| self.f64()).collect()
    }
}

#[cfg(any(test, feature = "tabulate"))]
/// Simulates every plane with `photons` photons each (see [`super::simulate`]) and returns the
/// table; bit-identical for a given seed and photon count whatever `threads` is.
pub fn tabulate(
    seed: u64,
    photons: u64,
    threads: usize,
    mut progress: impl FnMut(usize),
) -> TableData {
    let planes = ETAS
        .iter()
        .enumerate()
        .map(|(i, &eta)| {
            let t = super::simulate::simulate(eta, i as u64, seed, photons, threads);
            progress(i);
            Plane::from_tally(eta, &t)
        })
        .collect();
    TableData {
        seed,
        photons,
        planes,
    }
}
