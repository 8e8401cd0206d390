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

/// The region estimators' flags, shared by `render`, `beam` and `converge` (flattened into
/// each): how Sone and the kernel average, and how wide Sone's ellipse is.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct RegionFlags {
    /// Sone's and the kernel's averaging: `prefiltered` (default: Sone's constant-time closed
    /// forms, and the kernel's points read in the surface's plane without projection rays,
    /// where the field allows it and the surface is flat; sampling and projecting elsewhere)
    /// or `monte-carlo` (always sample and project).
    #[arg(long, value_parser = crate::choices::averaging())]
    pub averaging: Option<het_estimate::Averaging>,
    /// Sone's semi-minor axis b from the path width w of Eq. (2): `w` (default: closer to the
    /// path tracer on the beam presets and the checker half-space;
    /// docs/physics.md#path-width) or `w/2` (the paper calls w the length of the minor axis).
    #[arg(long, value_parser = crate::choices::semi_minor())]
    pub semi_minor: Option<het_estimate::SemiMinorAxis>,
}

impl RegionFlags {
    /// Errors when a flag was given that none of `methods` uses: `--averaging` applies to the
    /// Sone and kernel estimators (the two that read prefiltered or in-plane values where they
    /// can), `--semi-minor` to Sone alone (the one whose ellipse it sizes).
    pub fn check(&self, methods: &[Method]) -> anyhow::Result<()> {
        let names = || {
            let names: Vec<_> = methods.iter().map(|m| m.name()).collect();
            names.join(", ")
        };
        if self.averaging.is_some() && !methods.iter().any(|m| m.averaging().is_some()) {
            bail!(
                "--averaging does not apply to `{}`: only the sone and kernel estimators have a \
                 prefiltered and a Monte Carlo averaging",
                names()
            );
        }
        if self.semi_minor.is_some() && !methods.iter().any(|m| m.semi_minor().is_some()) {
            bail!(
                "--semi-minor does not apply to `{}`: only the sone estimator averages over an \
                 ellipse sized by Eq. (2)",
                names()
            );
        }
        Ok(())
    }

    /// `method` with these flags applied; `scene_averaging` (a scene file's `averaging`)
    /// stands where `--averaging` was not given.
    pub fn apply(
        &self,
        method: Method,
        scene_averaging: Option<het_estimate::Averaging>,
    ) -> Method {
        method
            .with_averaging(self.averaging.or(scene_averaging))
            .with_semi_minor(self.semi_minor)
    }
}
