//! `het-bssrdf`: the command-line front end. Thin: parses arguments, calls the library
//! crates, prints results, maps errors to exit codes.
//!
//! Exit codes: 0 success; 1 a run-time error (bad scene, unreadable file, unwritable output,
//! invalid parameter), printed with its cause chain; 2 a command-line usage error (from clap);
//! 128 + the signal (130, 143, 129) when `render`, `beam` or `merge` was interrupted by SIGINT,
//! SIGTERM or SIGHUP (see `signals`).
//!
//! Numeric flags accept values starting with `-`, so that `--photons -5` is reported as an
//! invalid value of `--photons` rather than as an unknown argument `-5`.

mod beam_command;
mod checkpoint;
mod choices;
mod common;
mod compare_command;
mod converge_command;
mod diag;
mod flags;
mod merge_command;
mod profile_command;
mod render_command;
mod reproduce_command;
mod signals;
mod tabulate_command;

use std::process::ExitCode;

use diag::say;

use anyhow::Context;
use clap::{CommandFactory, FromArgMatches, Subcommand};

/// Render heterogeneous translucent materials with homogeneous BSSRDFs, and measure them
/// against a reference volumetric path tracer.
#[derive(Debug, clap::Parser)]
#[command(name = "het-bssrdf", version, about)]
struct Cli {
    /// Worker threads (default: the environment's RAYON_NUM_THREADS, else one per core).
    /// Results are identical whatever the count.
    #[arg(long, global = true, env = "RAYON_NUM_THREADS", value_parser = common::parse_positive)]
    threads: Option<u64>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Print a homogeneous radial profile R(r) as CSV, or its total diffuse reflectance.
    Profile(profile_command::Args),
    /// Render a scene file with the path-traced reference or a BSSRDF method.
    Render(render_command::Args),
    /// Assemble the shards of a render (`render --tile I/N`) into the whole image.
    Merge(merge_command::Args),
    /// The paper's Figure 4: exitance map of a pencil beam in a textured half-space.
    Beam(beam_command::Args),
    /// Error metrics of a test image against a reference, and a difference image.
    Compare(compare_command::Args),
    /// Error against run time of several methods, and their speed-up over path tracing.
    Converge(converge_command::Args),
    /// Run the paper's experiments end to end and write report.md.
    Reproduce(reproduce_command::Args),
    /// Print a shell completion script, e.g. `het-bssrdf completions bash > het-bssrdf.bash`.
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Regenerate the tabulated half-space profile's data file by photon simulation.
    Tabulate(tabulate_command::Args),
}

fn run(cli: Cli, given: flags::Given) -> anyhow::Result<()> {
    if let Some(n) = cli.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(usize::try_from(n).context("--threads is too large")?)
            .build_global()
            .context("cannot start the worker threads (--threads)")?;
    }
    match cli.command {
        Command::Profile(args) => profile_command::run(args),
        Command::Render(args) => render_command::run(args),
        Command::Merge(args) => merge_command::run(args),
        Command::Beam(args) => beam_command::run(args),
        Command::Compare(args) => compare_command::run(args),
        Command::Converge(args) => converge_command::run(args, &given),
        Command::Reproduce(args) => reproduce_command::run(args),
        Command::Completions { shell } => {
            let mut cmd = Cli::command();
            clap_complete::generate(shell, &mut cmd, "het-bssrdf", &mut std::io::stdout());
            Ok(())
        }
        Command::Tabulate(args) => tabulate_command::run(args),
    }
}

fn main() -> ExitCode {
    signals::ignore_file_size_signal();
    let matches = Cli::command().get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    let given = flags::Given::from_matches(matches.subcommand().map(|(_, m)| m));
    match run(cli, given) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            // The libraries' errors do not repeat their sources in their messages (they return
            // them from `source()`), so the cause chain prints each cause once.
            say!("error: {err:#}");
            ExitCode::from(signals::exit_status().unwrap_or(1))
        }
    }
}
