//! `het-bssrdf profile`: print a homogeneous radial profile.

/// Arguments of `het-bssrdf profile`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("profile: not yet implemented")
}
