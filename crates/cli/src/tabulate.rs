//! `het-bssrdf tabulate`: regenerate the tabulated half-space profile's data file
//! (`bssrdf_core::tabulated`) by photon simulation. The file is bit-identical for a given
//! seed and photon count whatever the thread count; the built-in table is
//! `crates/bssrdf-core/data/halfspace-profile-v1.bin`, made with the defaults below; `--slab`
//! writes the slab table instead (`crates/bssrdf-core/data/slab-profile-v1.bin`, made with
//! `--slab --photons 4000000`).

use std::path::PathBuf;

use anyhow::Context;
use bssrdf_core::tabulated::file::tabulate;
use bssrdf_core::tabulated::grid::ETAS;
use bssrdf_core::tabulated::slab::{SLAB_ETAS, SLAB_THICKNESSES};
use bssrdf_core::tabulated::slab_file::tabulate_slab;

use crate::common::{check_writable, parse_positive};

/// Arguments of `het-bssrdf tabulate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output file (written atomically).
    #[arg(long, short = 'o')]
    out: PathBuf,
    /// Photons per refractive-index plane.
    #[arg(long, default_value = "1000000", value_parser = parse_positive, allow_hyphen_values = true)]
    photons: u64,
    /// Seed of the simulation.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Simulate the slab table (`bssrdf_core::tabulated::slab`, built in as
    /// `crates/bssrdf-core/data/slab-profile-v1.bin`) instead of the half-space one.
    #[arg(long)]
    slab: bool,
    /// Worker threads (default: every core); the file does not depend on it.
    #[arg(long, value_parser = parse_positive, allow_hyphen_values = true)]
    threads: Option<u64>,
}

/// Runs the simulation and writes the table.
pub fn run(args: Args) -> anyhow::Result<()> {
    check_writable(&args.out)?;
    let threads = args
        .threads
        .map_or_else(rayon::current_num_threads, |t| t as usize);
    if args.slab {
        return run_slab(&args, threads);
    }
    let bar = experiments::progress::bar(ETAS.len() as u64, "tabulate", "planes");
    let start = std::time::Instant::now();
    let data = tabulate(args.seed, args.photons, threads, |_| bar.inc(1));
    bar.finish_and_clear();
    tracer::output::write_atomic(&args.out, &data.to_bytes())
        .with_context(|| format!("cannot write `{}`", args.out.display()))?;
    let capped: u64 = data.planes.iter().map(|p| p.capped).sum();
    println!(
        "wrote {} ({} planes x {} photons, seed {}, {} paths cut at the event cap) in {:.1} s",
        args.out.display(),
        data.planes.len(),
        data.photons,
        data.seed,
        capped,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// `--slab`: the slab table, one plane per (thickness, η).
fn run_slab(args: &Args, threads: usize) -> anyhow::Result<()> {
    let planes = SLAB_THICKNESSES.len() * SLAB_ETAS.len();
    let bar = experiments::progress::bar(planes as u64, "tabulate", "planes");
    let start = std::time::Instant::now();
    let data = tabulate_slab(args.seed, args.photons, threads, |_| bar.inc(1));
    bar.finish_and_clear();
    tracer::output::write_atomic(&args.out, &data.to_bytes())
        .with_context(|| format!("cannot write `{}`", args.out.display()))?;
    let capped: u64 = data.planes.iter().map(|p| p.capped).sum();
    println!(
        "wrote {} ({} slab planes x {} photons, seed {}, {} paths cut at the event cap) in {:.1} s",
        args.out.display(),
        data.planes.len(),
        data.photons,
        data.seed,
        capped,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
