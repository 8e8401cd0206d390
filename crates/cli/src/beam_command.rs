//! `het-bssrdf beam`: the paper's Figure 4 experiment. A pencil beam of unit power enters an
//! index-matched half-space at the origin; σa is a texture varying in x and y. Writes the
//! diffuse exitance map over [−E, E]² (grey EXR, row 0 at y = +E), a false-colour log-scale
//! PNG with a colour bar, and a JSON sidecar.

use crate::diag::say;
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Context, bail};
use bssrdf_core::{ProfileModel, Scattering};
use experiments::beam::{BeamMap, BeamSetup, BeamTexture, PhotonBudget, write_beam_map};
use tracer::integrator::Method;

use crate::common::{
    check_writable, parse_exr_out, parse_positive, parse_seconds, set_collision_cap, warn_counters,
};
use crate::flags::EstimatorFlags;
use crate::signals;

/// Texture kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TextureKind {
    /// One σa everywhere (`--values A`).
    Const,
    /// Stripes (`--values A,B --width W --angle DEG`).
    Stripe,
    /// Checks (`--values A,B --width W`).
    Check,
}

/// The reference texture pairs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Preset {
    /// Stripes at 45°, width 4, σa 0.005 / 0.1 (the band through the origin has 0.005).
    Stripe,
    /// Checks of width 4, σa 0.005 / 0.1 (the cell at the origin has 0.005).
    Check,
}

/// The beam experiment's set-up flags (shared with `converge --beam`).
#[derive(Debug, Clone, clap::Args)]
pub struct SetupArgs {
    /// A reference texture (overrides --texture/--values/--width/--angle).
    #[arg(long, value_enum, conflicts_with_all = ["texture", "values", "width", "angle"])]
    pub preset: Option<Preset>,
    /// σa texture kind.
    #[arg(long, value_enum, default_value = "const")]
    pub texture: TextureKind,
    /// σa value(s): `A` for const, `A,B` for stripe and check (1/length, ≥ 0).
    #[arg(long, value_delimiter = ',', default_values_t = [0.01], allow_hyphen_values = true)]
    pub values: Vec<f64>,
    /// Stripe or check width (length).
    #[arg(long, default_value_t = 4.0, allow_hyphen_values = true)]
    pub width: f64,
    /// Stripe orientation in degrees.
    #[arg(long, default_value_t = 45.0, allow_hyphen_values = true)]
    pub angle: f64,
    /// Constant σs (1/length).
    #[arg(long = "sigma-s", default_value_t = 1.0, allow_hyphen_values = true)]
    pub sigma_s: f64,
    /// Henyey–Greenstein g.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub g: f64,
    /// Half-width E of the mapped square [−E, E]².
    #[arg(long, default_value_t = 15.0, allow_hyphen_values = true)]
    pub extent: f64,
    /// N: the map is N × N pixels.
    #[arg(long, value_parser = parse_positive, default_value_t = 120, allow_hyphen_values = true)]
    pub resolution: u64,
    /// Scattering orders: multiple (the paper), single or all. (`converge` on a scene: as for
    /// `render`, default the scene's.)
    #[arg(long, value_parser = crate::choices::scattering(), default_value = "multiple")]
    pub scattering: Scattering,
}

impl SetupArgs {
    /// The validated set-up.
    pub fn setup(&self) -> anyhow::Result<BeamSetup> {
        let texture = match self.preset {
            Some(Preset::Stripe) => BeamTexture::preset("stripe").expect("built-in preset"),
            Some(Preset::Check) => BeamTexture::preset("check").expect("built-in preset"),
            None => {
                for v in &self.values {
                    if !(v.is_finite() && *v >= 0.0) {
                        bail!("--values: σa must be a finite number ≥ 0, got {v}");
                    }
                }
                if !(self.width.is_finite() && self.width > 0.0) {
                    bail!("--width must be a positive number, got {}", self.width);
                }
                if !self.angle.is_finite() {
                    bail!("--angle must be finite, got {}", self.angle);
                }
                let pair = || -> anyhow::Result<[f64; 2]> {
                    match self.values.as_slice() {
                        [a, b] => Ok([*a, *b]),
                        v => bail!(
                            "--values: {:?} needs two values A,B, got {}",
                            self.texture,
                            v.len()
                        ),
                    }
                };
                match self.texture {
                    TextureKind::Const => match self.values.as_slice() {
                        [a] => BeamTexture::Const { value: *a },
                        v => bail!("--values: const needs one value, got {}", v.len()),
                    },
                    TextureKind::Stripe => BeamTexture::Stripe {
                        values: pair()?,
                        width: self.width,
                        angle_deg: self.angle,
                    },
                    TextureKind::Check => BeamTexture::Check {
                        values: pair()?,
                        width: self.width,
                    },
                }
            }
        };
        if !(self.sigma_s.is_finite() && self.sigma_s >= 0.0) {
            bail!(
                "--sigma-s must be a finite number ≥ 0, got {}",
                self.sigma_s
            );
        }
        if !(self.g.is_finite() && self.g.abs() < 1.0) {
            bail!("--g must lie in (-1, 1), got {}", self.g);
        }
        if !(self.extent.is_finite() && self.extent > 0.0) {
            bail!("--extent must be a positive number, got {}", self.extent);
        }
        Ok(BeamSetup {
            texture,
            sigma_s: self.sigma_s,
            g: self.g,
            extent: self.extent,
            resolution: u32::try_from(self.resolution).context("--resolution is too large")?,
            scattering: self.scattering,
        })
    }

    /// A short name for default file names.
    pub fn tag(&self) -> String {
        match self.preset {
            Some(Preset::Stripe) => "stripe".into(),
            Some(Preset::Check) => "check".into(),
            None => format!("{:?}", self.texture).to_lowercase(),
        }
    }
}

/// Arguments of `het-bssrdf beam`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    setup: SetupArgs,
    /// `pt` (light tracing, the reference) or a BSSRDF estimator (the other possible values).
    #[arg(long, value_parser = crate::choices::method(), default_value = "sone")]
    method: Method,
    #[command(flatten)]
    estimator: EstimatorFlags,
    /// Photons for `pt` (rounded up to batches of 8192).
    #[arg(long, value_parser = parse_positive, conflicts_with = "time", allow_hyphen_values = true)]
    photons: Option<u64>,
    /// Time budget in seconds for `pt` instead of a photon count.
    #[arg(long, value_parser = parse_seconds, allow_hyphen_values = true)]
    time: Option<Duration>,
    /// BSSRDF methods: K×K stratified points x_o per pixel.
    #[arg(long, value_parser = parse_positive, default_value_t = 4, allow_hyphen_values = true)]
    subsamples: u64,
    /// Seed.
    #[arg(long, default_value_t = 1, allow_hyphen_values = true)]
    seed: u64,
    /// Output EXR (default `beam-<texture>-<method>.exr`); PNG and JSON are written beside it.
    #[arg(short, long, value_parser = parse_exr_out)]
    out: Option<PathBuf>,
    /// Most collisions of one photon before it is cut (and counted), for `--method pt`
    /// (default 100,000,000).
    #[arg(long, value_parser = parse_positive, allow_hyphen_values = true)]
    max_collisions: Option<u64>,
}

/// Runs one method with a progress bar on stderr.
pub fn run_method(
    setup: &BeamSetup,
    method: Method,
    profile: ProfileModel,
    photons: PhotonBudget,
    subsamples: u32,
    seed: u64,
    show_progress: bool,
) -> anyhow::Result<BeamMap> {
    let bar = if !show_progress {
        pipeline::progress::ProgressBar::hidden()
    } else if method == Method::PathTraced {
        let len = match photons {
            PhotonBudget::Count(n) => {
                n.div_ceil(experiments::beam::BATCH) * experiments::beam::BATCH
            }
            PhotonBudget::Time(_) => 0,
        };
        pipeline::progress::bar(len, "pt", "photons")
    } else {
        pipeline::progress::bar(setup.resolution as u64, method.name(), "rows")
    };
    let map =
        experiments::beam::run_method(setup, method, profile, photons, subsamples, seed, &|k| {
            bar.inc(k)
        })?;
    bar.finish_and_clear();
    Ok(map)
}

/// Most `--subsamples` K: K × K = 1,048,576 points per pixel.
const MAX_SUBSAMPLES: u64 = 1024;

/// Checks `--subsamples K` (K × K points per pixel, computed in 64 bits).
fn check_subsamples(k: u64) -> anyhow::Result<u32> {
    if k > MAX_SUBSAMPLES {
        bail!(
            "--subsamples {k} means {} points per pixel; at most {MAX_SUBSAMPLES} ({} points) are allowed",
            u128::from(k) * u128::from(k),
            MAX_SUBSAMPLES * MAX_SUBSAMPLES
        );
    }
    Ok(u32::try_from(k).expect("at most MAX_SUBSAMPLES"))
}

/// Bytes per pixel of a beam map: the photon counts, the values and their standard errors
/// (8 bytes each), a batch's counts per thread, and the EXR and PNG buffers.
const BEAM_BYTES_PER_PIXEL: f64 = 8.0 * 3.0 + 4.0 * 16.0 + 8.0 + 6.0;

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    args.estimator.check(&[args.method])?;
    let setup = args.setup.setup()?;
    // The beam's half-space is index-matched (η = 1).
    let profile = args
        .estimator
        .profile
        .unwrap_or(ProfileModel::default_for(1.0));
    let name = match args.method {
        Method::PathTraced => "pt".to_string(),
        m => format!("{}-{}", m.name(), profile),
    };
    let out = args
        .out
        .unwrap_or_else(|| PathBuf::from(format!("beam-{}-{name}.exr", args.setup.tag())));
    check_writable(&out)?;
    let photons = match (args.photons, args.time) {
        (_, Some(t)) => PhotonBudget::Time(t),
        (Some(n), None) => PhotonBudget::Count(n),
        (None, None) => PhotonBudget::Count(1 << 20),
    };
    let sub = check_subsamples(args.subsamples)?;
    let n = f64::from(setup.resolution);
    tracer::memory::check(
        || format!("a {0}x{0} beam map", setup.resolution),
        n * n * BEAM_BYTES_PER_PIXEL,
    )
    .context("--resolution")?;
    set_collision_cap(args.max_collisions);
    signals::install(signals::Mode::Finish)?;
    let method = args.estimator.apply_options(args.method, None);
    let map = run_method(&setup, method, profile, photons, sub, args.seed, true)?;
    let interrupted = signals::received().map(signals::name);
    if let Some(signal) = interrupted
        && map.samples == 0
    {
        bail!("{signal} before the first batch completed; nothing written");
    }
    write_beam_map(
        &map,
        &setup,
        &out,
        serde_json::json!({
            "seed": args.seed,
            "averaging": method.averaging().map(|a| a.name()),
            "semi_minor": method.semi_minor().map(het_estimate::Named::name),
            "interrupted": interrupted.is_some(),
            "max_collisions": tracer::integrator::walk::collision_cap(),
        }),
    )?;
    if let Some(signal) = interrupted {
        bail!(
            "{signal}: wrote the {} samples completed to {} (the sidecar says \"interrupted\": true)",
            map.samples,
            out.display()
        );
    }
    say!(
        "{}: {} samples in {:.2} s; wrote {}",
        map.method,
        map.samples,
        map.seconds,
        out.display()
    );
    if let Some(x) = map.exits {
        let (a, se) = x.reflectance(Scattering::All);
        let rate = map.samples as f64 / map.seconds.max(1e-9) / rayon::current_num_threads() as f64;
        say!("  total reflectance {a:.5} ± {se:.5}; {rate:.3e} photons/s/core");
    }
    warn_counters(&map.counters, false);
    Ok(())
}
