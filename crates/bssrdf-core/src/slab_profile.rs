//! The thickness-aware profile of a material: reflection and transmission of a slab of the
//! local thickness ([`crate::tabulated::slab`], simulated by this project's photon tracer;
//! docs/shapes.md, "Thin parts: the slab profile"), for renderers that measure how thick an
//! object is around a pair of points.

use crate::error::{ParamError, validate_sigmas};
use crate::family::{Profile, ProfileFamily};
use crate::model::ProfileModel;
use crate::profile::RadialProfile;
use crate::tabulated::{SlabFace, SlabTerm};

/// Reflection R_slab(r) and transmission T_slab(ρ) of a homogeneous slab at one `(σa, σs)`,
/// thickness and the family's `g` and `η` (1/length², exitance per unit area per unit power
/// entering; conventions of [`RadialProfile`]). Multiple scattering from the slab table
/// (similarity theory for g ≠ 0: reduced coefficients, thickness in reduced mean free paths,
/// and both faces scaled as the half-space profile's multiple scattering is, so that the thick
/// limit is that profile; see [`ProfileFamily::profile`]); single scattering, when the
/// family selects it, is the half-space profile's single-scattering term on the entry face
/// and absent from the opposite face (an approximation: a thin slab reflects less single
/// scattering and transmits some). `Copy`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlabProfile {
    multiple: Option<SlabTerm>,
    single: Option<Profile>,
}

impl SlabProfile {
    /// R_slab(r) at distance `r` from the point of entry on the entry face, or T_slab(ρ) at
    /// distance `ρ` from the beam's axis on the opposite face (length; negative or NaN count
    /// as 0). Finite, ≥ 0.
    pub fn eval(&self, face: SlabFace, r: f64) -> f64 {
        let m = self.multiple.map_or(0.0, |m| m.eval(face, r));
        let s = match (face, &self.single) {
            (SlabFace::Reflection, Some(s)) => s.eval(r),
            _ => 0.0,
        };
        m + s
    }

    /// `∫ 2πr (R or T) dr` of `face` (dimensionless, ≥ 0).
    pub fn total(&self, face: SlabFace) -> f64 {
        let m = self.multiple.map_or(0.0, |m| m.total(face));
        let s = match (face, &self.single) {
            (SlabFace::Reflection, Some(s)) => s.total(),
            _ => 0.0,
        };
        m + s
    }
}

impl ProfileFamily {
    /// The slab profile for absorption `sigma_a`, scattering `sigma_s` (as
    /// [`ProfileFamily::profile`]) and thickness `thickness` (length, ≥ 0; +∞ is the
    /// half-space). `Ok(None)` unless the family's model is [`ProfileModel::Tabulated`] (the
    /// only model with a slab table); a typed error for invalid coefficients or a NaN or
    /// negative thickness. Pure absorbers and vacuum give the zero profile. No allocation.
    pub fn slab(
        &self,
        sigma_a: f64,
        sigma_s: f64,
        thickness: f64,
    ) -> Result<Option<SlabProfile>, ParamError> {
        let (sigma_a, sigma_s) = validate_sigmas(sigma_a, sigma_s)?;
        if thickness.is_nan() {
            return Err(ParamError::NotFinite {
                name: "thickness",
                value: thickness,
            });
        }
        if thickness < 0.0 {
            return Err(ParamError::Negative {
                name: "thickness",
                value: thickness,
            });
        }
        if self.model() != ProfileModel::Tabulated {
            return Ok(None);
        }
        let reduced = self.reduced(sigma_a, sigma_s);
        let sigma_tp = reduced.sigma_tp;
        let multiple = reduced
            .albedo
            .filter(|_| self.scattering().includes_multiple())
            .map(|alpha_p| {
                SlabTerm::new(sigma_tp, alpha_p, self.eta(), thickness)
                    .with_scale(self.multiple_scale(sigma_a, sigma_s))
            });
        let single = self.tabulated_single(sigma_a, sigma_s);
        Ok(Some(SlabProfile { multiple, single }))
    }
}

impl ProfileFamily {
    /// Whether a slab of thickness `thickness` (length) is, for absorption `sigma_a` and
    /// scattering `sigma_s`, as deep as the half-space: its reduced optical thickness σt'·d is
    /// at least 2 d_max ([`SlabTerm::is_half_space`]), where the slab table hands over to the
    /// half-space table entirely (reflection = the half-space profile, transmission 0; see
    /// [`crate::tabulated::slab`]). Then a caller can evaluate [`ProfileFamily::profile`]
    /// instead of building the slab profile. `false` for a model without a slab table, for
    /// invalid input (so that [`ProfileFamily::slab`] reports it) and for a medium that does not
    /// scatter.
    pub fn slab_is_half_space(&self, sigma_a: f64, sigma_s: f64, thickness: f64) -> bool {
        if self.model() != ProfileModel::Tabulated || thickness.is_nan() {
            return false;
        }
        let Ok((sigma_a, sigma_s)) = validate_sigmas(sigma_a, sigma_s) else {
            return false;
        };
        let reduced = self.reduced(sigma_a, sigma_s);
        reduced.albedo.is_some() && SlabTerm::is_half_space(reduced.sigma_tp, thickness)
    }

    /// The thickness (length) from which [`ProfileFamily::slab_is_half_space`] holds for
    /// absorption `sigma_a` and scattering `sigma_s`: 2 d_max / σt'. It grows as either
    /// coefficient falls (σt' = σa + (1 − g) σs), so a renderer can bound, from a field's
    /// smallest coefficients, how far it must look for an object's far side. `None` where no
    /// thickness is the half-space: a model without a slab table, invalid input, a medium
    /// that does not scatter.
    pub fn half_space_thickness(&self, sigma_a: f64, sigma_s: f64) -> Option<f64> {
        if self.model() != ProfileModel::Tabulated {
            return None;
        }
        let (sigma_a, sigma_s) = validate_sigmas(sigma_a, sigma_s).ok()?;
        let reduced = self.reduced(sigma_a, sigma_s);
        reduced.albedo?;
        let d = SlabTerm::half_space_thickness(reduced.sigma_tp);
        d.is_finite().then_some(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Scattering;

    /// The thickness from which the shortcut holds is where the predicate turns, for any g,
    /// and the bound a renderer takes from the smallest coefficients covers larger ones.
    #[test]
    fn the_half_space_thickness_is_where_the_shortcut_starts() {
        for g in [0.0, 0.4, -0.3] {
            let f = ProfileFamily::new(ProfileModel::Tabulated, Scattering::All, g, 1.3).unwrap();
            for (sa, ss) in [
                (0.002, 1.5),
                (0.0, 2.19),
                (3.0, 0.1),
                (1e-6, 1e-6),
                (1e6, 1e6),
            ] {
                let d = f.half_space_thickness(sa, ss).expect("scattering medium");
                assert!(f.slab_is_half_space(sa, ss, d), "g {g}: {sa} {ss} at {d}");
                assert!(!f.slab_is_half_space(sa, ss, d * 0.999), "g {g}: {sa} {ss}");
                assert!(f.slab_is_half_space(2.0 * sa + 0.1, 1.5 * ss, d));
            }
            assert_eq!(f.half_space_thickness(0.5, 0.0), None);
            assert_eq!(f.half_space_thickness(f64::NAN, 1.0), None);
        }
        let dipole = ProfileFamily::new(ProfileModel::Dipole, Scattering::All, 0.0, 1.3).unwrap();
        assert_eq!(dipole.half_space_thickness(0.01, 1.0), None);
    }

    /// The shortcut's predicate: from σt'·d = 2 d_max on (reduced coefficients), and not just
    /// below, where the slab still transmits. That the slab profile there *is* the half-space
    /// profile is `an_infinitely_thick_slab_is_the_half_space_table`'s first thickness.
    #[test]
    fn a_slab_is_the_half_space_from_twice_the_last_thickness() {
        let (sigma_a, sigma_s) = (0.002, 1.5);
        for g in [0.0, 0.4] {
            let f = ProfileFamily::new(ProfileModel::Tabulated, Scattering::All, g, 1.3).unwrap();
            let deep = 32.0 / (sigma_a + (1.0 - g) * sigma_s);
            assert!(f.slab_is_half_space(sigma_a, sigma_s, deep * (1.0 + 1e-12)));
            assert!(!f.slab_is_half_space(sigma_a, sigma_s, deep * 0.99));
            let thinner = f.slab(sigma_a, sigma_s, deep * 0.9).unwrap().unwrap();
            assert!(thinner.eval(SlabFace::Transmission, 1.0) > 0.0);
        }
        // Other models, invalid input and media that do not scatter: no shortcut.
        let f = ProfileFamily::new(ProfileModel::Dipole, Scattering::All, 0.0, 1.3).unwrap();
        assert!(!f.slab_is_half_space(0.01, 1.0, 1e9));
        let f = ProfileFamily::new(ProfileModel::Tabulated, Scattering::All, 0.0, 1.3).unwrap();
        assert!(!f.slab_is_half_space(-0.01, 1.0, 1e9));
        assert!(!f.slab_is_half_space(0.01, 1.0, f64::NAN));
        assert!(!f.slab_is_half_space(1.0, 0.0, 1e9));
        assert!(f.slab_is_half_space(0.01, 1.0, f64::INFINITY));
    }

    #[test]
    fn invalid_thickness_is_a_typed_error_and_other_models_have_no_slab() {
        let f = ProfileFamily::new(ProfileModel::Tabulated, Scattering::All, 0.0, 1.3).unwrap();
        assert!(matches!(
            f.slab(0.1, 1.0, f64::NAN),
            Err(ParamError::NotFinite { .. })
        ));
        assert!(matches!(
            f.slab(0.1, 1.0, -1.0),
            Err(ParamError::Negative { .. })
        ));
        assert!(f.slab(f64::NAN, 1.0, 1.0).is_err());
        let zero = f.slab(0.0, 0.0, 1.0).unwrap().unwrap();
        assert_eq!(zero.total(SlabFace::Reflection), 0.0);
        let dipole = ProfileFamily::new(ProfileModel::Dipole, Scattering::All, 0.0, 1.3).unwrap();
        assert_eq!(dipole.slab(0.1, 1.0, 1.0).unwrap(), None);
    }

    /// At 2 d_max (where `ProfileFamily::slab_is_half_space` starts) and at infinite thickness
    /// the slab profile is the half-space profile.
    #[test]
    fn an_infinitely_thick_slab_is_the_half_space_table() {
        let deep = 32.0 / (0.02 + 0.7 * 1.5) * (1.0 + 1e-12);
        for (scattering, d) in [Scattering::Multiple, Scattering::All]
            .into_iter()
            .flat_map(|s| [(s, deep), (s, f64::INFINITY)])
        {
            let f = ProfileFamily::new(ProfileModel::Tabulated, scattering, 0.3, 1.3).unwrap();
            let hs = f.profile(0.02, 1.5).unwrap();
            let slab = f.slab(0.02, 1.5, d).unwrap().unwrap();
            // With single scattering the half-space term interpolates the sum of both orders
            // log–log between bin centres, the slab profile each order alone: equal at the
            // centres, within 0.1 % between them; the totals are linear and equal.
            let tol = if scattering == Scattering::All {
                1e-3
            } else {
                1e-12
            };
            for r in [0.0, 0.01, 0.3, 2.0, 30.0] {
                let (a, b) = (hs.eval(r), slab.eval(SlabFace::Reflection, r));
                assert!((a - b).abs() <= tol * a.max(1e-300), "{r}: {a} {b}");
                assert_eq!(slab.eval(SlabFace::Transmission, r), 0.0);
            }
            let (a, b) = (hs.total(), slab.total(SlabFace::Reflection));
            assert!((a - b).abs() <= 1e-12 * a, "{a} {b}");
        }
    }
}
