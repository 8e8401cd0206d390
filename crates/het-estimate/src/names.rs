//! Closed sets of options with stable names (the CLI and scene files use these names).

use bssrdf_core::UnknownName;

/// A closed set of named choices (estimators and their options). `Display`/`FromStr` of
/// these types use exactly [`Named::name`]; [`Named::ALL`] lists the choices, e.g. for CLI help.
pub trait Named: Copy + 'static {
    /// What is being named, for error messages ("estimator", …).
    const WHAT: &'static str;
    /// Every choice, in documentation order.
    const ALL: &'static [Self];
    /// The stable name of this choice.
    fn name(self) -> &'static str;
}

/// Parses one of `T::ALL` by exact name.
pub(crate) fn parse_named<T: Named>(s: &str) -> Result<T, UnknownName> {
    UnknownName::find(s, T::WHAT, T::ALL, T::name)
}

/// Implements `Display` (the name) and `FromStr` (exact name, error `UnknownName`) for types
/// implementing [`Named`], and an inherent `ALL` constant.
macro_rules! named_display_fromstr {
    ($($t:ty),* $(,)?) => {$(
        impl $t {
            /// Every choice, in documentation order (the same list as [`Named::ALL`], without
            /// the trait in scope).
            ///
            /// [`Named::ALL`]: crate::Named::ALL
            pub const ALL: &'static [Self] = <Self as $crate::names::Named>::ALL;
        }
        impl ::std::fmt::Display for $t {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str($crate::names::Named::name(*self))
            }
        }
        impl ::std::str::FromStr for $t {
            type Err = ::bssrdf_core::UnknownName;
            fn from_str(s: &str) -> Result<Self, Self::Err> {
                $crate::names::parse_named(s)
            }
        }
    )*};
}
