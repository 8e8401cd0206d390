//! `het-bssrdf merge`: assemble the shards written by `render --tile I/N` into the whole
//! image (EXR, PNG preview and JSON sidecar); see `pipeline::sharding` and `pipeline::shard_merge` for the partition, the
//! checks and what a merge guarantees.

use crate::diag::say;
use std::path::{Path, PathBuf};

use crate::common::{claim_outputs, parse_exr_out};
use crate::signals;

/// Arguments of `het-bssrdf merge`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The shards' EXR files, in any order (each with its JSON sidecar beside it).
    #[arg(required = true, value_name = "SHARD.exr")]
    shards: Vec<PathBuf>,
    /// Output EXR; the PNG preview and JSON sidecar are written beside it.
    #[arg(short, long, value_parser = parse_exr_out)]
    out: PathBuf,
    /// Exposure of the PNG preview, in stops (default: the shards' own).
    #[arg(long, allow_hyphen_values = true)]
    exposure: Option<f64>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    let sidecars: Vec<PathBuf> = args
        .shards
        .iter()
        .map(|p| pipeline::files::sidecar_paths(p).1)
        .collect();
    let inputs: Vec<&Path> = args
        .shards
        .iter()
        .chain(&sidecars)
        .map(PathBuf::as_path)
        .collect();
    let _lock = claim_outputs(&args.out, &inputs)?;
    signals::install(signals::Mode::Quit)?;
    let summary = pipeline::shard_merge::merge(&args.shards, &args.out, args.exposure)?;
    let (png, json) = &summary.sidecars;
    let spp = if summary.spp.0 == summary.spp.1 {
        format!("{} spp", summary.spp.0)
    } else {
        format!(
            "{}..{} spp (per shard: see the sidecar)",
            summary.spp.0, summary.spp.1
        )
    };
    say!(
        "merged {} shards ({spp}{}); wrote {}, {}, {}",
        summary.count,
        if summary.time_budget {
            ", time budget: each shard's rows have its own sample count"
        } else {
            ""
        },
        args.out.display(),
        png.display(),
        json.display()
    );
    Ok(())
}
