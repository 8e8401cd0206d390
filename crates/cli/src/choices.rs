//! Value parsers for flags that take one of a fixed set of names (`--method`, `--methods`,
//! `--profile`, `--scattering`): they parse with the library's own `FromStr` (so the error
//! lists the accepted names in the library's words) and declare the names to clap, so that
//! `--help` lists them and shell completion offers them.

use std::ffi::OsStr;

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

/// `pt` or an estimator name.
pub fn method() -> Choice<Method> {
    let mut names = vec!["pt"];
    names.extend(Estimator::ALL.iter().map(|e| e.name()));
    Choice {
        names,
        parse: |s| s.parse(),
    }
}

/// A profile model name.
pub fn profile() -> Choice<ProfileModel> {
    Choice {
        names: ProfileModel::ALL.iter().map(|m| m.name()).collect(),
        parse: |s| {
            s.parse()
                .map_err(|e: bssrdf_core::UnknownName| e.to_string())
        },
    }
}

/// A scattering selection name.
pub fn scattering() -> Choice<Scattering> {
    Choice {
        names: Scattering::ALL.iter().map(|m| m.name()).collect(),
        parse: |s| {
            s.parse()
                .map_err(|e: bssrdf_core::UnknownName| e.to_string())
        },
    }
}
