//! Typed errors for invalid physical parameters.

/// An invalid physical parameter. Returned by validating constructors; never a panic, never a
/// silent NaN.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    /// A value was NaN or infinite.
    #[error("{name} must be finite, got {value}")]
    NotFinite {
        /// Parameter name (`sigma_a`, `g`, …).
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A value that must be non-negative was negative.
    #[error("{name} must be >= 0, got {value}")]
    Negative {
        /// Parameter name.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A value lay outside its allowed range.
    #[error("{name} must lie in {range}, got {value}")]
    OutOfRange {
        /// Parameter name.
        name: &'static str,
        /// The allowed range, for the message (e.g. `"(-1, 1)"`).
        range: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A name that matches no choice of a closed set (a profile model, an estimator, …), so
    /// that parsing composes with `?` alongside the other parameter checks.
    #[error(transparent)]
    UnknownName(#[from] crate::model::UnknownName),
}

/// Checks that `value` is finite and `>= 0`.
pub fn check_non_negative(name: &'static str, value: f64) -> Result<f64, ParamError> {
    if !value.is_finite() {
        return Err(ParamError::NotFinite { name, value });
    }
    if value < 0.0 {
        return Err(ParamError::Negative { name, value });
    }
    Ok(value)
}

/// Checks a Henyey–Greenstein mean cosine: finite with `|g| < 1` (the phase function is 0/0 at
/// `|g| = 1`).
pub fn check_g(g: f64) -> Result<f64, ParamError> {
    if !g.is_finite() {
        return Err(ParamError::NotFinite {
            name: "g",
            value: g,
        });
    }
    if g.abs() >= 1.0 {
        return Err(ParamError::OutOfRange {
            name: "g",
            range: "(-1, 1)",
            value: g,
        });
    }
    Ok(g)
}
