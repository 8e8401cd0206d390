//! `het-bssrdf`: the command-line front end. Thin: parses arguments, calls the library
//! crates, prints results, maps errors to exit codes.
//!
//! Exit codes: 0 success; 1 a run-time error (bad scene, unreadable file, unwritable output,
//! invalid parameter), printed with its cause chain; 2 a command-line usage error (from clap).

mod beam;
mod common;
mod compare;
mod converge;
mod profile;
mod render;
mod reproduce;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Render heterogeneous translucent materials with homogeneous BSSRDFs, and measure them
/// against a reference volumetric path tracer.
#[derive(Debug, Parser)]
#[command(name = "het-bssrdf", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Print a homogeneous radial profile R(r) as CSV, or its total diffuse reflectance.
    Profile(profile::Args),
    /// Render a scene file with the path-traced reference or a BSSRDF method.
    Render(render::Args),
    /// The paper's Figure 4: exitance map of a pencil beam in a textured half-space.
    Beam(beam::Args),
    /// Error metrics of a test image against a reference, and a difference image.
    Compare(compare::Args),
    /// Error against run time of several methods, and their speed-up over path tracing.
    Converge(converge::Args),
    /// Run the paper's experiments end to end and write report.md.
    Reproduce(reproduce::Args),
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Profile(args) => profile::run(args),
        Command::Render(args) => render::run(args),
        Command::Beam(args) => beam::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Converge(args) => converge::run(args),
        Command::Reproduce(args) => reproduce::run(args),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::from(1)
        }
    }
}
