//! Per-material radius-sampling table (the idea of pbrt-v4's `BSSRDFTable`, §11.4 of the
//! pbrt book, with an exactly consistent piecewise-linear density instead of Catmull-Rom
//! splines).
//!
//! # Layout
//! Everything is in optical units of the reduced extinction (`x = σt' r`), using the scaling
//! law `R(r; kσ) = k² R(kr; σ)` (docs/physics.md#conventions); for a fixed `g` a profile in these units depends
//! only on the reduced albedo `α'` (the single-scattering albedo `ϖ = α'/(1 − g + gα')` and
//! `σt/σt' = 1/(1 − gϖ)` follow from it).
//! * Rows: 48 reduced albedos uniform in `s = √(1 − α')` (dense near `α' = 1`, where the
//!   totals vary like `e^{−√3 s}`).
//! * Columns: `x₀ = 0` and 127 radii geometric from `1e-4` to `1e5`.
//! * Each row stores `p_j = 2πx_j R₁(x_j)`, its trapezoid cumulative, an exponential tail
//!   `p_last e^{−(x − x_last)/x_last}` beyond the last radius (so the density is positive
//!   everywhere and sampling is unbiased for any profile), and the model's exact total.
//!
//! # Sampler
//! [`ProfileTable::sampler`] returns a [`RadiusSampler`] (no allocation) for `(σa, σs)`: it
//! mixes the two albedo rows around `s` with weights `(1 − t, t)`; `sample_r` picks a row with
//! those probabilities (by splitting `u`) and inverts that row's piecewise-linear CDF exactly
//! (a quadratic per cell), so `pdf_r = σt'[(1−t)p_i(x) + t p_{i+1}(x)]` is *exactly* the
//! sampled density. `total` (the effective albedo ρ_eff) is the Catmull-Rom interpolation of
//! the rows' exact totals in `s`; `eval` is `total·pdf_r/(2πr)`, an approximation of the
//! profile that is consistent with `total` (use [`crate::Profile::eval`] for the BSSRDF value
//! and this sampler for `sample_r`/`pdf_r`). `radius_for_fraction` inverts the mixture CDF
//! exactly. Building a table costs one profile evaluation per node plus one total per row
//! (measured ≈ 0.15 ms for the dipole, ≈ 40 ms for photon beam diffusion; `sampler()` +
//! `sample_r` + `pdf_r` ≈ 0.2 µs; `benches/profiles.rs`).

use crate::error::ParamError;
use crate::family::{ProfileFamily, SIGMA_EPSILON, validate_sigmas};
use crate::profile::{RadialProfile, TWO_PI, clean_f, clean_r, clean_u, optical};

const ROWS: usize = 48;
const COLS: usize = 128;
const X1: f64 = 1e-4;
const XLAST: f64 = 1e5;
/// Radius at which the `x₀ = 0` column is evaluated (finite limit of `2πxR`).
const X0_EVAL: f64 = 1e-6;

/// `log2(x)` for a positive normal `x`, within 0.005: the exponent plus a quadratic in the
/// mantissa (exact at powers of two). Used only to guess a table cell.
#[inline]
fn approx_log2(x: f64) -> f64 {
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as f64 - 1023.0;
    let m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000) - 1.0;
    e + m * (1.3465 - 0.3465 * m)
}

/// The per-family table; build once per material with [`ProfileTable::new`].
#[derive(Debug, Clone)]
pub struct ProfileTable {
    family: ProfileFamily,
    /// Radii, `COLS`.
    x: Vec<f64>,
    /// `ln q` of the geometric part.
    ln_q: f64,
    /// Row-major `2πxR₁` values, `ROWS × COLS`.
    p: Vec<f64>,
    /// Row-major cumulative trapezoid areas.
    c: Vec<f64>,
    /// Normaliser per row (area + tail).
    z: Vec<f64>,
    /// Exact model total per row.
    total: Vec<f64>,
    /// Guide table per row, `ROWS × (GUIDE + 1)`: entry k is the last node whose CDF is at
    /// most k / GUIDE, so that inverting the CDF at f searches only the nodes between the
    /// entries around f (a few instead of all `COLS`; the guide tables of CA74 in
    /// docs/references.md).
    guide: Vec<u8>,
}

/// Intervals of the guide table per row.
const GUIDE: usize = 32;

impl ProfileTable {
    /// Builds the table for `family` (see the module docs for cost).
    pub fn new(family: ProfileFamily) -> Self {
        let ln_q = (XLAST / X1).ln() / (COLS - 2) as f64;
        let mut x = vec![0.0; COLS];
        for (j, xj) in x.iter_mut().enumerate().skip(1) {
            *xj = X1 * ((j - 1) as f64 * ln_q).exp();
        }
        x[COLS - 1] = XLAST;
        let mut p = vec![0.0; ROWS * COLS];
        let mut total = vec![0.0; ROWS];
        let g = family.g();
        for i in 0..ROWS {
            let s = i as f64 / (ROWS - 1) as f64;
            let alpha_p = 1.0 - s * s;
            // σt' = 1: σa = 1 − α', σs = α'/(1 − g).
            // Always valid (|g| ≤ G_MAX keeps σs ≤ 1e6); a zero row is repaired below.
            let prof = family
                .profile(1.0 - alpha_p, alpha_p / (1.0 - g))
                .unwrap_or(crate::family::Profile::ZERO);
            total[i] = prof.total();
            let row = &mut p[i * COLS..(i + 1) * COLS];
            row[0] = TWO_PI * X0_EVAL * prof.eval(X0_EVAL);
            for j in 1..COLS {
                row[j] = TWO_PI * x[j] * prof.eval(x[j]);
            }
        }
        let mut c = vec![0.0; ROWS * COLS];
        let mut tail = vec![0.0; ROWS];
        let mut z = vec![0.0; ROWS];
        for i in 0..ROWS {
            let row = &p[i * COLS..(i + 1) * COLS];
            let cr = &mut c[i * COLS..(i + 1) * COLS];
            for j in 1..COLS {
                cr[j] = cr[j - 1] + 0.5 * (row[j - 1] + row[j]) * (x[j] - x[j - 1]);
            }
            tail[i] = row[COLS - 1] * XLAST;
            z[i] = cr[COLS - 1] + tail[i];
        }
        // Rows with no energy (α' = 0) borrow the shape of the nearest row that has some, so
        // every row is a proper density.
        for i in 0..ROWS {
            if z[i] <= 0.0 {
                let donor = (0..ROWS)
                    .filter(|&k| z[k] > 0.0)
                    .min_by_key(|&k| k.abs_diff(i));
                if let Some(k) = donor {
                    let (src_p, src_c) = (
                        p[k * COLS..(k + 1) * COLS].to_vec(),
                        c[k * COLS..(k + 1) * COLS].to_vec(),
                    );
                    p[i * COLS..(i + 1) * COLS].copy_from_slice(&src_p);
                    c[i * COLS..(i + 1) * COLS].copy_from_slice(&src_c);
                    tail[i] = tail[k];
                    z[i] = z[k];
                } else {
                    // Every row empty (impossible for valid families): exponential shape.
                    for j in 0..COLS {
                        p[i * COLS + j] = (-x[j]).exp();
                    }
                    for j in 1..COLS {
                        c[i * COLS + j] = c[i * COLS + j - 1]
                            + 0.5 * (p[i * COLS + j - 1] + p[i * COLS + j]) * (x[j] - x[j - 1]);
                    }
                    z[i] = c[i * COLS + COLS - 1];
                }
            }
        }
        let mut guide = vec![0u8; ROWS * (GUIDE + 1)];
        for i in 0..ROWS {
            let mut j = 0;
            for k in 0..=GUIDE {
                let level = k as f64 / GUIDE as f64;
                while j + 1 < COLS && c[i * COLS + j + 1] / z[i] <= level {
                    j += 1;
                }
                guide[i * (GUIDE + 1) + k] = j as u8;
            }
        }
        Self {
            family,
            x,
            ln_q,
            p,
            c,
            z,
            total,
            guide,
        }
    }

    /// The family the table was built for.
    pub fn family(&self) -> &ProfileFamily {
        &self.family
    }

    /// The effective albedo ρ_eff (total diffuse reflectance) at reduced albedo `alpha_p`
    /// (clamped to [0, 1]), interpolated from the rows' exact totals.
    pub fn rho_eff(&self, alpha_p: f64) -> f64 {
        let s = (1.0 - alpha_p.clamp(0.0, 1.0)).sqrt();
        self.total_at(s)
    }

    /// Inverts [`ProfileTable::rho_eff`]: the reduced albedo whose effective albedo is `rho`
    /// (clamped to the table's range; ρ_eff is monotone in α'). Bisection, ≈ 1 µs.
    pub fn invert_rho_eff(&self, rho: f64) -> f64 {
        let (mut lo, mut hi) = (0.0_f64, 1.0_f64); // in s: s = 0 ↔ α' = 1 (largest ρ)
        let rho_max = self.total_at(0.0);
        let rho_min = self.total_at(1.0);
        let rho = if rho.is_nan() {
            rho_min
        } else {
            rho.clamp(rho_min, rho_max)
        };
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.total_at(mid) > rho {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let s = 0.5 * (lo + hi);
        1.0 - s * s
    }

    fn total_at(&self, s: f64) -> f64 {
        let pos = s.clamp(0.0, 1.0) * (ROWS - 1) as f64;
        let i = (pos.floor() as usize).min(ROWS - 2);
        let t = pos - i as f64;
        let at = |k: isize| -> f64 {
            if k < 0 {
                2.0 * self.total[0] - self.total[1]
            } else if k as usize >= ROWS {
                2.0 * self.total[ROWS - 1] - self.total[ROWS - 2]
            } else {
                self.total[k as usize]
            }
        };
        let k = i as isize;
        let (p0, p1, p2, p3) = (at(k - 1), at(k), at(k + 1), at(k + 2));
        // Catmull-Rom on a uniform grid.
        let v = 0.5
            * (2.0 * p1
                + (p2 - p0) * t
                + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t * t
                + (3.0 * (p1 - p2) + p3 - p0) * t * t * t);
        v.max(0.0)
    }

    /// The sampler for coefficients `(σa, σs)` (1/length; validated like
    /// [`ProfileFamily::profile`]). Cost: a few ns, no allocation.
    pub fn sampler(&self, sigma_a: f64, sigma_s: f64) -> Result<RadiusSampler<'_>, ParamError> {
        let (sigma_a, sigma_s) = validate_sigmas(sigma_a, sigma_s)?;
        let sigma_sp = (1.0 - self.family.g()) * sigma_s;
        let sigma_tp = sigma_a + sigma_sp;
        if sigma_sp < SIGMA_EPSILON || sigma_tp < SIGMA_EPSILON {
            return Ok(RadiusSampler {
                table: self,
                row: 0,
                t: 0.0,
                scale: 0.0,
                total: 0.0,
            });
        }
        let alpha_p = sigma_sp / sigma_tp;
        let s = (1.0 - alpha_p).max(0.0).sqrt();
        let pos = s * (ROWS - 1) as f64;
        let row = (pos.floor() as usize).min(ROWS - 2);
        let t = (pos - row as f64).clamp(0.0, 1.0);
        Ok(RadiusSampler {
            table: self,
            row,
            t,
            scale: sigma_tp,
            total: self.total_at(s),
        })
    }

    #[inline]
    fn row_p(&self, i: usize) -> &[f64] {
        &self.p[i * COLS..(i + 1) * COLS]
    }
    #[inline]
    fn row_c(&self, i: usize) -> &[f64] {
        &self.c[i * COLS..(i + 1) * COLS]
    }

    /// Cell `j` with `x_j ≤ x < x_{j+1}` (`x < x_last`).
    #[inline]
    fn cell(&self, x: f64) -> usize {
        if x < self.x[1] {
            return 0;
        }
        // The guess is within one cell (the cells are 0.24 wide in log2, the approximation
        // 0.005 off); the loops below make it exact.
        let guess = (approx_log2(x) - X1.log2()) * (std::f64::consts::LN_2 / self.ln_q);
        let mut j = (1 + guess.max(0.0) as usize).min(COLS - 2);
        while j > 1 && self.x[j] > x {
            j -= 1;
        }
        while j < COLS - 2 && self.x[j + 1] <= x {
            j += 1;
        }
        j
    }

    /// Normalised density of the rows `rows` mixed with their weights, at optical radius `x`:
    /// the cell is found once for both rows.
    #[inline]
    fn rows_pdf(&self, rows: [(usize, f64); 2], x: f64) -> f64 {
        if x >= XLAST {
            let tail = (-(x - XLAST) / XLAST).exp();
            return rows
                .iter()
                .filter(|(_, w)| *w > 0.0)
                .map(|&(i, w)| w * self.row_p(i)[COLS - 1] * tail / self.z[i])
                .sum();
        }
        let j = self.cell(x);
        let (x0, x1) = (self.x[j], self.x[j + 1]);
        let f = (x - x0) / (x1 - x0);
        rows.iter()
            .filter(|(_, w)| *w > 0.0)
            .map(|&(i, w)| {
                let p = self.row_p(i);
                w * (p[j] + (p[j + 1] - p[j]) * f) / self.z[i]
            })
            .sum()
    }

    /// Normalised CDF of row `i` at node `j`.
    #[inline]
    fn row_cdf_node(&self, i: usize, j: usize) -> f64 {
        self.row_c(i)[j] / self.z[i]
    }

    /// The CDF of the mixture `Σ w_k row_k` (weights sum to 1) at optical radius `x ≥ 0`:
    /// the trapezoid cumulative to the cell, the linear density's area within it, and the
    /// exponential tail beyond the last radius.
    fn mixture_cdf(&self, rows: [(usize, f64); 2], x: f64) -> f64 {
        // The cell, once for both rows.
        let j = if x >= XLAST { 0 } else { self.cell(x) };
        let mut f = 0.0;
        for (i, w) in rows {
            if w <= 0.0 {
                continue;
            }
            let (p, z) = (self.row_p(i), self.z[i]);
            let row = if x >= XLAST {
                let last = self.row_cdf_node(i, COLS - 1);
                let tail = p[COLS - 1] * XLAST / z;
                last + tail * (-(-(x - XLAST) / XLAST).exp_m1())
            } else {
                let (x0, x1) = (self.x[j], self.x[j + 1]);
                let tau = (x - x0).clamp(0.0, x1 - x0);
                let slope = (p[j + 1] - p[j]) / (x1 - x0);
                self.row_cdf_node(i, j) + (p[j] * tau + 0.5 * slope * tau * tau) / z
            };
            f += w * row;
        }
        f.clamp(0.0, 1.0)
    }

    /// Inverts the CDF of the mixture `Σ w_k row_k` (weights sum to 1) at `f`.
    fn invert_mixture(&self, rows: [(usize, f64); 2], f: f64) -> f64 {
        let cdf = |j: usize| -> f64 {
            rows.iter()
                .map(|&(i, w)| {
                    if w > 0.0 {
                        w * self.row_cdf_node(i, j)
                    } else {
                        0.0
                    }
                })
                .sum()
        };
        let last = cdf(COLS - 1);
        if f >= last {
            // Both tails decay at the same rate 1/x_last.
            let rest = 1.0 - last;
            if rest <= 0.0 {
                return XLAST;
            }
            let q = ((1.0 - f) / rest).clamp(f64::MIN_POSITIVE, 1.0);
            return XLAST - XLAST * q.ln();
        }
        // First node with cdf > f: between the rows' guide entries around f, when the
        // mixture's CDF confirms they bracket it (it does but for rounding), else anywhere.
        let (mut lo, mut hi) = (0usize, COLS - 1);
        let k = ((f * GUIDE as f64) as usize).min(GUIDE - 1);
        let (mut g_lo, mut g_hi) = (COLS - 1, 0usize);
        for &(i, w) in &rows {
            if w > 0.0 {
                let g = &self.guide[i * (GUIDE + 1)..(i + 1) * (GUIDE + 1)];
                g_lo = g_lo.min(usize::from(g[k]));
                g_hi = g_hi.max((usize::from(g[k + 1]) + 1).min(COLS - 1));
            }
        }
        if g_lo < g_hi && cdf(g_lo) <= f && cdf(g_hi) > f {
            (lo, hi) = (g_lo, g_hi);
        }
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if cdf(mid) > f {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let j = lo;
        let pj: f64 = rows
            .iter()
            .map(|&(i, w)| {
                if w > 0.0 {
                    w * self.row_p(i)[j] / self.z[i]
                } else {
                    0.0
                }
            })
            .sum();
        let pj1: f64 = rows
            .iter()
            .map(|&(i, w)| {
                if w > 0.0 {
                    w * self.row_p(i)[j + 1] / self.z[i]
                } else {
                    0.0
                }
            })
            .sum();
        let h = self.x[j + 1] - self.x[j];
        let delta = (f - cdf(j)).max(0.0);
        // Area of the linear density over [x_j, x_j + τ] = p_j τ + (p_{j+1} − p_j) τ²/(2h).
        let a = (pj1 - pj) / (2.0 * h);
        let disc = (pj * pj + 4.0 * a * delta).max(0.0);
        let denom = pj + disc.sqrt();
        let tau = if denom > 0.0 {
            2.0 * delta / denom
        } else {
            0.0
        };
        self.x[j] + tau.clamp(0.0, h)
    }
}

/// Radius sampler at one `(σa, σs)` drawn from a [`ProfileTable`]; see the module docs.
#[derive(Debug, Clone, Copy)]
pub struct RadiusSampler<'a> {
    table: &'a ProfileTable,
    row: usize,
    t: f64,
    /// σt' (1/length); 0 for the zero profile.
    scale: f64,
    total: f64,
}

impl RadiusSampler<'_> {
    /// True when the coefficients give no scattering (zero profile).
    pub fn is_zero(&self) -> bool {
        self.scale == 0.0
    }
    fn rows(&self) -> [(usize, f64); 2] {
        [(self.row, 1.0 - self.t), (self.row + 1, self.t)]
    }

    /// The sampling density's cumulative distribution at radius `r` (length): the fraction
    /// of [`RadialProfile::sample_r`]'s draws below `r`, the exact integral of
    /// [`RadialProfile::pdf_r`] over `[0, r]` (in `[0, 1]`; 0 for the zero profile and for
    /// `r ≤ 0` or NaN, 1 at `r = ∞`). The inverse of [`RadialProfile::radius_for_fraction`].
    pub fn fraction_within(&self, r: f64) -> f64 {
        if self.is_zero() || r.is_nan() || r <= 0.0 {
            return 0.0;
        }
        if r == f64::INFINITY {
            return 1.0;
        }
        self.table.mixture_cdf(self.rows(), optical(r, self.scale))
    }
}

impl RadialProfile for RadiusSampler<'_> {
    fn eval(&self, r: f64) -> f64 {
        if self.is_zero() {
            return 0.0;
        }
        let r = clean_r(r).max(X0_EVAL / self.scale);
        self.total * self.pdf_r(r) / (TWO_PI * r)
    }
    fn total(&self) -> f64 {
        self.total
    }
    fn sample_r(&self, u: f64) -> Option<f64> {
        let u = clean_u(u)?;
        if self.is_zero() {
            return None;
        }
        let w0 = 1.0 - self.t;
        let (i, v) = if u < w0 {
            (self.row, u / w0)
        } else {
            (
                self.row + 1,
                ((u - w0) / self.t).min(1.0 - f64::EPSILON / 2.0),
            )
        };
        Some(self.table.invert_mixture([(i, 1.0), (i, 0.0)], v) / self.scale)
    }
    fn pdf_r(&self, r: f64) -> f64 {
        if self.is_zero() {
            return 0.0;
        }
        let x = optical(r, self.scale);
        self.scale * self.table.rows_pdf(self.rows(), x)
    }
    fn radius_for_fraction(&self, f: f64) -> f64 {
        if self.is_zero() {
            return 0.0;
        }
        self.table.invert_mixture(self.rows(), clean_f(f)) / self.scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ProfileModel, Scattering};

    /// `fraction_within` inverts `radius_for_fraction` and integrates `pdf_r` (midpoint rule
    /// on a fine geometric grid, independent of the table's own cumulative).
    #[test]
    fn fraction_within_is_the_cdf_of_the_sampling_density() {
        for model in [ProfileModel::Dipole, ProfileModel::Tabulated] {
            let family = ProfileFamily::new(model, Scattering::Multiple, 0.0, 1.3).unwrap();
            let t = ProfileTable::new(family);
            for (a, s) in [(0.1, 0.9), (0.01, 0.99), (1e-4, 2.0), (0.3, 1e3)] {
                let sm = t.sampler(a, s).unwrap();
                // Also on the guide table's levels k/32 and between them.
                for f in [0.01, 0.03125, 0.25, 0.3, 0.5, 0.7, 0.96875, 0.99, 0.999] {
                    let r = sm.radius_for_fraction(f);
                    let got = sm.fraction_within(r);
                    assert!((got - f).abs() < 1e-9, "{model:?} ({a}, {s}) f {f}: {got}");
                }
                let r_end = sm.radius_for_fraction(0.9);
                let n = 200_000;
                let (lo, hi) = (1e-9 * r_end, r_end);
                let q = (hi / lo).powf(1.0 / n as f64);
                let mut integral = 0.0;
                let mut x = lo;
                for _ in 0..n {
                    let x1 = x * q;
                    integral += sm.pdf_r(0.5 * (x + x1)) * (x1 - x);
                    x = x1;
                }
                integral += sm.fraction_within(lo);
                assert!(
                    (integral - 0.9).abs() < 1e-4,
                    "{model:?} ({a}, {s}): {integral}"
                );
            }
            let zero = t.sampler(0.0, 0.0).unwrap();
            assert_eq!(zero.fraction_within(1.0), 0.0);
            let sm = t.sampler(0.1, 1.0).unwrap();
            assert_eq!(sm.fraction_within(0.0), 0.0);
            assert_eq!(sm.fraction_within(f64::NAN), 0.0);
            assert_eq!(sm.fraction_within(f64::INFINITY), 1.0);
            assert!(sm.fraction_within(1e300) <= 1.0);
        }
    }

    /// The cell found from the approximate logarithm is the one a linear search finds, at
    /// random radii and on and next to every grid node.
    #[test]
    fn cell_matches_a_linear_search() {
        let family = ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.0)
            .expect("valid family");
        let t = ProfileTable::new(family);
        let linear = |x: f64| (0..COLS - 1).rfind(|&j| t.x[j] <= x).unwrap().min(COLS - 2);
        let mut xs: Vec<f64> = Vec::new();
        for j in 1..COLS - 1 {
            let v = t.x[j];
            xs.extend([
                v,
                v.next_up(),
                v.next_down(),
                v * (1.0 + 1e-9),
                v * (1.0 - 1e-9),
            ]);
        }
        let mut u = 0.5f64;
        for _ in 0..20_000 {
            u = (u * 3.7 + 0.123).fract();
            xs.push(X1 * (XLAST / X1).powf(u));
        }
        for x in xs.into_iter().filter(|&x| x < XLAST) {
            assert_eq!(t.cell(x), linear(x), "x = {x:e}");
        }
        for x in [1e-300, f64::MIN_POSITIVE, 0.5, 1.0, 2.0, 1024.0] {
            assert!((approx_log2(x) - x.log2()).abs() < 0.005, "log2 {x}");
        }
    }
}
