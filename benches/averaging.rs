//! Cost of one (x_i, x_o) estimate for every estimator, by sample count, and the standard
//! deviation of the averaged coefficient versus the sample count (printed before the timings,
//! so that a user can pick N).
//!
//! Run: `cargo bench --bench averaging` (add `-- sone` or `-- kernel` to filter). Benchmark ids
//! are `averaging/<scene>/<estimator> samples=<N>`; point lookups have no N. `sone samples=<N>`
//! is Monte Carlo averaging; `sone prefiltered` is the default (closed-form averages where
//! the field has them and the pair is flat, the paper's 16 + 32 samples elsewhere): run
//! `cargo bench --bench averaging -- 'prefiltered|field-lookup|jensen-out'` to compare it
//! with a point lookup. `kernel samples=<N>` projects every point; `kernel prefiltered` is its
//! default (64 points, read in the plane where the pair is flat). Compare the
//! estimators with the point-lookup estimator `jensen-out` of the same scene (and with
//! `field-lookup`, one bare `CoefficientField::coefficients` call): absolute times depend on
//! the machine. Each iteration estimates one pair and keeps only the coefficients, as a
//! renderer does (the diagnostics are left for the optimiser to drop).
//!
//! Scenes (each is a surface, a coefficient field and a fixed list of (x_i, x_o) pairs):
//! * `plane-stripe`: the analytic plane with the Figure 4 stripe preset (width 4, 45°,
//!   σa 0.005 / 0.1, σs 1), x_i at the origin and x_o uniform in the paper's plot region
//!   [−15, 15]² (the beam experiment);
//! * `plane-check`: the same pairs over the Figure 4 check preset (cells of width 4);
//! * `plane-constant`: the same pairs over a constant field (the short-circuit: every estimator
//!   should cost about the same as a point lookup, or less);
//! * `plane-image`: the same pairs over a planar-projected 256 × 256 RGB image σa (random
//!   texels in [0.005, 0.1], nearest filtering, 30 × 30 scene units: about 8.5 texels per
//!   unit), σs 1; `sone prefiltered` reads the texture's summed-area table (built before the
//!   timings);
//! * `plane-one-band`: the stripe preset's values in bands 10⁵ wide, so that every footprint
//!   lies in one band and the closed form does no band work: `sone prefiltered` there is the
//!   estimate's fixed cost (chord, widths, footprints), beside `jensen-out` and `floor`, the
//!   least arithmetic the estimate needs written out straight (chord, two stripe fractions,
//!   one width of Eq. 2: what no implementation can avoid);
//! * `mesh-stripe`: the tracer's BVH over a sphere of radius 10 tessellated into 81,920
//!   triangles (icosphere, 6 subdivisions), the same stripe texture projected along z, and
//!   pairs of surface points at most 8 apart: a projection is two BVH rays. `sone sampled
//!   samples=<N>` there is the default estimator over the same stripe with its closed forms
//!   hidden (a field read point by point): each region is sampled on the pair's local
//!   quadric where the quadric's error bound allows, by rays elsewhere (what a render pays
//!   where it samples on a curved mesh); `sone samples=<N>` projects every point by rays.
//! * `mesh-uv-image`: the `plane-image` texture UV-mapped on a flat box (a 60 × 60 top of
//!   64 × 64 quads, texture coordinates the plane-image's projection), pairs of top-face
//!   points at most 8 apart in x and y (x_i uniform in [−15, 15]²): `sone prefiltered` reads
//!   the summed-area table through the texture coordinates' chart, against 16 + 32 samples of
//!   two BVH rays each; `kernel prefiltered` reads its points through the chart.
//!
//! To add a scene, build its surface, field and pairs and call [`bench_scene`] and
//! [`print_std_table`] with them; nothing else changes.

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use het_bssrdf::bssrdf_core::Rgb;
use het_bssrdf::het_estimate::FieldCapabilities;
use het_bssrdf::het_estimate::analytic::{
    CheckField, ConstantField, Plane, PlanePoint, StripeField,
};
use het_bssrdf::het_estimate::pattern::{Check, Stripe};
use het_bssrdf::het_estimate::{
    Averaging, CoefficientField, Coefficients, Estimator, KernelParams, SampleBudget,
    SegmentParams, SoneParams, SplitMix64, SurfaceQuery, UniformSource,
};
use het_bssrdf::het_estimate::{FieldBounds, PlanarEllipse};
use het_bssrdf::tracer::field::{
    Axis, Field, Filter, ImageMapping, MediumField, PlanarProjection, Texture, Wrap,
};
use het_bssrdf::tracer::geometry::{Geometry, Hit, ObjectSurface, Ray, primitives};

/// Sample counts benchmarked (per averaging stage: Sone uses N for the disk and N for the
/// ellipse).
const SAMPLE_COUNTS: [u32; 5] = [1, 4, 16, 64, 256];
/// Points benchmarked for the kernel estimator (N points in all: 2N matches Sone's N).
const KERNEL_SAMPLE_COUNTS: [u32; 6] = [2, 8, 16, 32, 128, 512];
/// HG g of the benchmarked material (isotropic, as in the paper's Figure 4).
const G: f64 = 0.0;
/// Relative index of refraction of the benchmarked material (index-matched, as in Figure 4).
const ETA: f64 = 1.0;

/// Every estimator at every benchmarked sample count, with its benchmark label.
fn estimators() -> Vec<(String, Estimator)> {
    let mut v = vec![
        ("jensen-in".to_string(), Estimator::JensenIn),
        ("jensen-out".to_string(), Estimator::JensenOut),
        ("endpoints".to_string(), Estimator::Endpoints),
    ];
    for n in SAMPLE_COUNTS {
        let budget = SampleBudget::fixed(n);
        v.push((
            format!("segment samples={n}"),
            Estimator::Segment(SegmentParams::new().with_samples(budget)),
        ));
    }
    for n in SAMPLE_COUNTS {
        let budget = SampleBudget::fixed(n);
        v.push((
            format!("sone samples={n}"),
            Estimator::Sone(
                SoneParams::paper()
                    .with_averaging(Averaging::MonteCarlo)
                    .with_samples(budget),
            ),
        ));
    }
    // The default: closed forms where the field has them and the pair is flat, sampling (at
    // the paper's 16 + 32) where it is not.
    v.push((
        "sone prefiltered".to_string(),
        Estimator::Sone(SoneParams::paper()),
    ));
    // The kernel draws N points in all (Sone above draws N in the disk and N in the ellipse):
    // compare `kernel samples=2N` with `sone samples=N` for equal lookups. Both project every
    // point (Monte Carlo averaging); `kernel prefiltered` is the default, 64 points read in the
    // plane where the pair is flat.
    for n in KERNEL_SAMPLE_COUNTS {
        let budget = SampleBudget::fixed(n);
        v.push((
            format!("kernel samples={n}"),
            Estimator::Kernel(
                KernelParams::new()
                    .with_samples(budget)
                    .with_averaging(Averaging::MonteCarlo),
            ),
        ));
    }
    v.push((
        "kernel prefiltered".to_string(),
        Estimator::Kernel(KernelParams::new()),
    ));
    v
}

/// The Figure 4 stripe preset.
fn stripe_preset() -> StripeField {
    StripeField {
        pattern: Stripe::new(4.0, std::f64::consts::FRAC_PI_4),
        values: [Coefficients::grey(0.005, 1.0), Coefficients::grey(0.1, 1.0)],
    }
}

/// Beam-experiment pairs on the plane: x_i at the origin, x_o uniform in [−15, 15]².
fn beam_pairs(n: usize, seed: u64) -> Vec<(PlanePoint, PlanePoint)> {
    let mut rng = SplitMix64::new(seed);
    (0..n)
        .map(|_| {
            let x = 30.0 * rng.next_f64() - 15.0;
            let y = 30.0 * rng.next_f64() - 15.0;
            (PlanePoint::new(0.0, 0.0), PlanePoint::new(x, y))
        })
        .collect()
}

/// The group `averaging/<scene>`, with the timings every averaging group uses.
fn averaging_group<'c>(
    c: &'c mut Criterion,
    scene: &str,
) -> criterion::BenchmarkGroup<'c, criterion::measurement::WallTime> {
    let mut group = c.benchmark_group(format!("averaging/{scene}"));
    group
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(30);
    group
}

/// Times one estimate per iteration, cycling through `pairs`, for every estimator.
fn bench_scene<S, F>(
    c: &mut Criterion,
    scene: &str,
    surface: &S,
    field: &F,
    pairs: &[(S::Point, S::Point)],
) where
    S: SurfaceQuery,
    F: CoefficientField<S::Point>,
{
    let mut group = averaging_group(c, scene);
    let mut i = 0usize;
    group.bench_function("field-lookup", |b| {
        b.iter(|| {
            let (_, x_o) = &pairs[i % pairs.len()];
            i = i.wrapping_add(1);
            black_box(field.coefficients(black_box(x_o)))
        })
    });
    for (label, estimator) in estimators() {
        bench_estimator(&mut group, &label, estimator, surface, field, pairs);
    }
    group.finish();
}

/// Benchmarks `estimator` over `pairs` in `group` as `label`: one pair per iteration, keeping
/// only the coefficients.
fn bench_estimator<S, F>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    label: &str,
    estimator: Estimator,
    surface: &S,
    field: &F,
    pairs: &[(S::Point, S::Point)],
) where
    S: SurfaceQuery,
    F: CoefficientField<S::Point>,
{
    let prepared = estimator
        .prepare(G, ETA)
        .expect("valid benchmark parameters");
    let mut rng = SplitMix64::new(7);
    let mut i = 0usize;
    group.bench_function(label, |b| {
        b.iter(|| {
            let (x_i, x_o) = &pairs[i % pairs.len()];
            i = i.wrapping_add(1);
            let est = prepared.estimate(surface, field, black_box(x_i), black_box(x_o), &mut rng);
            black_box(est.coefficients)
        })
    });
}

/// Prints, for each region estimator and N, the standard deviation of the averaged σa (red
/// channel) over `seeds` random streams, as the RMS over `pairs` (absolute, and relative to
/// the pair's mean estimate), so that N can be chosen for a target noise level.
fn print_std_table<S, F>(
    scene: &str,
    surface: &S,
    field: &F,
    pairs: &[(S::Point, S::Point)],
    seeds: u64,
) where
    S: SurfaceQuery,
    F: CoefficientField<S::Point>,
{
    println!(
        "\nstandard deviation of the averaged sigma_a over {seeds} seeds, RMS over {} pairs ({scene}, g = {G})",
        pairs.len()
    );
    println!("{:<22} {:>14} {:>14}", "estimator", "sd", "sd / mean");
    for (label, estimator) in estimators() {
        if matches!(
            estimator,
            Estimator::JensenIn | Estimator::JensenOut | Estimator::Endpoints
        ) {
            continue; // deterministic
        }
        let prepared = estimator.prepare(G, ETA).expect("valid parameters");
        let (mut sum_var, mut sum_rel_var) = (0.0, 0.0);
        for (p, (x_i, x_o)) in pairs.iter().enumerate() {
            let vals: Vec<f64> = (0..seeds)
                .map(|s| {
                    let mut rng = SplitMix64::new(0x9e37 ^ ((p as u64) << 20) ^ s);
                    prepared
                        .estimate(surface, field, x_i, x_o, &mut rng)
                        .coefficients
                        .sigma_a[0]
                })
                .collect();
            let mean = vals.iter().sum::<f64>() / seeds as f64;
            let var = vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (seeds - 1) as f64;
            sum_var += var;
            sum_rel_var += if mean > 0.0 { var / (mean * mean) } else { 0.0 };
        }
        let n = pairs.len() as f64;
        println!(
            "{label:<22} {:>14.3e} {:>14.3e}",
            (sum_var / n).sqrt(),
            (sum_rel_var / n).sqrt()
        );
    }
    println!();
}

/// A tracer [`MediumField`] read on the analytic plane z = 0 (its planar projection along z
/// sees the plane's points as they are), for the `plane-image` scene.
struct PlaneMedium(MediumField);

impl CoefficientField<PlanePoint> for PlaneMedium {
    #[inline]
    fn coefficients(&self, p: &PlanePoint) -> Coefficients {
        self.0.at_point(DVec3::new(p.x, p.y, 0.0))
    }
    fn bounds(&self) -> Option<FieldBounds> {
        Some(self.0.field_bounds())
    }
    fn ellipse_average(&self, e: &PlanarEllipse) -> Option<Coefficients> {
        CoefficientField::<Hit>::ellipse_average(&self.0, e)
    }
    fn capabilities(&self) -> FieldCapabilities {
        CoefficientField::<Hit>::capabilities(&self.0)
    }
}

/// The medium of the image scenes: σa a 256 × 256 random RGB texture read through `mapping`
/// (its summed-area table already built), σs 1.
fn image_medium(mapping: ImageMapping) -> MediumField {
    let n = 256u32;
    let mut rng = SplitMix64::new(11);
    let texels = (0..n * n)
        .map(|_| std::array::from_fn(|_| (0.005 + 0.095 * rng.next_f64()) as f32))
        .collect();
    let tex = std::sync::Arc::new(Texture::from_texels("random", n, n, texels).expect("valid"));
    tex.area_table();
    let sigma_a = Field::image(tex, mapping, Wrap::Repeat, Filter::Nearest, Rgb::ONE)
        .expect("valid image field");
    MediumField::new(sigma_a, Field::constant(Rgb::ONE).expect("valid constant"))
}

/// The `plane-image` field (see the module docs).
fn image_preset() -> PlaneMedium {
    PlaneMedium(image_medium(ImageMapping::Planar {
        projection: PlanarProjection::new(Axis::Z, DVec3::ZERO),
        size: [IMAGE_SIZE, IMAGE_SIZE],
    }))
}

/// The side of the image scenes' texture in scene units.
const IMAGE_SIZE: f64 = 30.0;

/// The `mesh-uv-image` scene (see the module docs): a flat box whose top is 64 × 64 quads, its
/// texture coordinates the plane-image's projection, the same texture UV-mapped, and pairs of
/// top-face points at most 8 apart in x and y.
fn uv_mesh_scene() -> (Geometry, MediumField, Vec<(Hit, Hit)>) {
    let mut mesh = primitives::subdivided_cuboid(
        DVec3::new(-30.0, -30.0, -20.0),
        DVec3::new(30.0, 30.0, 0.0),
        [64, 64, 4],
    );
    mesh.uvs = Some(
        mesh.positions
            .iter()
            .map(|p| {
                let uv = p.truncate() / IMAGE_SIZE + 0.5;
                uv.as_vec2()
            })
            .collect(),
    );
    let geometry = Geometry::build(vec![mesh]);
    let field = image_medium(ImageMapping::Uv);
    let mut rng = SplitMix64::new(5);
    let top = |x: f64, y: f64| {
        geometry
            .intersect(&Ray::new(DVec3::new(x, y, 1.0), DVec3::NEG_Z))
            .expect("the top face is below")
    };
    let pairs = (0..1024)
        .map(|_| {
            let (x, y) = (30.0 * rng.next_f64() - 15.0, 30.0 * rng.next_f64() - 15.0);
            let (dx, dy) = (16.0 * rng.next_f64() - 8.0, 16.0 * rng.next_f64() - 8.0);
            (top(x, y), top(x + dx, y + dy))
        })
        .collect();
    (geometry, field, pairs)
}

/// `averaging/mesh-uv-image` (see the module docs): what prefiltering through the UV chart
/// saves against sampling, where every sample costs two BVH rays.
fn bench_uv_mesh(c: &mut Criterion) {
    let (geometry, field, pairs) = uv_mesh_scene();
    let surface = ObjectSurface::new(&geometry, 0);
    let mut group = averaging_group(c, "mesh-uv-image");
    let sampled = |n| {
        SoneParams::paper()
            .with_averaging(Averaging::MonteCarlo)
            .with_samples(SampleBudget::fixed(n))
    };
    for (label, estimator) in [
        ("jensen-out".to_string(), Estimator::JensenOut),
        ("sone samples=16".to_string(), Estimator::Sone(sampled(16))),
        (
            "sone prefiltered".to_string(),
            Estimator::Sone(SoneParams::paper()),
        ),
        (
            "kernel samples=64".to_string(),
            Estimator::Kernel(KernelParams::new().with_averaging(Averaging::MonteCarlo)),
        ),
        (
            "kernel prefiltered".to_string(),
            Estimator::Kernel(KernelParams::new()),
        ),
    ] {
        bench_estimator(&mut group, &label, estimator, &surface, &field, &pairs);
    }
    group.finish();
}

/// The BVH-mesh scene: sphere, stripe field, pairs of nearby surface points.
fn mesh_scene() -> (Geometry, MediumField, Vec<(Hit, Hit)>) {
    let geometry = Geometry::build(vec![primitives::icosphere(DVec3::ZERO, 10.0, 6)]);
    let stripe = Field::stripe(
        4.0,
        std::f64::consts::FRAC_PI_4,
        [Rgb::splat(0.005), Rgb::splat(0.1)],
        PlanarProjection::default(),
    )
    .expect("valid stripe");
    let field = MediumField::new(stripe, Field::constant(Rgb::ONE).expect("valid constant"));
    let mut rng = SplitMix64::new(3);
    let on_sphere = |rng: &mut SplitMix64, around: Option<DVec3>| loop {
        let d = DVec3::new(
            rng.next_f64() - 0.5,
            rng.next_f64() - 0.5,
            rng.next_f64() - 0.5,
        );
        let d = match around {
            Some(a) => (a + 0.8 * d).normalize(),
            None => d.normalize(),
        };
        if let Some(h) = geometry.intersect(&Ray::new(DVec3::ZERO, d)) {
            return h;
        }
    };
    let pairs = (0..1024)
        .map(|_| {
            let x_i = on_sphere(&mut rng, None);
            let x_o = on_sphere(&mut rng, Some(x_i.p / 10.0));
            (x_i, x_o)
        })
        .collect();
    (geometry, field, pairs)
}

/// The cost of one projection (two rays through the BVH) with f64 arguments, and the same
/// after a round trip through f32 as a renderer with f32 geometry would make (convert its
/// points to `DVec3` for the trait, and back to f32 for its BVH).
fn bench_projection(c: &mut Criterion, surface: &ObjectSurface<'_>, pairs: &[(Hit, Hit)]) {
    let mut group = averaging_group(c, "mesh-stripe");
    let mut i = 0usize;
    group.bench_function("project f64", |b| {
        b.iter(|| {
            let (x_i, x_o) = &pairs[i % pairs.len()];
            i = i.wrapping_add(1);
            let mid = 0.5 * (x_i.p + x_o.p);
            black_box(surface.project(black_box(mid), x_o.ns))
        })
    });
    let mut i = 0usize;
    group.bench_function("project via f32", |b| {
        b.iter(|| {
            let (x_i, x_o) = &pairs[i % pairs.len()];
            i = i.wrapping_add(1);
            let mid = (0.5 * (x_i.p + x_o.p)).as_vec3();
            let n = x_o.ns.as_vec3();
            black_box(surface.project(black_box(mid).as_dvec3(), black_box(n).as_dvec3()))
        })
    });
    group.finish();
}

/// A field read point by point only: the tracer's stripe with its closed forms hidden, as a
/// procedural field or a texture without a summed-area table would be.
struct PointsOnly<'f>(&'f MediumField);

impl CoefficientField<Hit> for PointsOnly<'_> {
    #[inline]
    fn coefficients(&self, p: &Hit) -> Coefficients {
        CoefficientField::<Hit>::coefficients(self.0, p)
    }
    fn bounds(&self) -> Option<FieldBounds> {
        CoefficientField::<Hit>::bounds(self.0)
    }
    fn displacement_scale(&self, region: &PlanarEllipse) -> Option<f64> {
        CoefficientField::<Hit>::displacement_scale(self.0, region)
    }
    #[inline]
    fn averaged_at_point(&self, x: DVec3) -> Option<Coefficients> {
        CoefficientField::<Hit>::averaged_at_point(self.0, x)
    }
    fn capabilities(&self) -> FieldCapabilities {
        CoefficientField::<Hit>::capabilities(self.0)
    }
}

/// `averaging/mesh-stripe/sone sampled samples=<N>`: the default (prefiltered) Sone estimator
/// over a field without closed forms, so that every region is sampled: on the pair's local
/// quadric where its error bound allows (no rays), by projection rays elsewhere. Against
/// `sone samples=<N>` (Monte Carlo averaging, which projects every point by rays), the cost
/// of sampling as renders do it on a curved mesh.
fn bench_sampled_on_quadric(
    c: &mut Criterion,
    surface: &ObjectSurface<'_>,
    field: &PointsOnly<'_>,
    pairs: &[(Hit, Hit)],
) {
    let mut group = averaging_group(c, "mesh-stripe");
    for n in [16u32, 64] {
        let estimator = Estimator::Sone(SoneParams::paper().with_samples(SampleBudget::fixed(n)));
        let label = format!("sone sampled samples={n}");
        bench_estimator(&mut group, &label, estimator, surface, field, pairs);
    }
    group.finish();
}

/// `averaging/plane-one-band` (see the module docs): the prefiltered estimate's fixed cost,
/// and `floor`, the least arithmetic it needs.
fn bench_one_band(c: &mut Criterion, pairs: &[(PlanePoint, PlanePoint)]) {
    let field = StripeField {
        pattern: Stripe::new(1e5, std::f64::consts::FRAC_PI_4),
        ..stripe_preset()
    };
    let mut group = averaging_group(c, "plane-one-band");
    for (label, estimator) in [
        ("jensen-out", Estimator::JensenOut),
        ("sone prefiltered", Estimator::Sone(SoneParams::paper())),
    ] {
        bench_estimator(&mut group, label, estimator, &Plane, &field, pairs);
    }
    let theta2 = Estimator::Sone(SoneParams::paper())
        .prepare(G, ETA)
        .ok()
        .and_then(|p| p.mean_square_angle())
        .expect("valid benchmark parameters");
    let mut i = 0usize;
    group.bench_function("floor", |b| {
        b.iter(|| {
            let (x_i, x_o) = &pairs[i % pairs.len()];
            i = i.wrapping_add(1);
            black_box(sone_floor(&field, theta2, black_box(x_i), black_box(x_o)))
        })
    });
    group.finish();
}

/// The least arithmetic of one prefiltered Sone estimate on the plane, for `floor`: the
/// chord (its length and direction; the plane's normal is z, so the flatness test and the
/// projection into the pattern's plane are free), the disk's and the ellipse's stripe
/// fractions, and one width of Eq. (2) (a grey field). No bounds, clamps, colour channels,
/// diagnostics or generic surface and field: what any implementation of the estimate must
/// compute, not one to use (the estimator is tested; this is not).
fn sone_floor(field: &StripeField, theta2: f64, x_i: &PlanePoint, x_o: &PlanePoint) -> f64 {
    use het_bssrdf::het_estimate::path_integral::width;
    use het_bssrdf::het_estimate::prefilter::{FootprintWeight, PlaneFootprint, stripe_fraction};
    let diff = glam::DVec2::new(x_o.x - x_i.x, x_o.y - x_i.y);
    let d = diff.length();
    let x_hat = diff / d;
    let minor = glam::DVec2::new(-x_hat.y, x_hat.x);
    let centre = glam::DVec2::new(0.5 * (x_i.x + x_o.x), 0.5 * (x_i.y + x_o.y));
    let footprint = |b: f64| PlaneFootprint {
        centre,
        axis_u: 0.5 * d * x_hat,
        axis_v: b * minor,
        weight: FootprintWeight::Uniform,
    };
    let [v0, v1] = field.values;
    let mix = |f: f64, v: fn(&Coefficients) -> f64| v(&v0) * (1.0 - f) + v(&v1) * f;
    let f_disk = stripe_fraction(&field.pattern, &footprint(0.5 * d)).unwrap_or(0.0);
    let (sa, ss) = (mix(f_disk, |c| c.sigma_a[0]), mix(f_disk, |c| c.sigma_s[0]));
    let w = width(theta2, ss, sa, d).unwrap_or(0.0);
    let f = stripe_fraction(&field.pattern, &footprint(0.5 * w)).unwrap_or(0.0);
    mix(f, |c| c.sigma_a[0])
}

fn averaging(c: &mut Criterion) {
    let pairs = beam_pairs(1024, 1);
    let stripe = stripe_preset();
    print_std_table("plane-stripe", &Plane, &stripe, &pairs[..64], 64);
    bench_scene(c, "plane-stripe", &Plane, &stripe, &pairs);
    let check = CheckField {
        pattern: Check { width: 4.0 },
        values: [Coefficients::grey(0.005, 1.0), Coefficients::grey(0.1, 1.0)],
    };
    bench_scene(c, "plane-check", &Plane, &check, &pairs);
    bench_one_band(c, &pairs);
    let constant = ConstantField(Coefficients::grey(0.05, 1.0));
    bench_scene(c, "plane-constant", &Plane, &constant, &pairs);
    let image = image_preset();
    bench_scene(c, "plane-image", &Plane, &image, &pairs);
    let (geometry, field, mesh_pairs) = mesh_scene();
    let surface = ObjectSurface::new(&geometry, 0);
    print_std_table("mesh-stripe", &surface, &field, &mesh_pairs[..64], 64);
    bench_scene(c, "mesh-stripe", &surface, &field, &mesh_pairs);
    bench_projection(c, &surface, &mesh_pairs);
    bench_sampled_on_quadric(c, &surface, &PointsOnly(&field), &mesh_pairs);
    bench_uv_mesh(c);
}

criterion_group!(benches, averaging);
criterion_main!(benches);
