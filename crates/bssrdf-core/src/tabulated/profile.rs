//! The tabulated profile as a [`RadialProfile`]: interpolated in radius, albedo and η.

use std::sync::OnceLock;

use super::file::TableData;
use super::grid::{
    BINS_PER_DECADE, ETAS, N_ALBEDO, N_BINS, S_MIN, X_FIRST, X_LAST, annulus_area, centre, edge,
};
use crate::profile::{RadialProfile, TWO_PI, clean_f, clean_u, optical};

/// The data file built into the crate (regenerate with the `tabulate` example or
/// `het-bssrdf tabulate`).
static DATA: &[u8] = include_bytes!("../../data/halfspace-profile-v1.bin");

/// Relative standard error below which a radial bin is used alone (see
/// [`super::file::Plane::pool_sparse_bins`]).
pub const POOL_REL_SE: f64 = 0.1;

/// The built-in table, parsed once, with sparse bins pooled.
pub fn table() -> &'static TableData {
    static TABLE: OnceLock<TableData> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t =
            TableData::from_bytes(DATA).expect("the built-in profile table is valid (tested)");
        for p in &mut t.planes {
            p.pool_sparse_bins(POOL_REL_SE);
        }
        t
    })
}

/// Largest η the table covers.
pub const ETA_MAX: f64 = ETAS[ETAS.len() - 1];

/// One evaluation corner of a table: plane (the half-space table's η plane, or the slab
/// table's thickness-major plane), albedo row, weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Corner {
    pub(crate) plane: u8,
    pub(crate) row: u8,
    pub(crate) w: f64,
}

/// The tabulated profile at one `(σt, α, η)`, for the scattering orders selected. `Copy`; a
/// few dozen bytes; evaluating costs a handful of table reads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TabulatedTerm {
    /// σt (1/length).
    sigma_t: f64,
    /// Which kinds (single, multiple) are counted.
    kinds: [bool; 2],
    /// Four η planes (Lagrange weights) × two albedo rows (linear weights).
    corners: [Corner; 8],
}

impl TabulatedTerm {
    /// The profile for extinction `sigma_t` (> 0), albedo `alpha` ∈ [0, 1] and `eta` ∈ [1,
    /// [`ETA_MAX`]] (clamped), counting single and/or multiple scattering.
    pub fn new(sigma_t: f64, alpha: f64, eta: f64, single: bool, multiple: bool) -> Self {
        let (first, we) = eta_weights(eta, &ETAS);
        let (r0, fr) = row_position(alpha, N_ALBEDO);
        let c = |dp: usize, dr: usize| Corner {
            plane: (first + dp).min(ETAS.len() - 1) as u8,
            row: (r0 + dr) as u8,
            w: we[dp] * if dr == 0 { 1.0 - fr } else { fr },
        };
        Self {
            sigma_t,
            kinds: [single, multiple],
            corners: [
                c(0, 0),
                c(0, 1),
                c(1, 0),
                c(1, 1),
                c(2, 0),
                c(2, 1),
                c(3, 0),
                c(3, 1),
            ],
        }
    }

    /// R̂ summed over the selected kinds and interpolated corners, in bin `j` (1/mfp²);
    /// never negative (the quadratic weights can overshoot where a bin is nearly empty).
    #[inline]
    pub(crate) fn bin_value(&self, j: usize) -> f64 {
        let t = table();
        let mut v = 0.0;
        for c in &self.corners {
            if c.w == 0.0 {
                continue;
            }
            let plane = &t.planes[c.plane as usize];
            for kind in 0..2 {
                if self.kinds[kind] {
                    let i = (kind * N_ALBEDO + c.row as usize) * N_BINS + j;
                    v += c.w * f64::from(plane.density[i]);
                }
            }
        }
        v.max(0.0)
    }

    /// R̂ at optical radius `x` ([`radial_value`]).
    fn value(&self, x: f64) -> f64 {
        radial_value(x, |j| self.bin_value(j))
    }

    /// Probability mass of each bin (sums to ≤ 1 before normalisation) and their total. A scan
    /// of every bin (about 1,000 table reads): `sample_r`, `pdf_r` and `radius_for_fraction`
    /// pay it on each call, which suits per-material use; a renderer samples radii through
    /// [`crate::ProfileTable`], built once from `eval` and `total`.
    fn masses(&self) -> ([f64; N_BINS], f64) {
        let mut m = [0.0; N_BINS];
        let mut total = 0.0;
        for (j, mj) in m.iter_mut().enumerate() {
            *mj = self.bin_value(j) * annulus_area(j);
            total += *mj;
        }
        (m, total)
    }
}

/// Integer part and fraction of a grid position `p ∈ [0, n − 1]`, with the integer part at
/// most `n − 2` (so that `i + 1` is a valid index).
fn split(p: f64, n: usize) -> (usize, f64) {
    let i = (p.floor() as usize).min(n - 2);
    (i, (p - i as f64).clamp(0.0, 1.0))
}

/// Lagrange weights for `eta` on the uniform grid `etas` (at least 3 planes; `eta` clamped to
/// its range): the first of the four planes used and their weights. Cubic through the four
/// planes around `eta`, quadratic in the first and last interval: exact at the planes and
/// continuous between them. Linear interpolation between planes 0.15 apart would miss the
/// totals' curvature by several times the table's noise near α = 1 (measured; see
/// docs/tabulated-profile.md). The fourth weight is 0 in the end intervals.
pub(crate) fn eta_weights(eta: f64, etas: &[f64]) -> (usize, [f64; 4]) {
    let n = etas.len();
    let last = (n - 1) as f64;
    let pe = ((eta - etas[0]) / (etas[1] - etas[0])).clamp(0.0, last);
    let i = (pe.floor() as usize).min(n - 2);
    if i == 0 || i == n - 2 {
        // Quadratic through nodes mid − 1, mid, mid + 1 at t = pe − mid.
        let mid = i.clamp(1, n - 2);
        let t = pe - mid as f64;
        (
            mid - 1,
            [0.5 * t * (t - 1.0), 1.0 - t * t, 0.5 * t * (t + 1.0), 0.0],
        )
    } else {
        let u = pe - i as f64;
        (
            i - 1,
            [
                -u * (u - 1.0) * (u - 2.0) / 6.0,
                (u + 1.0) * (u - 1.0) * (u - 2.0) / 2.0,
                -(u + 1.0) * u * (u - 2.0) / 2.0,
                (u + 1.0) * u * (u - 1.0) / 6.0,
            ],
        )
    }
}

/// The albedo rows around `alpha` on a grid of `rows` rows with `s = √(1 − α)` geometric from
/// [`S_MIN`] to 1 (linear in log s; larger albedos use the first row): the lower row and the
/// weight of the next.
pub(crate) fn row_position(alpha: f64, rows: usize) -> (usize, f64) {
    let s = (1.0 - alpha.clamp(0.0, 1.0)).sqrt();
    let pr = if s <= S_MIN {
        0.0
    } else {
        ((s / S_MIN).ln() / (1.0 / S_MIN).ln() * (rows - 1) as f64).clamp(0.0, (rows - 1) as f64)
    };
    split(pr, rows)
}

/// A binned density (`bin(j)`, 1/mfp², on the grid of [`super::grid`]) at optical radius `x`:
/// log–log interpolation between bin centres (linear where a neighbour is 0, constant inside
/// the first bin's centre, 0 from the last edge on).
pub(crate) fn radial_value(x: f64, bin: impl Fn(usize) -> f64) -> f64 {
    if x >= X_LAST {
        return 0.0;
    }
    if x <= centre(0) {
        return bin(0);
    }
    if x < centre(1) {
        let f = (x - centre(0)) / (centre(1) - centre(0));
        return (1.0 - f) * bin(0) + f * bin(1);
    }
    let u = (x / X_FIRST).log10() * BINS_PER_DECADE as f64 + 0.5;
    let j = (u as usize).clamp(1, N_BINS - 1);
    if j >= N_BINS - 1 {
        return bin(N_BINS - 1);
    }
    let f = (u - j as f64).clamp(0.0, 1.0);
    let (a, b) = (bin(j), bin(j + 1));
    if a > 0.0 && b > 0.0 {
        (a.ln() * (1.0 - f) + b.ln() * f).exp()
    } else {
        (1.0 - f) * a + f * b
    }
}

impl RadialProfile for TabulatedTerm {
    fn eval(&self, r: f64) -> f64 {
        let x = optical(r, self.sigma_t);
        self.sigma_t * self.sigma_t * self.value(x)
    }
    /// The simulated totals (every exit, also beyond the last bin), interpolated.
    fn total(&self) -> f64 {
        let t = table();
        self.corners
            .iter()
            .map(|c| {
                let plane = &t.planes[c.plane as usize];
                (0..2)
                    .filter(|&k| self.kinds[k])
                    .map(|k| c.w * plane.total[k * N_ALBEDO + c.row as usize])
                    .sum::<f64>()
            })
            .sum::<f64>()
            .max(0.0)
    }
    /// Exact inversion of the binned density: a bin by its mass, then uniform in area within
    /// its annulus.
    fn sample_r(&self, u: f64) -> Option<f64> {
        let u = clean_u(u)?;
        let (m, total) = self.masses();
        if total <= 0.0 {
            return None;
        }
        let target = u * total;
        let mut acc = 0.0;
        for (j, &mj) in m.iter().enumerate() {
            if mj > 0.0 && (acc + mj > target || j == N_BINS - 1) {
                let f = ((target - acc) / mj).clamp(0.0, 1.0);
                let (a, b) = (edge(j), edge(j + 1));
                return Some((a * a + f * (b * b - a * a)).sqrt() / self.sigma_t);
            }
            acc += mj;
        }
        None
    }
    fn pdf_r(&self, r: f64) -> f64 {
        let x = optical(r, self.sigma_t);
        if x >= X_LAST {
            return 0.0;
        }
        let j = super::grid::bin_of(x).unwrap_or(N_BINS - 1);
        let (m, total) = self.masses();
        if total <= 0.0 {
            return 0.0;
        }
        self.sigma_t * m[j] / total * TWO_PI * x / annulus_area(j)
    }
    fn radius_for_fraction(&self, f: f64) -> f64 {
        let f = clean_f(f);
        let (m, total) = self.masses();
        if total <= 0.0 {
            return 0.0;
        }
        let target = f * total;
        let mut acc = 0.0;
        for (j, &mj) in m.iter().enumerate() {
            if acc + mj >= target && mj > 0.0 {
                let g = ((target - acc) / mj).clamp(0.0, 1.0);
                let (a, b) = (edge(j), edge(j + 1));
                return (a * a + g * (b * b - a * a)).sqrt() / self.sigma_t;
            }
            acc += mj;
        }
        X_LAST / self.sigma_t
    }
}
