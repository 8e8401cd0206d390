//! `het-bssrdf profile`: print a homogeneous radial profile `R(r)` as CSV (`r,value`), or its
//! total diffuse reflectance.
//!
//! `value` is `R(r)` in 1/length² (diffuse exitance per unit area per unit incident power,
//! no Fresnel factors; see `bssrdf_core::RadialProfile`). With `--total` the only output is
//! `∫2πr R(r) dr` (for the dipole this is JMLH01's closed form; for photon beam diffusion a
//! numerical integral). Invalid parameters exit with status 1 and a message naming the flag.

use anyhow::{Context, bail};
use bssrdf_core::{ParamError, ProfileFamily, ProfileModel, RadialProfile, Scattering};
use std::io::{BufWriter, Write};

/// Whether the single-scattering term is added to the model's multiple scattering.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SingleScattering {
    /// Add PBD's single-scattering term (HCJ13).
    Include,
    /// Multiple scattering only (as in the paper's experiments).
    Exclude,
}

/// Arguments of `het-bssrdf profile`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Profile model: dipole, pbd, better-dipole or tabulated (the exact half-space profile,
    /// η ≤ 1.6; `render`'s default there).
    #[arg(long, value_parser = crate::choices::profile())]
    model: ProfileModel,
    /// Absorption coefficient σa (1/length, ≥ 0).
    #[arg(long = "sigma-a", allow_hyphen_values = true)]
    sigma_a: f64,
    /// Scattering coefficient σs (1/length, ≥ 0).
    #[arg(long = "sigma-s", allow_hyphen_values = true)]
    sigma_s: f64,
    /// Henyey–Greenstein mean cosine g, in (−1, 1).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    g: f64,
    /// Relative index of refraction η = n_medium/n_outside, in [1, 3] (1 = index-matched).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    eta: f64,
    /// Largest radius printed (length units, > 0).
    #[arg(long = "r-max", default_value_t = 15.0, allow_hyphen_values = true)]
    r_max: f64,
    /// Number of evenly spaced radii from 0 to --r-max (≥ 2).
    #[arg(long, default_value_t = 151)]
    steps: usize,
    /// Include or exclude single scattering.
    #[arg(long = "single-scattering", value_enum, default_value = "exclude")]
    single_scattering: SingleScattering,
    /// Print only the total diffuse reflectance ∫2πr R(r) dr.
    #[arg(long)]
    total: bool,
}

/// The command-line flag that carries a library parameter name.
fn flag_of(e: &ParamError) -> &'static str {
    let name = match e {
        ParamError::NotFinite { name, .. }
        | ParamError::Negative { name, .. }
        | ParamError::OutOfRange { name, .. } => *name,
        _ => "",
    };
    match name {
        "sigma_a" => "--sigma-a",
        "sigma_s" => "--sigma-s",
        "g" => "--g",
        "eta" => "--eta",
        _ => "a parameter",
    }
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    if !(args.r_max.is_finite() && args.r_max > 0.0) {
        bail!(
            "invalid value for --r-max: must be finite and > 0, got {}",
            args.r_max
        );
    }
    if args.steps < 2 {
        bail!(
            "invalid value for --steps: must be at least 2, got {}",
            args.steps
        );
    }
    let scattering = match args.single_scattering {
        SingleScattering::Include => Scattering::All,
        SingleScattering::Exclude => Scattering::Multiple,
    };
    let family = ProfileFamily::new(args.model, scattering, args.g, args.eta)
        .map_err(|e| anyhow::anyhow!("invalid value for {}: {e}", flag_of(&e)))?;
    let profile = family
        .profile(args.sigma_a, args.sigma_s)
        .map_err(|e| anyhow::anyhow!("invalid value for {}: {e}", flag_of(&e)))?;
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    if args.total {
        writeln!(out, "{}", profile.total()).context("writing to stdout")?;
    } else {
        writeln!(out, "r,value").context("writing to stdout")?;
        let n = args.steps - 1;
        for i in 0..=n {
            let r = args.r_max * i as f64 / n as f64;
            writeln!(out, "{r},{}", profile.eval(r)).context("writing to stdout")?;
        }
    }
    out.flush().context("writing to stdout")?;
    Ok(())
}
