//! The angular coupling of the tabulated profile: how the light a half-space returns depends
//! on the pair of directions it arrives from and leaves toward, beyond the separable lobes.
//!
//! The renderer's BSSRDF is the separable form of pbrt-v4 §11.4 (`NormalizedFresnelBxDF`):
//!
//! S = R(r) · (1 − F_r(μ_i)) · (1 − F_r(μ_o)) / (c π),   c = 1 − 2 C₁(1/η),
//!
//! with R the exitance per unit power entering at normal incidence (the tabulated profile).
//! Integrated over the surface, a half-space then returns R_tot (1 − F_r(μ_i)) (1 − F_r(μ_o))
//! / (c π) per unit irradiance: the same angular shape at every albedo, and the same total for
//! light entering at every angle. Neither holds. Under a uniform sky at η = 1 and α = 0.9,
//! the path tracer's half-space seen at μ = 0.3 is 11 % brighter than this form predicts; at
//! α = 0.99 it is 6 % dimmer (docs/tabulated-profile.md, "Angular coupling").
//!
//! The coupling T(α, μ_i, μ_o; η) is the ratio of the exact surface-integrated response to
//! the separable one, both for cosine-weighted bins of incidence and exit (`angular_file`):
//!
//! T_jk = P_jk · N · c / (⟨1 − F_r⟩_j ⟨1 − F_r⟩_k R_tot),
//!
//! P_jk the simulated fraction of the power falling from bin j that leaves into bin k, N the
//! number of bins, ⟨1 − F_r⟩_j the bin's mean transmittance, and R_tot the half-space table's
//! total for the same η, albedo and scattering orders. Multiplying S by T makes the profile
//! exact for a flat homogeneous half-space under any distant light, in every direction and not
//! only at normal incidence, up to the azimuth (averaged) and the bins' resolution; the
//! radial shape stays the normal-incidence one. T is symmetric in (μ_i, μ_o) by reciprocity,
//! imposed on the data (P ← (P + Pᵀ)/2) and exactly by the lookup (its arguments ordered), so
//! S stays reciprocal bit for bit.

use std::sync::OnceLock;

use super::angular_file::{ANGULAR_ETAS, AngularData, N_MU, index};
use super::grid::N_ALBEDO;
use super::half_space::{AlbedoRow, table};
use crate::fresnel::{dielectric, fresnel_moment};
use crate::model::Scattering;

/// The data file built into the crate (regenerate with `het-bssrdf tabulate --angular`).
static DATA: &[u8] = include_bytes!("../../data/angular-coupling-v1.bin");

/// The built-in coupling data, parsed once.
pub fn angular_data() -> &'static AngularData {
    static DATA_PARSED: OnceLock<AngularData> = OnceLock::new();
    DATA_PARSED.get_or_init(|| {
        AngularData::from_bytes(DATA).expect("the built-in angular coupling data is valid (tested)")
    })
}

/// ⟨1 − F_r⟩ over the cosine bin `j` for light crossing a boundary of relative index `eta`
/// from outside: the mean over μ² uniform in the bin (midpoint rule, 64 nodes).
pub fn bin_transmission(j: usize, eta: f64) -> f64 {
    const NODES: usize = 64;
    (0..NODES)
        .map(|m| {
            let mu2 = (j as f64 + (m as f64 + 0.5) / NODES as f64) / N_MU as f64;
            1.0 - dielectric(mu2.sqrt(), eta)
        })
        .sum::<f64>()
        / NODES as f64
}

/// The angular coupling T for one η and choice of scattering orders: per albedo row, an
/// N × N symmetric matrix over cosine bins. About 10 KB; built once per material.
#[derive(Debug, Clone, PartialEq)]
pub struct AngularCoupling {
    /// `[row][j][k]`.
    t: Vec<f32>,
}

impl AngularCoupling {
    /// The coupling at relative index `eta` (clamped to [1, 1.6]; linear between the data's
    /// planes, 0.1 apart) for the scattering orders `scattering` selects, as the tabulated
    /// profile of a [`crate::ProfileFamily`] with the same [`Scattering`] counts them.
    pub fn new(eta: f64, scattering: Scattering) -> Self {
        let (single, multiple) = (scattering.includes_single(), scattering.includes_multiple());
        let (q, f) = super::grid::eta_bracket(&ANGULAR_ETAS, eta);
        let lo = Self::plane(q, single, multiple);
        let hi = Self::plane(q + 1, single, multiple);
        let t = lo
            .iter()
            .zip(&hi)
            .map(|(a, b)| ((1.0 - f) * a + f * b) as f32)
            .collect();
        Self { t }
    }

    /// T at the data's plane `q` (`[row][j][k]`, f64).
    fn plane(q: usize, single: bool, multiple: bool) -> Vec<f64> {
        let data = &angular_data().planes[q];
        let eta = data.eta;
        // The half-space table's plane with the same η (every other plane).
        let totals = &table().planes[2 * q];
        debug_assert_eq!(totals.eta, eta);
        let c = 1.0 - 2.0 * fresnel_moment(1, 1.0 / eta);
        let a: Vec<f64> = (0..N_MU).map(|j| bin_transmission(j, eta)).collect();
        // The normalisation's quadrature over the incidence (below): 256 midpoints in μ², each
        // the cells of (μ, 1) and the transmittance 1 − F_r(μ); the same for every row.
        const NODES: usize = 256;
        let nodes: Vec<(Cells, f64)> = (0..NODES)
            .map(|n| {
                let mu = ((n as f64 + 0.5) / NODES as f64).sqrt();
                (Cells::new(mu, 1.0), 1.0 - dielectric(mu, eta))
            })
            .collect();
        let den: f64 = nodes.iter().map(|(_, w)| w).sum();
        let kinds = [single, multiple];
        let mut t = vec![1.0; N_ALBEDO * N_MU * N_MU];
        for row in 0..N_ALBEDO {
            let r_tot: f64 = (0..2)
                .filter(|&k| kinds[k])
                .map(|k| totals.total[k * N_ALBEDO + row])
                .sum();
            let p = |j: usize, k: usize| -> f64 {
                (0..2)
                    .filter(|&kind| kinds[kind])
                    .map(|kind| f64::from(data.p[index(kind, row, j, k)]))
                    .sum()
            };
            let m = &mut t[row * N_MU * N_MU..(row + 1) * N_MU * N_MU];
            for j in 0..N_MU {
                for k in 0..N_MU {
                    let sym = 0.5 * (p(j, k) + p(k, j));
                    let den = a[j] * a[k] * r_tot;
                    let v = sym * N_MU as f64 * c / den;
                    if den > 1e-12 && v.is_finite() {
                        m[j * N_MU + k] = v;
                    }
                }
            }
            // Normalised at normal exit under uniform light: there the separable form already
            // returns the normal-incidence total (reciprocity). The integral runs over the
            // lookup itself, so the normalisation holds for the values the renderer reads.
            let num: f64 = nodes
                .iter()
                .map(|(cells, w)| w * cells.eval(|j, k| m[j * N_MU + k]))
                .sum();
            let rho = num / den;
            if rho.is_finite() && rho > 0.0 {
                m.iter_mut().for_each(|v| *v /= rho);
            }
        }
        t
    }

    /// T(α, μ_i, μ_o) (unitless, finite and ≥ 0 for every input): bilinear in μ² between the
    /// bins' centres, extrapolated linearly over the half bins beyond the outer centres (to
    /// μ = 0 and μ = 1), linear between albedo rows as the tabulated profile is. Exactly
    /// symmetric in (`mu_i`, `mu_o`). Non-finite arguments give 1.
    pub fn factor(&self, alpha: f64, mu_i: f64, mu_o: f64) -> f64 {
        self.factors([alpha; 1], mu_i, mu_o)[0]
    }

    /// [`AngularCoupling::factor`] for several albedos (the channels of one pair) at the same
    /// pair of cosines: the cosines' cells are found once, and a channel whose albedo equals the
    /// previous one's reuses its value.
    pub fn factors<const N: usize>(&self, alpha: [f64; N], mu_i: f64, mu_o: f64) -> [f64; N] {
        self.factors_on(AlbedoRow::of_each(alpha), mu_i, mu_o)
    }

    /// [`AngularCoupling::factors`] at albedos already placed on the grid (`None`: a
    /// non-finite albedo, which reads 1).
    pub(crate) fn factors_on<const N: usize>(
        &self,
        rows: [Option<AlbedoRow>; N],
        mu_i: f64,
        mu_o: f64,
    ) -> [f64; N] {
        let mut out = [1.0; N];
        if !(mu_i.is_finite() && mu_o.is_finite()) {
            return out;
        }
        let cells = Cells::new(mu_i, mu_o);
        for ch in 0..N {
            out[ch] = match rows[ch] {
                _ if ch > 0 && rows[ch] == rows[ch - 1] => out[ch - 1],
                Some(row) => self.at(&cells, row),
                None => 1.0,
            };
        }
        out
    }

    /// T at an albedo's `row` and the cosines' `cells`.
    fn at(&self, cells: &Cells, row: AlbedoRow) -> f64 {
        let (r0, fr) = row.position(N_ALBEDO);
        let row = |r: usize| {
            let m = &self.t[r * N_MU * N_MU..(r + 1) * N_MU * N_MU];
            cells.eval(|j, k| f64::from(m[j * N_MU + k]))
        };
        let v = if fr == 0.0 {
            row(r0)
        } else {
            (1.0 - fr) * row(r0) + fr * row(r0 + 1)
        };
        v.max(0.0)
    }
}

/// Where two cosines fall on the bins' centres in μ² (ordered, so that what is evaluated from
/// them is symmetric bit for bit): the lower cell index and the weight of the next, per
/// cosine, the weight in [−½, 3/2] over the outer half bins (linear extrapolation).
#[derive(Clone, Copy)]
pub(super) struct Cells {
    j: usize,
    fj: f64,
    k: usize,
    fk: f64,
}

impl Cells {
    pub(super) fn new(mu_a: f64, mu_b: f64) -> Self {
        let (a, b) = if mu_a <= mu_b {
            (mu_a, mu_b)
        } else {
            (mu_b, mu_a)
        };
        let cell = |mu: f64| {
            let x = mu.clamp(0.0, 1.0).powi(2) * N_MU as f64 - 0.5;
            let i = (x.max(0.0) as usize).min(N_MU - 2);
            (i, x - i as f64)
        };
        let ((j, fj), (k, fk)) = (cell(a), cell(b));
        Self { j, fj, k, fk }
    }

    /// The four corners `(j, k)` of the cell (j the lower cosine's bin) with their bilinear
    /// weights, in a fixed order.
    #[inline]
    pub(super) fn corners(&self) -> [((usize, usize), f64); 4] {
        let Self { j, fj, k, fk } = *self;
        [
            ((j, k), (1.0 - fj) * (1.0 - fk)),
            ((j, k + 1), (1.0 - fj) * fk),
            ((j + 1, k), fj * (1.0 - fk)),
            ((j + 1, k + 1), fj * fk),
        ]
    }

    /// The matrix `m(j, k)` (values at the bins' centres) interpolated at the two cosines.
    #[inline]
    pub(super) fn eval(&self, m: impl Fn(usize, usize) -> f64) -> f64 {
        let Self { j, fj, k, fk } = *self;
        (1.0 - fj) * ((1.0 - fk) * m(j, k) + fk * m(j, k + 1))
            + fj * ((1.0 - fk) * m(j + 1, k) + fk * m(j + 1, k + 1))
    }
}

#[cfg(test)]
mod tests {
    use super::super::angular_file::{AngularData, simulate_plane};
    use super::super::grid::ETAS;
    use super::*;

    #[test]
    fn planes_are_every_other_plane_of_the_half_space_table() {
        for (q, &eta) in ANGULAR_ETAS.iter().enumerate() {
            assert_eq!(ETAS[2 * q], eta);
            assert_eq!(angular_data().planes[q].eta, eta);
        }
    }

    #[test]
    fn built_in_data_round_trips_and_rejects_damage() {
        let d = angular_data();
        let bytes = d.to_bytes();
        assert_eq!(
            bytes, DATA,
            "the built-in file is what its parse writes back"
        );
        assert_eq!(AngularData::from_bytes(&bytes).as_ref(), Ok(d));
        assert!(AngularData::from_bytes(&bytes[..bytes.len() - 1]).is_err());
        let mut bad = bytes.clone();
        bad[0] = b'X';
        assert!(AngularData::from_bytes(&bad).is_err());
        let mut trailing = bytes;
        trailing.push(0);
        assert!(AngularData::from_bytes(&trailing).is_err());
    }

    #[test]
    fn simulation_is_independent_of_the_thread_count() {
        let a = simulate_plane(3, 7, 2_000, 1);
        let b = simulate_plane(3, 7, 2_000, 3);
        assert_eq!(a, b);
        assert!(a.p.iter().any(|&v| v > 0.0));
    }

    #[test]
    fn factor_is_symmetric_bit_for_bit_and_finite_everywhere() {
        let values = [
            -1.0,
            0.0,
            1e-9,
            0.1,
            0.3,
            0.5,
            0.77,
            0.999,
            1.0,
            2.0,
            f64::NAN,
            f64::INFINITY,
        ];
        for eta in [1.0, 1.05, 1.3, 1.6, 3.0, f64::NAN] {
            for &scattering in Scattering::ALL {
                let c = AngularCoupling::new(eta, scattering);
                for &alpha in &values {
                    for &a in &values {
                        for &b in &values {
                            let (x, y) = (c.factor(alpha, a, b), c.factor(alpha, b, a));
                            assert!(x.is_finite() && x >= 0.0, "{eta} {alpha} {a} {b}: {x}");
                            assert_eq!(x.to_bits(), y.to_bits(), "{eta} {alpha} {a} {b}");
                        }
                    }
                }
            }
        }
    }
}
