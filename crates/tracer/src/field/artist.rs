//! Artist parameters (`subsurface_color`, `subsurface_radius`): how a colour and a mean free
//! path become σa and σs at a point, and where the estimators invert
//! (`docs/artist-parameters.md`).

use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

use bssrdf_core::{AlbedoInversion, Rgb, UnknownName};
use het_estimate::{Coefficients, FieldBounds};

use crate::error::FieldError;

/// Where the BSSRDF estimators turn an artist's colour and mean free path into σa and σs.
///
/// The two differ because the inversion is nonlinear: the mean of σ(C, r) over a region is
/// not σ(mean C, mean r). The path tracer always sees the per-point medium σ(C(p), r(p)).
/// Names: `before`, `after`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum InvertAt {
    /// Invert per point, then average σa and σs (the estimators see the per-point medium, as
    /// the path tracer does).
    Before,
    /// Average the colour and the mean free path, then invert the means.
    After,
}

impl InvertAt {
    /// Every variant.
    pub const ALL: &'static [InvertAt] = &[InvertAt::Before, InvertAt::After];

    /// The default: the one closer to the path tracer on the measured painted scene
    /// (`docs/artist-parameters.md#before-or-after`).
    pub const DEFAULT: InvertAt = InvertAt::Before;

    /// The name used in scene files and on the command line.
    pub const fn name(self) -> &'static str {
        match self {
            InvertAt::Before => "before",
            InvertAt::After => "after",
        }
    }
}

impl Default for InvertAt {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl fmt::Display for InvertAt {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for InvertAt {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        UnknownName::find(s, "inversion point", Self::ALL, |m| m.name())
    }
}

/// Smallest mean free path as a fraction of the medium's largest one: a zero (or tiny) texel
/// of a radius texture is raised to this, so that σt and the path tracer's majorant stay
/// finite. At 1e-3 of the largest radius such a texel is, for the eye, a diffuse surface.
pub const MFP_FLOOR_FRACTION: f64 = 1e-3;

/// The map from (colour, mean free path) to (σa, σs) of one material: the inversion of its
/// profile ([`AlbedoInversion`]: the material's own profile, so that every method of a scene
/// sees the same medium), where estimators invert, and the floor on the mean free path.
#[derive(Debug, Clone, PartialEq)]
pub struct ArtistMap {
    inversion: Arc<AlbedoInversion>,
    invert: InvertAt,
    /// Mean free paths below this (scene units) count as this; set by
    /// [`crate::field::MediumField::artist`].
    floor: f64,
}

impl ArtistMap {
    /// The map through `inversion`, inverting `invert` averaging.
    pub fn new(inversion: Arc<AlbedoInversion>, invert: InvertAt) -> Self {
        Self {
            inversion,
            invert,
            floor: 0.0,
        }
    }

    /// The inversion (profile model, g, η).
    pub fn inversion(&self) -> &AlbedoInversion {
        &self.inversion
    }
    /// Where estimators invert.
    pub fn invert(&self) -> InvertAt {
        self.invert
    }
    /// The same map inverting at `invert`.
    pub fn with_invert(mut self, invert: InvertAt) -> Self {
        self.invert = invert;
        self
    }
    /// The smallest mean free path used (scene units): [`MFP_FLOOR_FRACTION`] of the largest.
    pub fn mfp_floor(&self) -> f64 {
        self.floor
    }

    /// The map with its floor set from the largest mean free path `max` (per channel); an
    /// error when every channel's largest mean free path is 0 (or not finite).
    pub(crate) fn with_floor(mut self, max: Rgb) -> Result<Self, FieldError> {
        let m = max.max_component();
        if !(m > 0.0 && max.is_finite()) {
            return Err(FieldError::Other(format!(
                "subsurface_radius must be finite and positive somewhere, got at most {:?} (a zero radius everywhere is a diffuse surface)",
                max.0
            )));
        }
        self.floor = MFP_FLOOR_FRACTION * m;
        Ok(self)
    }

    /// The map without a floor (to be set again).
    pub(crate) fn without_floor(mut self) -> Self {
        self.floor = 0.0;
        self
    }

    /// σa and σs (in the two slots of the result) of colour `raw.sigma_a` and mean free path
    /// `raw.sigma_s`, per channel.
    #[inline]
    pub fn coefficients(&self, raw: Coefficients) -> Coefficients {
        let mut out = Coefficients::default();
        for k in 0..3 {
            let (a, s) = self
                .inversion
                .coefficients(raw.sigma_a[k], raw.sigma_s[k].max(self.floor));
            out.sigma_a[k] = a;
            out.sigma_s[k] = s;
        }
        out
    }

    /// Bounds of σa and σs from the bounds of colour and mean free path: α grows with the
    /// colour and σt = 1/mfp falls with the mean free path, so the extremes are at corners.
    pub(crate) fn bounds(&self, raw: &FieldBounds) -> FieldBounds {
        if raw.is_constant() {
            return FieldBounds::constant(self.coefficients(raw.min));
        }
        let (lo, hi) = (raw.min, raw.max);
        // Dark and far, bright and near, and the two mixed corners.
        let corner = |c: Rgb, r: Rgb| {
            self.coefficients(Coefficients {
                sigma_a: c,
                sigma_s: r,
            })
        };
        let (dark_far, bright_near) = (
            corner(lo.sigma_a, hi.sigma_s),
            corner(hi.sigma_a, lo.sigma_s),
        );
        let (dark_near, bright_far) = (
            corner(lo.sigma_a, lo.sigma_s),
            corner(hi.sigma_a, hi.sigma_s),
        );
        let min = Coefficients {
            sigma_a: bright_far.sigma_a,
            sigma_s: dark_far.sigma_s,
        };
        let max = Coefficients {
            sigma_a: dark_near.sigma_a,
            sigma_s: bright_near.sigma_s,
        };
        // Components whose inputs do not vary come out equal at both corners.
        FieldBounds { min, max }
    }
}
