//! Value parsers for flags that take one of a fixed set of names (`--method`, `--methods`,
//! `--profile`, `--scattering`): they parse with the library's own `FromStr` (so the error
//! lists the accepted names in the library's words) and declare the names to clap, so that
//! `--help` lists them and shell completion offers them.

use std::ffi::OsStr;
use std::str::FromStr;

use bssrdf_core::{ProfileModel, Scattering};
use clap::builder::{PossibleValue, TypedValueParser};
use het_estimate::{Estimator, Named};
use tracer::integrator::Method;

/// A parser of one of `names` with `parse`.
#[derive(Clone)]
pub struct Choice<T> {
    names: Vec<&'static str>,
    parse: fn(&str) -> Result<T, String>,
}

impl<T: Clone + Send + Sync + 'static> TypedValueParser for Choice<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<T, clap::Error> {
        TypedValueParser::parse_ref(&self.parse, cmd, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.names.iter().map(|&n| PossibleValue::new(n))))
    }
}

/// A parser of one of `names` by the type's `FromStr`.
fn by_name<T: FromStr>(names: Vec<&'static str>) -> Choice<T>
where
    T::Err: std::fmt::Display,
{
    Choice {
        names,
        parse: |s| s.parse::<T>().map_err(|e| e.to_string()),
    }
}

/// `pt`, `auto` or an estimator name.
pub fn method() -> Choice<Method> {
    let mut names = vec!["pt", "auto"];
    names.extend(Estimator::ALL.iter().map(|e| e.name()));
    by_name(names)
}

/// An averaging mode of the Sone estimator (`prefiltered`, `monte-carlo`).
pub fn averaging() -> Choice<het_estimate::Averaging> {
    by_name(
        het_estimate::Averaging::ALL
            .iter()
            .map(|a| a.name())
            .collect(),
    )
}

/// Sone's semi-minor axis reading of Eq. (2) (`w/2`, `w`).
pub fn semi_minor() -> Choice<het_estimate::SemiMinorAxis> {
    by_name(
        het_estimate::SemiMinorAxis::ALL
            .iter()
            .map(|b| b.name())
            .collect(),
    )
}

/// A profile model name.
pub fn profile() -> Choice<ProfileModel> {
    by_name(ProfileModel::ALL.iter().map(|m| m.name()).collect())
}

/// A scattering selection name.
pub fn scattering() -> Choice<Scattering> {
    by_name(Scattering::ALL.iter().map(|m| m.name()).collect())
}

/// Where estimators invert artist materials (`before`, `after`).
pub fn invert() -> Choice<tracer::field::InvertAt> {
    by_name(
        tracer::field::InvertAt::ALL
            .iter()
            .map(|i| i.name())
            .collect(),
    )
}

/// A shape-correction choice (`auto`, `on`, `off`).
pub fn correction() -> Choice<tracer::integrator::Correction> {
    by_name(tracer::integrator::Correction::NAMES.to_vec())
}
