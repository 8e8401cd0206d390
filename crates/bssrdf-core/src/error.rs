//! Typed errors for invalid physical parameters.

/// An invalid physical parameter. Returned by validating constructors; never a panic, never a
/// silent NaN.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    /// A value was NaN or infinite.
    #[error("{name} must be finite, got {}", Num(*value))]
    NotFinite {
        /// Parameter name (`sigma_a`, `g`, …).
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A value that must be non-negative was negative.
    #[error("{name} must be >= 0, got {}", Num(*value))]
    Negative {
        /// Parameter name.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A value lay outside its allowed range.
    #[error("{name} must lie in {range}, got {}", Num(*value))]
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
    UnknownName(#[from] UnknownName),
}

/// A name that matches no variant of a closed set.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} `{given}` (expected one of: {expected})")]
pub struct UnknownName {
    /// What was being parsed ("profile model", …).
    pub what: &'static str,
    /// The string given.
    pub given: String,
    /// The accepted names, comma-separated.
    pub expected: String,
}

impl UnknownName {
    /// The element of `all` whose `name` is `given`, or an error listing the accepted names.
    pub fn find<T: Copy>(
        given: &str,
        what: &'static str,
        all: &[T],
        name: impl Fn(T) -> &'static str,
    ) -> Result<T, UnknownName> {
        all.iter()
            .copied()
            .find(|&m| name(m) == given)
            .ok_or_else(|| UnknownName {
                what,
                given: given.to_string(),
                expected: all.iter().map(|&m| name(m)).collect::<Vec<_>>().join(", "),
            })
    }
}

/// A number as error messages print it: as written when that is short (`0.5`, `-1`, `1.6`),
/// in scientific notation (`{:e}`) when the plain form would run past 12 characters, so that
/// `1e50` prints as `1e50` and not as 51 digits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let plain = self.0.to_string();
        if plain.len() <= 12 {
            f.write_str(&plain)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
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

/// Largest |g| used: accepted `g ∈ (−1, 1)` is clamped to `[−G_MAX, G_MAX]` (HG is 0/0 at
/// |g| = 1 and `σs' = (1 − g)σs` degenerates; docs/physics.md#hazards).
pub const G_MAX: f64 = 1.0 - 1e-6;

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

/// Coefficients (1/length) below this are treated as exactly 0: a mean free path above 1e12
/// scene units is vacuum for every practical scene, and it keeps `r = x/σ` finite.
pub const SIGMA_EPSILON: f64 = 1e-12;
/// Largest accepted coefficient (1/length); larger values are rejected as out of range.
pub const SIGMA_MAX: f64 = 1e12;
/// Validated range of the relative index of refraction η = n_medium / n_outside: the Fresnel
/// moments' quadrature is accurate there (see [`crate::fresnel`]).
pub const ETA_RANGE: (f64, f64) = (1.0, 3.0);

/// Checks a relative index of refraction: finite and in [`ETA_RANGE`].
pub fn check_eta(eta: f64) -> Result<f64, ParamError> {
    if !eta.is_finite() {
        return Err(ParamError::NotFinite {
            name: "eta",
            value: eta,
        });
    }
    if !(ETA_RANGE.0..=ETA_RANGE.1).contains(&eta) {
        return Err(ParamError::OutOfRange {
            name: "eta",
            range: "[1, 3]",
            value: eta,
        });
    }
    Ok(eta)
}

/// Checks an absorption or scattering coefficient (1/length): finite, `>= 0` and at most
/// [`SIGMA_MAX`].
pub fn check_sigma(name: &'static str, value: f64) -> Result<f64, ParamError> {
    check_non_negative(name, value)?;
    if value > SIGMA_MAX {
        return Err(ParamError::OutOfRange {
            name,
            range: "[0, 1e12]",
            value,
        });
    }
    Ok(value)
}

/// Validates a coefficient pair: finite, ≥ 0, ≤ [`SIGMA_MAX`]; flushes values below
/// [`SIGMA_EPSILON`] to 0.
pub fn validate_sigmas(sigma_a: f64, sigma_s: f64) -> Result<(f64, f64), ParamError> {
    let check = |name: &'static str, v: f64| -> Result<f64, ParamError> {
        check_sigma(name, v).map(|v| if v < SIGMA_EPSILON { 0.0 } else { v })
    };
    Ok((check("sigma_a", sigma_a)?, check("sigma_s", sigma_s)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_print_short_numbers() {
        let e = check_sigma("sigma_a", 1.000_000_000_000_000_5e20).unwrap_err();
        assert_eq!(
            e.to_string(),
            "sigma_a must lie in [0, 1e12], got 1.0000000000000005e20"
        );
        assert_eq!(
            check_sigma("sigma_s", -0.5).unwrap_err().to_string(),
            "sigma_s must be >= 0, got -0.5"
        );
        assert_eq!(Num(f64::NAN).to_string(), "NaN");
        assert_eq!(Num(1.0 / 3.0).to_string(), "3.333333333333333e-1");
        assert_eq!(Num(1e-30).to_string(), "1e-30");
        assert_eq!(Num(1.6).to_string(), "1.6");
    }
}
