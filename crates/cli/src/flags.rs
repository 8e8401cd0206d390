//! Flags that do not apply: which flags were given on the command line, and the refusal of
//! those that would be silently ignored (`--profile` with `pt`, `--estimator-samples` with an
//! estimator that takes no samples, `beam` set-up flags on a scene…).

use anyhow::bail;
use clap::ArgMatches;
use clap::parser::ValueSource;
use het_estimate::Estimator;
use tracer::integrator::Method;

/// The flags given on the command line of one subcommand (clap argument ids, such as
/// `sigma_s`), as opposed to left at their defaults.
#[derive(Debug, Clone, Default)]
pub struct Given(Vec<String>);

impl Given {
    /// The flags given in `matches` (the subcommand's matches).
    pub fn from_matches(matches: Option<&ArgMatches>) -> Self {
        let Some(m) = matches else {
            return Self::default();
        };
        Self(
            m.ids()
                .filter(|id| m.value_source(id.as_str()) == Some(ValueSource::CommandLine))
                .map(|id| id.as_str().to_string())
                .collect(),
        )
    }

    /// True when the flag with id `id` was given.
    pub fn has(&self, id: &str) -> bool {
        self.0.iter().any(|g| g == id)
    }

    /// Errors naming the first of `ids` that was given: it does not apply `context`.
    pub fn refuse(&self, ids: &[&str], context: &str) -> anyhow::Result<()> {
        if let Some(id) = ids.iter().find(|id| self.has(id)) {
            bail!("--{} does not apply {context}", id.replace('_', "-"));
        }
        Ok(())
    }
}

/// Errors when `--profile` (`profile`) or `--estimator-samples` (`samples`) was given but
/// none of `methods` uses it: the profile only matters to BSSRDF methods, the samples only to
/// the segment, Sone and kernel estimators.
pub fn check_method_flags(methods: &[Method], profile: bool, samples: bool) -> anyhow::Result<()> {
    let names = || {
        methods
            .iter()
            .map(|m| m.name())
            .collect::<Vec<_>>()
            .join(", ")
    };
    if profile && !methods.iter().any(|m| matches!(m, Method::Bssrdf { .. })) {
        bail!(
            "--profile does not apply to `{}`: it selects the profile of BSSRDF methods",
            names()
        );
    }
    let sampled = |m: &Method| {
        matches!(
            m,
            Method::Bssrdf {
                estimator: Estimator::Segment(_) | Estimator::Sone(_) | Estimator::Kernel(_),
                ..
            }
        )
    };
    if samples && !methods.iter().any(sampled) {
        bail!(
            "--estimator-samples does not apply to `{}`: only the segment, sone and kernel \
             estimators take averaging samples",
            names()
        );
    }
    Ok(())
}

/// Errors when `--averaging` was given but none of `methods` is the Sone or kernel estimator,
/// the two that read prefiltered or in-plane values where they can.
pub fn check_averaging_flag(methods: &[Method], given: bool) -> anyhow::Result<()> {
    if given && !methods.iter().any(|m| m.averaging().is_some()) {
        let names: Vec<_> = methods.iter().map(|m| m.name()).collect();
        bail!(
            "--averaging does not apply to `{}`: only the sone and kernel estimators have a \
             prefiltered and a Monte Carlo averaging",
            names.join(", ")
        );
    }
    Ok(())
}

/// Errors when `--semi-minor` was given but none of `methods` is the Sone estimator, the one
/// whose ellipse it sizes.
pub fn check_semi_minor_flag(methods: &[Method], given: bool) -> anyhow::Result<()> {
    if given && !methods.iter().any(|m| m.semi_minor().is_some()) {
        let names: Vec<_> = methods.iter().map(|m| m.name()).collect();
        bail!(
            "--semi-minor does not apply to `{}`: only the sone estimator averages over an \
             ellipse sized by Eq. (2)",
            names.join(", ")
        );
    }
    Ok(())
}
