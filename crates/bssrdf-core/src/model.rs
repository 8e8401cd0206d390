//! The closed sets a user picks from: which homogeneous profile model, and which scattering
//! orders it accounts for.

use std::fmt;
use std::str::FromStr;

use crate::error::UnknownName;

/// A homogeneous radial profile model. Adding a model is one more variant here plus its module.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ProfileModel {
    /// Classical dipole (JMLH01).
    Dipole,
    /// Photon beam diffusion (HCJ13), as in pbrt-v3/v4.
    Pbd,
    /// The "better dipole" (dE12).
    BetterDipole,
    /// The exact half-space profile, tabulated by this project's photon simulation
    /// ([`crate::tabulated`]); η ∈ [1, 1.6].
    Tabulated,
}

impl ProfileModel {
    /// Every model, in CLI order.
    pub const ALL: &'static [ProfileModel] = &[
        ProfileModel::Dipole,
        ProfileModel::Pbd,
        ProfileModel::BetterDipole,
        ProfileModel::Tabulated,
    ];

    /// The model used when none is asked for: the exact [`ProfileModel::Tabulated`] profile
    /// wherever its table reaches (η ≤ 1.6), otherwise photon beam diffusion, the least biased
    /// of the diffusion models on a half-space (`docs/tabulated-profile.md`). `eta` is the
    /// material's relative refractive index; a NaN gives the tabulated model, whose
    /// construction then reports the invalid η.
    pub fn default_for(eta: f64) -> ProfileModel {
        if eta > crate::tabulated::half_space::ETA_MAX {
            ProfileModel::Pbd
        } else {
            ProfileModel::Tabulated
        }
    }

    /// The name used on the command line and in scene files.
    pub const fn name(self) -> &'static str {
        match self {
            ProfileModel::Dipole => "dipole",
            ProfileModel::Pbd => "pbd",
            ProfileModel::BetterDipole => "better-dipole",
            ProfileModel::Tabulated => "tabulated",
        }
    }
}

impl fmt::Display for ProfileModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ProfileModel {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        UnknownName::find(s, "profile model", Self::ALL, |m| m.name())
    }
}

/// Which scattering orders a profile (or a path-traced reference) accounts for. The paper's
/// experiments use [`Scattering::Multiple`] (single scattering excluded).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Scattering {
    /// Paths with two or more scattering events inside the medium.
    #[default]
    Multiple,
    /// Paths with exactly one scattering event.
    Single,
    /// Every order (including unscattered light where it applies).
    All,
}

impl Scattering {
    /// Every variant.
    pub const ALL: &'static [Scattering] =
        &[Scattering::Multiple, Scattering::Single, Scattering::All];

    /// The name used on the command line and in scene files.
    pub const fn name(self) -> &'static str {
        match self {
            Scattering::Multiple => "multiple",
            Scattering::Single => "single",
            Scattering::All => "all",
        }
    }
    /// True when paths with `order` scattering events are counted.
    pub const fn counts(self, order: u32) -> bool {
        match self {
            Scattering::Multiple => order >= 2,
            Scattering::Single => order == 1,
            Scattering::All => true,
        }
    }
    /// True when the multiple-scattering term is included.
    pub const fn includes_multiple(self) -> bool {
        matches!(self, Scattering::Multiple | Scattering::All)
    }
    /// True when the single-scattering term is included.
    pub const fn includes_single(self) -> bool {
        matches!(self, Scattering::Single | Scattering::All)
    }
}

impl fmt::Display for Scattering {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Scattering {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        UnknownName::find(s, "scattering selection", Self::ALL, |m| m.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for &m in ProfileModel::ALL {
            assert_eq!(m.name().parse::<ProfileModel>().unwrap(), m);
        }
        for &s in Scattering::ALL {
            assert_eq!(s.name().parse::<Scattering>().unwrap(), s);
        }
        let e = "dipol".parse::<ProfileModel>().unwrap_err().to_string();
        assert!(e.contains("dipole") && e.contains("dipol"), "{e}");
    }

    #[test]
    fn orders() {
        assert!(!Scattering::Multiple.counts(1) && Scattering::Multiple.counts(2));
        assert!(Scattering::Single.counts(1) && !Scattering::Single.counts(2));
        assert!(Scattering::All.counts(0));
    }
}
