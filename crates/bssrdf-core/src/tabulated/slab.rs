//! The tabulated slab profile: multiple-scattering reflection and transmission of a
//! homogeneous, isotropically scattering slab of finite thickness, simulated by this
//! project's own photon tracer ([`super::slab_file`]) like the half-space table
//! (docs/tabulated-profile.md, "The slab table").
//!
//! For a slab of thickness `d` with a pencil beam entering one face along its normal, the
//! light leaving the entry face at distance `r` from the beam and the opposite face at
//! distance `ρ` from the beam's axis (measured in the plane of that face) are
//!
//! ```text
//! R_slab(r; σt, α, η, d) = σt² · R̂(σt r; α, η, σt d),
//! T_slab(ρ; σt, α, η, d) = σt² · T̂(σt ρ; α, η, σt d),
//! ```
//!
//! exitance per unit area (1/length²) per unit power entering the medium, after the Fresnel
//! transmission of a smooth dielectric at either face (the convention of every profile in this
//! crate; no 1/π, no exit Fresnel factor of the BSSRDF). Multiple scattering only (two or
//! more events). Interpolation: cubic Lagrange in η ([`SLAB_ETAS`], as the half-space table),
//! linear in log √(1 − α) between [`SLAB_ROWS`] rows, linear in log d between the
//! [`SLAB_THICKNESSES`], and log–log in radius between bin centres. Outside the thickness
//! grid: below the first thickness the first plane scaled by d / d₀ (R and T vanish as
//! d → 0); between the last, d_max = 16 mfp, and 2 d_max the last plane and the half-space
//! table's multiple scattering (whose transmission is 0) blended linearly in d, and from
//! 2 d_max on the half-space table alone, so that the limit d → ∞ is the half-space table
//! exactly. (At α = 0.99, σtr·d_max ≈ 2.8: the transmission of a 32 mfp slab is about 0.4 %
//! of its exitance; at α = 0.999 the blend is an approximation, see
//! docs/tabulated-profile.md.)

use std::sync::OnceLock;

use super::half_space::{
    Corner, POOL_REL_SE, RowTotals, TabulatedTerm, conserve_bin_masses, eta_weights, radial_value,
    row_position, totals_between_rows,
};
use super::slab_file::{SlabData, SlabPlane};

pub use super::grid::{SLAB_ETAS, SLAB_ROWS, SLAB_THICKNESSES, slab_albedo_of_row, slab_s_of_row};

/// The data file built into the crate (regenerate with `het-bssrdf tabulate --slab`).
static DATA: &[u8] = include_bytes!("../../data/slab-profile-v1.bin");

/// The built-in slab table, parsed once, with sparse bins pooled.
pub fn slab_table() -> &'static SlabData {
    static TABLE: OnceLock<SlabData> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = SlabData::from_bytes(DATA).expect("the built-in slab table is valid (tested)");
        for p in &mut t.planes {
            p.pool_sparse_bins(POOL_REL_SE);
            conserve_bin_masses(&mut p.density);
        }
        t
    })
}

/// The slab table's [`RowTotals`] per plane and face (`[2 · plane + face]`), single and
/// multiple scattering.
fn slab_row_totals() -> &'static [RowTotals] {
    static TOTALS: OnceLock<Vec<RowTotals>> = OnceLock::new();
    TOTALS.get_or_init(|| {
        slab_table()
            .planes
            .iter()
            .flat_map(|p| {
                (0..2).map(move |f| {
                    RowTotals::new(
                        SLAB_ROWS,
                        |r| p.single[f * SLAB_ROWS + r],
                        |r| p.total[f * SLAB_ROWS + r],
                    )
                })
            })
            .collect()
    })
}

/// The face of a slab a point of exit lies on, relative to the point of entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlabFace {
    /// The face the light entered through: R_slab.
    Reflection,
    /// The opposite face: T_slab.
    Transmission,
}

impl SlabFace {
    fn index(self) -> usize {
        match self {
            SlabFace::Reflection => 0,
            SlabFace::Transmission => 1,
        }
    }
}

/// The slab profile at one `(σt, α, η, d)`, multiple scattering. `Copy`; evaluating costs a
/// few dozen table reads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlabTerm {
    /// σt (1/length).
    sigma_t: f64,
    /// Two thicknesses × four η planes × two rows.
    corners: [Corner; 16],
    /// Weight of the half-space table (thicknesses beyond the last plane), and its term.
    half_space: (f64, TabulatedTerm),
    /// Per face (reflection, transmission): the factor that brings the corners' total
    /// (linear between albedo rows) to the face's total with the rows' totals interpolated
    /// cubically, as the half-space table's ([`TabulatedTerm::new`]); both also carry
    /// [`SlabTerm::with_scale`].
    scale: [f64; 2],
}

impl SlabTerm {
    /// Whether the slab of thickness `thickness` (length) at extinction `sigma_t` is the
    /// half-space as far as the table goes: σt·d ≥ 2 d_max, where [`SlabTerm::new`] gives the
    /// half-space table's multiple scattering alone and no transmission (module docs).
    #[inline]
    pub fn is_half_space(sigma_t: f64, thickness: f64) -> bool {
        thickness * sigma_t >= 2.0 * SLAB_THICKNESSES[SLAB_THICKNESSES.len() - 1]
    }

    /// The smallest thickness (length) [`SlabTerm::is_half_space`] accepts at extinction
    /// `sigma_t`, up to one rounding (+∞ for `sigma_t` = 0).
    #[inline]
    pub fn half_space_thickness(sigma_t: f64) -> f64 {
        let d = 2.0 * SLAB_THICKNESSES[SLAB_THICKNESSES.len() - 1] / sigma_t;
        // One ulp up where the quotient rounded down below the predicate.
        if Self::is_half_space(sigma_t, d) {
            d
        } else {
            d.next_up()
        }
    }

    /// The slab profile for extinction `sigma_t` (> 0), albedo `alpha` ∈ [0, 1], `eta` ∈ [1,
    /// 1.6] (clamped) and thickness `thickness` (length, ≥ 0, +∞ for the half-space).
    pub fn new(sigma_t: f64, alpha: f64, eta: f64, thickness: f64) -> Self {
        let tau = (thickness * sigma_t).max(0.0);
        let n_d = SLAB_THICKNESSES.len();
        let (d0, d_max) = (SLAB_THICKNESSES[0], SLAB_THICKNESSES[n_d - 1]);
        // (lower plane, weight of the upper one, scale of the slab part, half-space weight)
        let (i, fd, scale, w_hs) = if tau <= d0 {
            (0, 0.0, tau / d0, 0.0)
        } else if tau >= d_max {
            let w = (2.0 - tau / d_max).clamp(0.0, 1.0);
            (n_d - 2, 1.0, w, 1.0 - w)
        } else {
            let p = (tau / d0).log2();
            let i = (p.floor() as usize).min(n_d - 2);
            (i, (p - i as f64).clamp(0.0, 1.0), 1.0, 0.0)
        };
        let (first, we) = eta_weights(eta, &SLAB_ETAS);
        let (r0, fr) = row_position(alpha, SLAB_ROWS);
        let mut corners = [Corner {
            plane: 0,
            row: 0,
            w: 0.0,
        }; 16];
        for (k, c) in corners.iter_mut().enumerate() {
            let (dd, de, dr) = (k / 8, (k / 2) % 4, k % 2);
            let e = (first + de).min(SLAB_ETAS.len() - 1);
            *c = Corner {
                plane: ((i + dd) * SLAB_ETAS.len() + e) as u8,
                row: (r0 + dr) as u8,
                w: scale
                    * (if dd == 0 { 1.0 - fd } else { fd })
                    * we[de]
                    * (if dr == 0 { 1.0 - fr } else { fr }),
            };
        }
        // The faces' totals between rows (totals_between_rows; the shape stays linear).
        let t = slab_table();
        let face_scale = |f: usize| {
            let linear: f64 = corners
                .iter()
                .map(|c| c.w * t.planes[c.plane as usize].total[f * SLAB_ROWS + c.row as usize])
                .sum();
            // The (thickness × η) planes the corners use, mixed, between the rows.
            let rt = slab_row_totals();
            let planes = || {
                corners.chunks_exact(2).filter_map(|pair| {
                    let wp = pair[0].w + pair[1].w;
                    (wp != 0.0).then(|| (wp, &rt[2 * pair[0].plane as usize + f]))
                })
            };
            let (_, want) = totals_between_rows(
                alpha,
                SLAB_ROWS,
                planes().map(|(w, p)| w * p.single).sum(),
                |r| planes().map(|(w, p)| w * p.all[r]).sum(),
            );
            if linear > 0.0 && want.is_finite() {
                want / linear
            } else {
                1.0
            }
        };
        Self {
            sigma_t,
            corners,
            half_space: (
                w_hs,
                TabulatedTerm::new(sigma_t, alpha, eta.min(1.6), false, true),
            ),
            scale: [face_scale(0), face_scale(1)],
        }
    }

    /// The same slab with both faces (the slab part and the half-space blend alike)
    /// multiplied by `k` (≥ 0): how the family gives an anisotropic medium its own
    /// multiple-scattering total (`crate::slab_profile`).
    pub fn with_scale(mut self, k: f64) -> Self {
        if k.is_finite() && k >= 0.0 {
            self.scale[0] *= k;
            self.scale[1] *= k;
            let hs = &self.half_space.1;
            self.half_space.1 = hs.scaled_to(k * crate::profile::RadialProfile::total(hs));
        }
        self
    }

    fn sum_corners(&self, mut read: impl FnMut(&SlabPlane, usize) -> f64) -> f64 {
        let t = slab_table();
        self.corners
            .iter()
            .filter(|c| c.w != 0.0)
            .map(|c| c.w * read(&t.planes[c.plane as usize], c.row as usize))
            .sum()
    }

    /// The interpolated density of `face` in bin `j` (1/mfp²) over the η corners of thickness
    /// plane and albedo row `k` (0–3: thinner lower row, thinner upper row, thicker lower
    /// row, thicker upper row), never negative.
    fn bin_value(&self, face: SlabFace, k: usize, j: usize) -> f64 {
        let f = face.index();
        let t = slab_table();
        let v: f64 = self
            .corners
            .iter()
            .skip(8 * (k / 2) + k % 2)
            .step_by(2)
            .take(4)
            .filter(|c| c.w != 0.0)
            .map(|c| {
                c.w * f64::from(
                    t.planes[c.plane as usize].density[SlabPlane::index(f, c.row as usize, j)],
                )
            })
            .sum();
        (self.scale[f] * v).max(0.0)
    }

    /// R_slab(r) or T_slab(ρ) (1/length²) at distance `r` (length; negative or NaN count as
    /// 0) from the beam (reflection) or from its axis (transmission). Finite, ≥ 0. The two
    /// thickness planes and the half-space blend are interpolated in radius each on its own
    /// and then mixed: the transmission changes by orders of magnitude from one thickness
    /// plane to the next, and log–log interpolation of the mixed bins would lose the bins'
    /// mass conservation by up to 0.35 %.
    pub fn eval(&self, face: SlabFace, r: f64) -> f64 {
        let x = crate::profile::optical(r, self.sigma_t);
        let slab: f64 = (0..4)
            .filter(|&k| {
                let mut cs = self
                    .corners
                    .iter()
                    .skip(8 * (k / 2) + k % 2)
                    .step_by(2)
                    .take(4);
                cs.any(|c| c.w != 0.0)
            })
            .map(|k| radial_value(x, |j| self.bin_value(face, k, j)))
            .sum();
        let (w, hs) = &self.half_space;
        let blend = if *w != 0.0 && face == SlabFace::Reflection {
            w * crate::profile::RadialProfile::eval(hs, r)
        } else {
            0.0
        };
        (self.sigma_t * self.sigma_t * slab + blend).max(0.0)
    }

    /// `∫ 2πr R_slab(r) dr` or `∫ 2πρ T_slab(ρ) dρ`: the simulated totals (every exit, also
    /// beyond the last bin), interpolated. Dimensionless, ≥ 0.
    pub fn total(&self, face: SlabFace) -> f64 {
        let f = face.index();
        let mut v = self.scale[f] * self.sum_corners(|p, row| p.total[f * SLAB_ROWS + row]);
        let (w, hs) = &self.half_space;
        if *w != 0.0 && face == SlabFace::Reflection {
            use crate::profile::RadialProfile;
            v += w * hs.total();
        }
        v.max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tabulated::grid::N_BINS;

    #[test]
    fn the_built_in_slab_table_parses_and_round_trips() {
        let t = SlabData::from_bytes(DATA).unwrap();
        assert_eq!(t.to_bytes(), DATA);
        assert_eq!(t.planes.len(), SLAB_THICKNESSES.len() * SLAB_ETAS.len());
        assert_eq!(t.planes[0].density.len(), 2 * SLAB_ROWS * N_BINS);
    }

    #[test]
    fn values_are_finite_for_every_valid_input() {
        for &st in &[1e-6, 1.0, 1e6] {
            for &a in &[0.0, 0.5, 0.99, 1.0] {
                for &eta in &[1.0, 1.3, 1.6] {
                    for &d in &[0.0, 1e-9, 0.3, 3.0, 20.0, 1e9, f64::INFINITY] {
                        let t = SlabTerm::new(st, a, eta, d);
                        for face in [SlabFace::Reflection, SlabFace::Transmission] {
                            let tot = t.total(face);
                            assert!(tot.is_finite() && tot >= 0.0);
                            for &r in &[0.0, 1e-9, 1.0, 1e3, 1e300, f64::NAN, -1.0] {
                                let v = t.eval(face, r);
                                assert!(v.is_finite() && v >= 0.0, "{st} {a} {eta} {d} {r}");
                            }
                        }
                    }
                }
            }
        }
    }
}
