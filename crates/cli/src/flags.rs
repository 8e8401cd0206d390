//! Flags that do not apply: which flags were given on the command line, and the refusal of
//! those that would be silently ignored (`--profile` with `pt`, `--estimator-samples` with an
//! estimator that takes no samples, `beam` set-up flags on a scene…).

use anyhow::bail;
use bssrdf_core::ProfileModel;
use clap::ArgMatches;
use clap::parser::ValueSource;
use het_estimate::EstimatorOptions;

use crate::common::parse_positive;
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

/// The estimator flags of `render`, `beam` and `converge` (flattened into each): the profile
/// model and the options an estimator may take ([`het_estimate::EstimatorOptions`]). A flag
/// that none of the chosen methods takes is refused ([`EstimatorFlags::check`]).
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct EstimatorFlags {
    /// Profile model for BSSRDF methods (default: each material's, else the tabulated exact
    /// profile where it applies (η ≤ 1.6), else photon beam diffusion; the beam's
    /// index-matched half-space: tabulated).
    #[arg(long, value_parser = crate::choices::profile())]
    pub profile: Option<ProfileModel>,
    /// Averaging samples per region of the estimators that take them.
    #[arg(long, value_parser = parse_positive, long_help = samples_help())]
    pub estimator_samples: Option<u64>,
    /// Averaging of the estimators that have one: prefiltered or monte-carlo.
    #[arg(long, value_parser = crate::choices::averaging(), long_help = averaging_help())]
    pub averaging: Option<het_estimate::Averaging>,
    /// The semi-minor axis b of the path-integral ellipse from the path width w: w or w/2.
    #[arg(long, value_parser = crate::choices::semi_minor(), long_help = semi_minor_help())]
    pub semi_minor: Option<het_estimate::SemiMinorAxis>,
}

/// `--estimator-samples`' long help, naming the estimators that take samples.
fn samples_help() -> String {
    format!(
        "Averaging samples per region of the estimators that take them: {} (default: 16 on \
         the segment; 16 in the disk and 32 in the ellipse for Sone; 64 points for the kernel, \
         at most 1024)",
        EstimatorOptions::names_of(|o| o.samples)
    )
}

/// `--averaging`'s long help, naming the estimators that have one.
fn averaging_help() -> String {
    format!(
        "Averaging of the estimators that have one, {}: `prefiltered` (default: Sone's \
         constant-time closed forms, and the kernel's points read in the surface's plane \
         without projection rays, where the field allows it and the surface is flat; sampling \
         and projecting elsewhere) or `monte-carlo` (always sample and project)",
        EstimatorOptions::names_of(|o| o.averaging)
    )
}

/// `--semi-minor`'s long help, naming the estimators with an ellipse.
fn semi_minor_help() -> String {
    format!(
        "The semi-minor axis b of the ellipse of {} from the path width w of Eq. (2): `w` \
         (default: closer to the path tracer on the beam presets and the checker half-space; \
         docs/physics.md#path-width) or `w/2` (the paper calls w the length of the minor axis)",
        EstimatorOptions::names_of(|o| o.semi_minor)
    )
}

impl EstimatorFlags {
    /// Errors when a flag was given that none of `methods` uses: `--profile` applies to the
    /// BSSRDF methods, the others to the estimators whose [`het_estimate::EstimatorOptions`]
    /// say they take it.
    pub fn check(&self, methods: &[Method]) -> anyhow::Result<()> {
        let names = || {
            let names: Vec<_> = methods.iter().map(|m| m.name()).collect();
            names.join(", ")
        };
        if self.profile.is_some() && !methods.iter().any(|m| matches!(m, Method::Bssrdf { .. })) {
            bail!(
                "--profile does not apply to `{}`: it selects the profile of BSSRDF methods",
                names()
            );
        }
        let takes =
            |t: fn(EstimatorOptions) -> bool| methods.iter().any(|m| t(m.estimator_options()));
        if self.estimator_samples.is_some() && !takes(|o| o.samples) {
            bail!(
                "--estimator-samples does not apply to `{}`: only the {} estimators take \
                 averaging samples",
                names(),
                EstimatorOptions::names_of(|o| o.samples)
            );
        }
        if self.averaging.is_some() && !takes(|o| o.averaging) {
            bail!(
                "--averaging does not apply to `{}`: only the {} estimators have a prefiltered \
                 and a Monte Carlo averaging",
                names(),
                EstimatorOptions::names_of(|o| o.averaging)
            );
        }
        if self.semi_minor.is_some() && !takes(|o| o.semi_minor) {
            bail!(
                "--semi-minor does not apply to `{}`: only the {} estimator averages over an \
                 ellipse sized by Eq. (2)",
                names(),
                EstimatorOptions::names_of(|o| o.semi_minor)
            );
        }
        Ok(())
    }

    /// `--estimator-samples`, saturated to `u32`.
    fn samples(&self) -> Option<u32> {
        self.estimator_samples
            .map(|n| n.min(u32::MAX as u64) as u32)
    }

    /// `method` with the estimator options applied, not the profile (for the beam, whose
    /// profile is passed on its own); `scene_averaging` (a scene file's `averaging`) stands
    /// where `--averaging` was not given.
    pub fn apply_options(
        &self,
        method: Method,
        scene_averaging: Option<het_estimate::Averaging>,
    ) -> Method {
        method
            .with_estimator_samples(self.samples())
            .with_averaging(self.averaging.or(scene_averaging))
            .with_semi_minor(self.semi_minor)
    }

    /// `method` with these flags applied, the profile included ([`Self::apply_options`]).
    pub fn apply(
        &self,
        method: Method,
        scene_averaging: Option<het_estimate::Averaging>,
    ) -> Method {
        self.apply_options(method.with_profile(self.profile), scene_averaging)
    }
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;
    use het_estimate::{Estimator, EstimatorOptions};

    /// The long help of `--flag` of `command`, whitespace normalised.
    fn help(command: &str, flag: &str) -> String {
        let cli = crate::Cli::command();
        let sub = cli.find_subcommand(command).expect(command);
        let arg = sub
            .get_arguments()
            .find(|a| a.get_long() == Some(flag))
            .unwrap_or_else(|| panic!("{command} --{flag}"));
        let text = arg
            .get_long_help()
            .or(arg.get_help())
            .map(|h| h.to_string())
            .unwrap_or_default();
        text.split_whitespace().collect::<Vec<_>>().join(" ")
    }

    /// The methods offered are `Estimator::ALL`'s, and the option flags' help names the
    /// estimators that take them.
    #[test]
    fn help_texts_match_the_estimators() {
        for (command, flag) in [
            ("render", "method"),
            ("beam", "method"),
            ("converge", "methods"),
        ] {
            let cli = crate::Cli::command();
            let arg = cli
                .find_subcommand(command)
                .and_then(|c| c.get_arguments().find(|a| a.get_long() == Some(flag)))
                .unwrap_or_else(|| panic!("{command} --{flag}"));
            let values: Vec<String> = arg
                .get_possible_values()
                .iter()
                .map(|v| v.get_name().to_string())
                .collect();
            for e in Estimator::ALL {
                assert!(
                    values.iter().any(|v| v == e.name()),
                    "{command} --{flag}: {e}"
                );
            }
        }
        type Takes = fn(EstimatorOptions) -> bool;
        let options: [(&str, Takes); 3] = [
            ("estimator-samples", |o| o.samples),
            ("averaging", |o| o.averaging),
            ("semi-minor", |o| o.semi_minor),
        ];
        for command in ["render", "beam", "converge"] {
            for (flag, takes) in options {
                let text = help(command, flag);
                let names = EstimatorOptions::names_of(takes);
                assert!(
                    text.contains(&names),
                    "{command} --{flag}: `{names}` not in {text}"
                );
            }
        }
    }
}
