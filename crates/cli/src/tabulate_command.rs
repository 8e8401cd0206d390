//! `het-bssrdf tabulate`: regenerate the tabulated half-space profile's data file
//! (`bssrdf_core::tabulated`) by photon simulation. The file is bit-identical for a given
//! seed and photon count whatever the thread count; the built-in table is
//! `crates/bssrdf-core/data/halfspace-profile-v1.bin`, made with the defaults below; `--slab`
//! writes the slab table instead (`crates/bssrdf-core/data/slab-profile-v1.bin`, made with
//! `--slab --photons 4000000`); `--angular` writes the angular coupling
//! (`crates/bssrdf-core/data/angular-coupling-v1.bin`); `--oblique` the coupling's radial part
//! (`crates/bssrdf-core/data/oblique-shape-v1.bin`, made with `--oblique --photons 131072`).

use std::path::PathBuf;

use anyhow::Context;
use bssrdf_core::tabulated::angular_file::{ANGULAR_ETAS, tabulate_angular};
use bssrdf_core::tabulated::file::tabulate;
use bssrdf_core::tabulated::grid::ETAS;
use bssrdf_core::tabulated::oblique_file::tabulate_oblique;
use bssrdf_core::tabulated::slab::{SLAB_ETAS, SLAB_THICKNESSES};
use bssrdf_core::tabulated::slab_file::tabulate_slab;

use crate::common::{check_writable, parse_positive};
use crate::diag::report;

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
    #[arg(long, conflicts_with_all = ["angular", "oblique"])]
    slab: bool,
    /// Simulate the angular coupling (`bssrdf_core::tabulated::angular`, built in as
    /// `crates/bssrdf-core/data/angular-coupling-v1.bin`, made with `--angular --photons
    /// 65536`; photons per incidence bin and plane) instead of the half-space table.
    #[arg(long, conflicts_with = "oblique")]
    angular: bool,
    /// Simulate the angular coupling's radial part, the oblique shape
    /// (`bssrdf_core::tabulated::oblique`, built in as
    /// `crates/bssrdf-core/data/oblique-shape-v1.bin`, made with `--oblique --photons 131072`;
    /// photons per incidence bin and plane) instead of the half-space table.
    #[arg(long)]
    oblique: bool,
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
        // The slab table: one plane per (thickness, η).
        let planes = SLAB_THICKNESSES.len() * SLAB_ETAS.len();
        return simulate_and_write(&args, planes, "slab planes", |progress| {
            let data = tabulate_slab(args.seed, args.photons, threads, progress);
            let capped = data.planes.iter().map(|p| p.capped).sum();
            (data.to_bytes(), capped)
        });
    }
    if args.angular {
        return simulate_and_write(&args, ANGULAR_ETAS.len(), "angular planes", |progress| {
            let data = tabulate_angular(args.seed, args.photons, threads, progress);
            let capped = data.planes.iter().map(|p| p.capped).sum();
            (data.to_bytes(), capped)
        });
    }
    if args.oblique {
        return simulate_and_write(&args, ANGULAR_ETAS.len(), "oblique planes", |progress| {
            let data = tabulate_oblique(args.seed, args.photons, threads, progress);
            let capped = data.planes.iter().map(|p| p.capped).sum();
            (data.to_bytes(), capped)
        });
    }
    simulate_and_write(&args, ETAS.len(), "planes", |progress| {
        let data = tabulate(args.seed, args.photons, threads, progress);
        let capped = data.planes.iter().map(|p| p.capped).sum();
        (data.to_bytes(), capped)
    })
}

/// Runs `simulate` (which reports each finished plane and returns the file's bytes and the
/// paths cut at the event cap) behind a progress bar of `planes` planes, writes the file
/// atomically and says what it wrote.
fn simulate_and_write(
    args: &Args,
    planes: usize,
    what: &str,
    simulate: impl FnOnce(&mut dyn FnMut(usize)) -> (Vec<u8>, u64),
) -> anyhow::Result<()> {
    let bar = pipeline::progress::bar(planes as u64, "tabulate", "planes");
    let start = std::time::Instant::now();
    let (bytes, capped) = simulate(&mut |_| bar.inc(1));
    bar.finish_and_clear();
    tracer::output::write_atomic(&args.out, &bytes)
        .with_context(|| format!("cannot write `{}`", args.out.display()))?;
    report(&format!(
        "wrote {} ({planes} {what} x {} photons, seed {}, {capped} paths cut at the event cap) in {:.1} s",
        args.out.display(),
        args.photons,
        args.seed,
        start.elapsed().as_secs_f64()
    ))
}
