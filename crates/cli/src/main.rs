//! `het-bssrdf`: the command-line front end. Thin: parses arguments, calls the library
//! crates, prints results, maps errors to exit codes.
//!
//! Exit codes: 0 success; 1 a run-time error (bad scene, unreadable file, unwritable output,
//! invalid parameter), printed with its cause chain; 2 a command-line usage error (from clap);
//! 130 or 143 when `render` or `beam` was interrupted by SIGINT or SIGTERM (see `interrupt`).
//!
//! Numeric flags accept values starting with `-`, so that `--photons -5` is reported as an
//! invalid value of `--photons` rather than as an unknown argument `-5`.

mod beam;
mod checkpoint;
mod common;
mod compare;
mod converge;
mod interrupt;
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

/// The error and its causes joined by `: `, outermost first, like `{err:#}`, except that a
/// cause whose text the message already contains is skipped: the library's error types print
/// their source in their own message (`cannot read `x`: No such file…`) and also return it
/// from `source()`, which `{err:#}` would print a second time.
fn message(err: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if msg.contains(&text) {
            continue;
        }
        if !msg.is_empty() {
            msg.push_str(": ");
        }
        msg.push_str(&text);
    }
    msg
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {}", message(&err));
            ExitCode::from(interrupt::exit_status().unwrap_or(1))
        }
    }
}
