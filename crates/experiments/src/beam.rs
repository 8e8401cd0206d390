//! The paper's Figure 4 experiment: a pencil beam of unit power enters a non-refractive
//! (η = 1) semi-infinite medium at the origin, perpendicular to its surface z = 0 (medium in
//! z < 0); σs is constant, σa is a texture varying in x and y only. The output is the diffuse
//! exitance map — power leaving through the surface per unit area, in all directions, per unit
//! beam power (1/length²) — over [−E, E]² on an N × N grid.
//!
//! Map convention: row 0 is y = +E, column 0 is x = −E; pixel (i, j) covers
//! x ∈ [−E + jΔ, −E + (j+1)Δ], y ∈ [E − (i+1)Δ, E − iΔ], Δ = 2E/N; a value is the pixel average.
//!
//! Everything runs through the tracer: the half-space is a large box mesh, the beam's entry
//! point and every exitant point are found by tracing, and the estimators' projection rays
//! use the BVH.
//! * `pt` ([`trace_photons`]): light tracing with the volumetric random walk of the path
//!   tracer ([`tracer::integrator::walk`]). Every photon carries weight 1 (analog tracking,
//!   η = 1), so a pixel's value is an integer count of exits / (photons · Δ²): sums of
//!   integers are exact, so the map is identical whatever the thread count. The medium is
//!   grey (the texture and σs are the same in every channel), so the walk of channel 0 is the
//!   walk of all three: no spectral MIS is needed (`docs/physics.md#spectral-mis`).
//! * BSSRDF methods ([`bssrdf_map`]): for `k × k` stratified jittered points x_o per pixel,
//!   estimate the homogeneous coefficients for (x_i, x_o) and evaluate the profile R(r) at
//!   r = |x_o − x_i|.

use std::time::{Duration, Instant};

use bssrdf_core::{ProfileModel, Rgb, Scattering};
use glam::DVec3;
use het_estimate::Estimator;
use rayon::prelude::*;
use serde::Serialize;

use tracer::camera::Camera;
use tracer::error::SceneError;
use tracer::field::{Field, MediumField, PlanarProjection};
use tracer::geometry::{Hit, Ray, primitives};
use tracer::integrator::PathCounters;
use tracer::integrator::profile_eval::eval_profile_channel;
use tracer::integrator::walk::{Interface, WalkEnd, WalkMedium, WalkStart};
use tracer::light::Light;
use tracer::render::Counters;
use tracer::rng::Rng;
use tracer::scene::{Material, RenderSettings, Scene, SceneBuilder, Translucent};
use tracer::volume::ChannelView;

pub use crate::colour_range::ColourRange;

/// Side of the box standing in for the half-space (scene units), and its depth. With
/// σa ≥ 0.005 and σs = 1 the diffusion length 1/σtr is about 8, so light reaching the box's
/// sides or bottom is below e⁻²⁴ of the beam.
pub const HALF_SPACE_SIZE: f64 = 400.0;
/// Depth of the half-space box.
pub const HALF_SPACE_DEPTH: f64 = 200.0;
/// Photons per parallel batch of the light tracer.
pub const BATCH: u64 = 1 << 13;

/// The σa texture of the experiment (values in 1/length).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum BeamTexture {
    /// The same σa everywhere.
    Const {
        /// σa.
        value: f64,
    },
    /// Stripes: u = x cos θ + y sin θ, k = floor(u/w + ½), σa = values[k mod 2].
    Stripe {
        /// The two values; the band containing the origin has `values[0]`.
        values: [f64; 2],
        /// Band width w.
        width: f64,
        /// θ in degrees.
        angle_deg: f64,
    },
    /// Checks: k = floor(x/w + ½) + floor(y/w + ½), σa = values[k mod 2].
    Check {
        /// The two values; the cell containing the origin has `values[0]`.
        values: [f64; 2],
        /// Cell side w.
        width: f64,
    },
}

impl BeamTexture {
    /// The reference pair: `stripe` (45°, width 4) or `check` (width 4), values 0.005 and 0.1.
    pub fn preset(name: &str) -> Option<Self> {
        match name {
            "stripe" => Some(BeamTexture::Stripe {
                values: [0.005, 0.1],
                width: 4.0,
                angle_deg: 45.0,
            }),
            "check" => Some(BeamTexture::Check {
                values: [0.005, 0.1],
                width: 4.0,
            }),
            _ => None,
        }
    }

    /// The texture as a tracer field (planar projection along z, origin at 0).
    pub fn field(&self) -> Result<Field, tracer::error::FieldError> {
        let proj = PlanarProjection::default();
        match *self {
            BeamTexture::Const { value } => Field::constant(Rgb::splat(value)),
            BeamTexture::Stripe {
                values,
                width,
                angle_deg,
            } => Field::stripe(
                width,
                angle_deg.to_radians(),
                [Rgb::splat(values[0]), Rgb::splat(values[1])],
                proj,
            ),
            BeamTexture::Check { values, width } => {
                Field::check(width, [Rgb::splat(values[0]), Rgb::splat(values[1])], proj)
            }
        }
    }
}

/// Everything that defines one beam experiment except the method.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BeamSetup {
    /// σa texture.
    pub texture: BeamTexture,
    /// Constant σs.
    pub sigma_s: f64,
    /// HG mean cosine.
    pub g: f64,
    /// Half-width E of the mapped square [−E, E]².
    pub extent: f64,
    /// N: the map is N × N.
    pub resolution: u32,
    /// Scattering orders counted (the paper: multiple).
    #[serde(serialize_with = "serialize_display")]
    pub scattering: Scattering,
}

fn serialize_display<T: std::fmt::Display, S: serde::Serializer>(
    v: &T,
    s: S,
) -> Result<S::Ok, S::Error> {
    s.collect_str(v)
}

impl BeamSetup {
    /// The paper's set-up with a given texture: σs = 1, isotropic, E = 15, N = 120, multiple
    /// scattering only.
    pub fn paper(texture: BeamTexture) -> Self {
        Self {
            texture,
            sigma_s: 1.0,
            g: 0.0,
            extent: 15.0,
            resolution: 120,
            scattering: Scattering::Multiple,
        }
    }

    /// Pixel side Δ = 2E/N.
    pub fn pixel_size(&self) -> f64 {
        2.0 * self.extent / self.resolution as f64
    }

    /// The scene: the half-space box with the textured medium, the beam at (0, 0, 1) pointing
    /// down, and an orthographic camera over the mapped square.
    pub fn scene(&self) -> Result<Scene, SceneError> {
        let bad = |key: &str, message: String| SceneError::Invalid {
            file: "<beam experiment>".into(),
            key: key.into(),
            line: None,
            message,
        };
        if !(self.extent > 0.0 && self.extent.is_finite()) {
            return Err(bad(
                "extent",
                format!("must be a positive number, got {}", self.extent),
            ));
        }
        if self.resolution == 0 {
            return Err(bad("resolution", "must be at least 1".into()));
        }
        let sigma_a = self
            .texture
            .field()
            .map_err(|e| bad("texture", e.to_string()))?;
        let sigma_s =
            Field::constant(Rgb::splat(self.sigma_s)).map_err(|e| bad("sigma-s", e.to_string()))?;
        let medium = MediumField::new(sigma_a, sigma_s);
        let n = self.resolution;
        let camera = Camera::orthographic(
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::NEG_Z,
            DVec3::Y,
            2.0 * self.extent,
            2.0 * self.extent,
            n,
            n,
        )
        .map_err(|e| bad("extent", e.to_string()))?;
        SceneBuilder::new(RenderSettings::new(n, n, 1), camera)
            .name("<beam experiment>")
            .light(
                Light::beam(DVec3::new(0.0, 0.0, 1.0), DVec3::NEG_Z, Rgb::ONE)
                    .map_err(|e| bad("beam", e.to_string()))?,
            )
            .object(
                "half-space",
                primitives::half_space(0.0, [0.0, 0.0], HALF_SPACE_SIZE, HALF_SPACE_DEPTH, 40),
                Material::Translucent(Translucent::new("medium", medium, self.g, 1.0)),
            )
            .build()
    }
}

/// Photons to trace.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PhotonBudget {
    /// Exactly this many (rounded up to whole batches of 8192).
    Count(u64),
    /// Doubling batches while they fit in this wall-clock time.
    Time(Duration),
}

/// Exits of the light tracer through the top face, by scattering order (whatever the map).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ExitCounts {
    /// Photons traced.
    pub photons: u64,
    /// Exits after exactly one scattering event.
    pub single: u64,
    /// Exits after two or more.
    pub multiple: u64,
    /// Exits without scattering (impossible at normal incidence; kept for completeness).
    pub unscattered: u64,
}

impl ExitCounts {
    /// Reflectance (fraction of beam power leaving through the top) with `scattering`, and its
    /// standard error √(p(1−p)/n) (each photon contributes 0 or 1).
    pub fn reflectance(&self, scattering: Scattering) -> (f64, f64) {
        let k = match scattering {
            Scattering::Single => self.single,
            Scattering::Multiple => self.multiple,
            Scattering::All => self.single + self.multiple + self.unscattered,
        };
        let n = self.photons.max(1) as f64;
        let p = k as f64 / n;
        (p, (p * (1.0 - p) / n).sqrt())
    }
}

/// A beam exitance map and how it was made.
#[derive(Debug, Clone, Serialize)]
#[non_exhaustive]
pub struct BeamMap {
    /// N.
    pub resolution: u32,
    /// E.
    pub extent: f64,
    /// Exitance per unit area per unit beam power, row-major, row 0 at y = +E.
    #[serde(skip)]
    pub values: Vec<f64>,
    /// Per-pixel standard error (light tracing only).
    #[serde(skip)]
    pub std_error: Option<Vec<f64>>,
    /// `pt` or the estimator name.
    pub method: String,
    /// Profile model (BSSRDF methods).
    pub profile: Option<String>,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Photons (pt) or x_o points (BSSRDF).
    pub samples: u64,
    /// Light tracing: exits by order.
    pub exits: Option<ExitCounts>,
    /// Work and rare-event counters.
    pub counters: PathCounters,
}

fn entry_point(scene: &Scene) -> Result<(Hit, DVec3), SceneError> {
    let beam = scene
        .beams()
        .next()
        .copied()
        .ok_or_else(|| SceneError::Invalid {
            file: "<beam experiment>".into(),
            key: "beam".into(),
            line: None,
            message: "the scene has no beam light".into(),
        })?;
    let hit = scene
        .geometry()
        .intersect(&Ray::new(beam.origin, beam.direction))
        .ok_or_else(|| SceneError::Invalid {
            file: "<beam experiment>".into(),
            key: "beam".into(),
            line: None,
            message: "the beam misses the medium".into(),
        })?;
    Ok((hit, beam.direction))
}

/// Light tracing from the beam (the reference), with a progress callback receiving the photon
/// count so far.
pub fn trace_photons(
    setup: &BeamSetup,
    budget: PhotonBudget,
    seed: u64,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<BeamMap, SceneError> {
    let scene = setup.scene()?;
    let (entry, dir) = entry_point(&scene)?;
    let Material::Translucent(t) = &scene.objects()[entry.object as usize].material else {
        unreachable!("the beam scene's only object is translucent")
    };
    let view = ChannelView::new(&t.medium, 0);
    let walk = WalkMedium {
        geometry: scene.geometry(),
        object: entry.object,
        medium: &view,
        g: t.g,
        interface: Interface::smooth(1.0),
    };
    let n = setup.resolution as usize;
    let (e, delta) = (setup.extent, setup.pixel_size());
    let start = Instant::now();
    let mut tally = PhotonTally::new(n);
    let mut batches_done = 0u64;
    let (total, limit) = match budget {
        PhotonBudget::Count(p) => (Some(p.div_ceil(BATCH).max(1)), None),
        PhotonBudget::Time(t) => (None, Some(t.as_secs_f64())),
    };
    let mut next = 1;
    while next > 0 {
        let pass_start = Instant::now();
        // After an interrupt (crate::interrupt) the batches not yet started are skipped; the
        // completed ones are kept and counted, so the map stays normalised by its photons.
        let results: Vec<(Vec<u32>, ExitCounts, PathCounters)> = (batches_done
            ..batches_done + next)
            .into_par_iter()
            .filter(|_| !tracer::interrupt::requested())
            .map(|b| {
                let mut local = vec![0u32; n * n];
                let mut ex = ExitCounts::default();
                let mut c = PathCounters::default();
                for k in b * BATCH..(b + 1) * BATCH {
                    let mut rng = Rng::from_keys(seed, &[0xbea, k]);
                    let mut order = 0;
                    c.paths += 1;
                    let from = WalkStart {
                        origin: entry.spawn_origin(dir),
                        dir,
                        last_scatter: None,
                    };
                    let end = walk.walk(from, &mut order, &mut rng, &mut c, |_, _, _, _| {});
                    if let WalkEnd::Exited { hit, .. } = end
                        && hit.ng.z > 0.5
                    {
                        {
                            match order {
                                0 => ex.unscattered += 1,
                                1 => ex.single += 1,
                                _ => ex.multiple += 1,
                            }
                            if setup.scattering.counts(order) {
                                let j = ((hit.p.x + e) / delta).floor();
                                let i = ((e - hit.p.y) / delta).floor();
                                if (0.0..n as f64).contains(&j) && (0.0..n as f64).contains(&i) {
                                    local[i as usize * n + j as usize] += 1;
                                }
                            }
                        }
                    }
                }
                ex.photons = BATCH;
                progress(BATCH);
                (local, ex, c)
            })
            .collect();
        for (local, ex, c) in &results {
            tally.add(local, ex, c);
        }
        batches_done += next;
        if tracer::interrupt::requested() {
            break;
        }
        let per_batch = pass_start.elapsed().as_secs_f64() / next as f64;
        next = tracer::render::next_pass_size(
            batches_done,
            per_batch,
            start.elapsed().as_secs_f64(),
            total,
            limit,
        );
    }
    Ok(tally.into_map(setup, start.elapsed().as_secs_f64()))
}

/// The light tracer's results so far: photon exits counted per pixel (row by row) and by
/// scattering order, and the path counters.
struct PhotonTally {
    counts: Vec<u64>,
    exits: ExitCounts,
    counters: PathCounters,
}

impl PhotonTally {
    /// Nothing counted yet, for an `n` × `n` map.
    fn new(n: usize) -> Self {
        Self {
            counts: vec![0u64; n * n],
            exits: ExitCounts::default(),
            counters: PathCounters::default(),
        }
    }

    /// Adds one batch's counts: per pixel (`local`), by order (`ex`), and its counters.
    fn add(&mut self, local: &[u32], ex: &ExitCounts, c: &PathCounters) {
        for (a, b) in self.counts.iter_mut().zip(local) {
            *a += *b as u64;
        }
        self.exits.photons += ex.photons;
        self.exits.single += ex.single;
        self.exits.multiple += ex.multiple;
        self.exits.unscattered += ex.unscattered;
        self.counters.merge(c);
    }

    /// The map of `setup`: the counts per unit area per photon, with their standard errors,
    /// traced in `seconds`.
    fn into_map(self, setup: &BeamSetup, seconds: f64) -> BeamMap {
        let delta = setup.pixel_size();
        let photons = self.exits.photons as f64;
        let norm = 1.0 / (photons * delta * delta);
        BeamMap {
            resolution: setup.resolution,
            extent: setup.extent,
            values: self.counts.iter().map(|&c| c as f64 * norm).collect(),
            std_error: Some(
                self.counts
                    .iter()
                    .map(|&c| (c as f64).sqrt() * norm)
                    .collect(),
            ),
            method: "pt".into(),
            profile: None,
            seconds,
            samples: self.exits.photons,
            exits: Some(self.exits),
            counters: self.counters,
        }
    }
}

/// The map of a BSSRDF method: `sub × sub` stratified jittered points per pixel.
pub fn bssrdf_map(
    setup: &BeamSetup,
    estimator: Estimator,
    profile: ProfileModel,
    sub: u32,
    seed: u64,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<BeamMap, SceneError> {
    let bad = |key: &str, message: String| SceneError::Invalid {
        file: "<beam experiment>".into(),
        key: key.into(),
        line: None,
        message,
    };
    let scene = setup.scene()?;
    let (x_i, _) = entry_point(&scene)?;
    let Material::Translucent(t) = &scene.objects()[x_i.object as usize].material else {
        unreachable!("the beam scene's only object is translucent")
    };
    let (family, prepared) = t
        .prepare_bssrdf(Some(profile), setup.scattering, estimator)
        .map_err(|(what, e)| bad(what, e.to_string()))?;
    let surface = scene.object_surface(x_i.object);
    let n = setup.resolution as usize;
    let sub = sub.max(1);
    let (e, delta) = (setup.extent, setup.pixel_size());
    let start = Instant::now();
    let rows: Vec<(Vec<f64>, PathCounters)> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut row = vec![0.0; n];
            let mut c = PathCounters::default();
            for (j, value) in row.iter_mut().enumerate() {
                let mut sum = 0.0;
                let k = u64::from(sub);
                for s in 0..k * k {
                    let mut rng = Rng::from_keys(seed, &[0xb55, i as u64, j as u64, s]);
                    let (a, b) = ((s % k) as f64, (s / k) as f64);
                    let x = -e + (j as f64 + (a + rng.uniform()) / sub as f64) * delta;
                    let y = e - (i as f64 + (b + rng.uniform()) / sub as f64) * delta;
                    let down = Ray::new(DVec3::new(x, y, 1.0), DVec3::NEG_Z);
                    let Some(x_o) = scene.geometry().intersect_object(x_i.object, &down) else {
                        c.probe_misses += 1;
                        continue;
                    };
                    let est = prepared.estimate(&surface, &t.medium, &x_i, &x_o, &mut rng);
                    c.record_estimate(&est.diagnostics);
                    let cf = est.coefficients;
                    let r = (x_o.p - x_i.p).length();
                    sum += eval_profile_channel(&family, cf.sigma_a[0], cf.sigma_s[0], r, &mut c);
                }
                *value = sum / (k * k) as f64;
            }
            progress(1);
            (row, c)
        })
        .collect();
    let mut counters = PathCounters::default();
    let mut values = Vec::with_capacity(n * n);
    for (row, c) in &rows {
        values.extend_from_slice(row);
        counters.merge(c);
    }
    Ok(BeamMap {
        resolution: setup.resolution,
        extent: setup.extent,
        values,
        std_error: None,
        method: estimator.name().into(),
        profile: Some(profile.name().into()),
        seconds: start.elapsed().as_secs_f64(),
        samples: (n * n) as u64 * (sub * sub) as u64,
        exits: None,
        counters,
    })
}

/// One estimator variant of [`write_variant_maps`]: its file-name suffix, the estimator, and
/// what its sidecar records about it.
pub struct Variant {
    /// File-name suffix: the map is `<preset>-<name>.exr`.
    pub name: String,
    /// The estimator, with the variant's parameters.
    pub estimator: Estimator,
    /// Merged into the map's sidecar.
    pub sidecar: serde_json::Value,
}

/// The examples' variant studies (`examples/sone_variants.rs`, `examples/kernel_variants.rs`):
/// for the preset, seed and output directory on the command line (`<stripe|check> <seed>
/// <out-dir>`; `example` names the program in the usage line, which exits with status 2 on
/// other arguments), writes each variant's beam map with the tabulated profile and 4 × 4
/// subsamples per pixel as `<out-dir>/<preset>-<name>.exr` with its sidecar, for `het-bssrdf
/// compare` against a light-traced reference, and prints each path with its time.
pub fn write_variant_maps(example: &str, variants: impl IntoIterator<Item = Variant>) {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [preset, seed, out] = &args[..] else {
        eprintln!("usage: {example} <stripe|check> <seed> <out-dir>");
        std::process::exit(2);
    };
    let texture = BeamTexture::preset(preset).expect("preset: stripe or check");
    let seed: u64 = seed.parse().expect("seed: an integer");
    let setup = BeamSetup::paper(texture);
    std::fs::create_dir_all(out).expect("output directory");
    for v in variants {
        let map = bssrdf_map(
            &setup,
            v.estimator,
            ProfileModel::Tabulated,
            4,
            seed,
            &|_| {},
        )
        .expect("beam map");
        let path = std::path::Path::new(out).join(format!("{preset}-{}.exr", v.name));
        write_beam_map(&map, &setup, &path, v.sidecar).expect("write");
        println!("{} ({:.1} s)", path.display(), map.seconds);
    }
}

/// Writes a beam map: grey EXR at `exr`, a false-colour log-scale PNG with a colour bar
/// beside it (feature `plot`), and a JSON sidecar with the set-up, the method, timings and
/// counters (`extra` is merged in). The colour bar spans the map's own range
/// ([`ColourRange::of`]); [`write_beam_map_in`] takes a range shared by a figure.
pub fn write_beam_map(
    map: &BeamMap,
    setup: &BeamSetup,
    exr: &std::path::Path,
    extra: serde_json::Value,
) -> Result<(), crate::error::WriteError> {
    write_beam_map_in(map, setup, exr, extra, ColourRange::of(&map.values))
}

/// [`write_beam_map`] with the PNG's colours over `range` (values outside it take the bar's
/// end colours).
pub fn write_beam_map_in(
    map: &BeamMap,
    setup: &BeamSetup,
    exr: &std::path::Path,
    extra: serde_json::Value,
    range: ColourRange,
) -> Result<(), crate::error::WriteError> {
    let n = map.resolution;
    // Small files first, images last, renamed into place together or not at all.
    let mut set = tracer::output::OutputSet::new();
    let exr_bytes = tracer::output::grey_exr_bytes(n, n, &map.values, exr)?;
    #[cfg(feature = "plot")]
    let png_bytes = {
        use crate::plot::{MapPlot, MapScale, map_png_bytes};
        let e = map.extent;
        let title = match &map.profile {
            Some(p) => format!("{} ({p})", map.method),
            None => map.method.clone(),
        };
        map_png_bytes(
            &exr.with_extension("png"),
            &MapPlot {
                values: &map.values,
                width: n,
                height: n,
                extent: [-e, e, -e, e],
                scale: MapScale::Log {
                    min: range.min,
                    max: range.max,
                },
                title: &title,
                label: "exitance per unit power (1/area)",
            },
        )?
    };
    let mut value = serde_json::json!({
        "setup": setup,
        "map": map,
        "photons_per_second_per_core": (map.method == "pt").then(|| {
            map.samples as f64 / map.seconds.max(1e-9) / rayon::current_num_threads() as f64
        }),
        "reflectance": map.exits.map(|x| {
            let (a, a_se) = x.reflectance(Scattering::All);
            let (s, s_se) = x.reflectance(Scattering::Single);
            let (m, m_se) = x.reflectance(Scattering::Multiple);
            serde_json::json!({"all": [a, a_se], "single": [s, s_se], "multiple": [m, m_se]})
        }),
    });
    if let (Some(obj), serde_json::Value::Object(more)) = (value.as_object_mut(), extra) {
        obj.extend(more);
    }
    let json = exr.with_extension("json");
    set.add(
        &json,
        tracer::output::json_bytes(&pipeline::provenance::stamped(value), &json)?,
    );
    #[cfg(feature = "plot")]
    set.add(&exr.with_extension("png"), png_bytes);
    set.add(exr, exr_bytes);
    set.commit()?;
    Ok(())
}

/// Runs one method of the beam experiment: light tracing for [`Method::PathTraced`](tracer::integrator::Method::PathTraced) (with
/// `photons`), otherwise the BSSRDF map with `sub × sub` points per pixel and `profile` unless
/// the method names its own. `progress` receives units of work (photons or rows).
pub fn run_method(
    setup: &BeamSetup,
    method: tracer::integrator::Method,
    profile: ProfileModel,
    photons: PhotonBudget,
    sub: u32,
    seed: u64,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<BeamMap, SceneError> {
    match method {
        tracer::integrator::Method::PathTraced => trace_photons(setup, photons, seed, progress),
        tracer::integrator::Method::Bssrdf {
            estimator,
            profile: p,
            ..
        } => bssrdf_map(setup, estimator, p.unwrap_or(profile), sub, seed, progress),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The EXR, PNG and JSON of a beam map are committed together: when one destination cannot
    /// be written (here the sidecar's path is a directory), none of the three is left behind.
    #[test]
    fn a_beam_map_is_written_whole_or_not_at_all() {
        let mut setup = BeamSetup::paper(BeamTexture::preset("stripe").unwrap());
        setup.resolution = 8;
        let method: tracer::integrator::Method = "jensen-out".parse().unwrap();
        let map = run_method(
            &setup,
            method,
            ProfileModel::Dipole,
            PhotonBudget::Count(1),
            1,
            1,
            &|_| {},
        )
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let exr = dir.path().join("m.exr");
        std::fs::create_dir(dir.path().join("m.json")).unwrap();
        assert!(write_beam_map(&map, &setup, &exr, serde_json::json!({})).is_err());
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, vec![std::ffi::OsString::from("m.json")], "{left:?}");
        // With a free destination all three appear.
        let exr = dir.path().join("ok.exr");
        write_beam_map(&map, &setup, &exr, serde_json::json!({})).unwrap();
        for ext in ["exr", "json"] {
            assert!(exr.with_extension(ext).is_file(), "{ext}");
        }
        #[cfg(feature = "plot")]
        assert!(exr.with_extension("png").is_file());
    }
}
