//! The Monte Carlo averaging loop shared by the region estimators: accumulate sanitised
//! coefficients at projected sample points of a region, under a [`SampleBudget`].

use bssrdf_core::Rgb;
use glam::DVec3;

use crate::budget::{REPLICATES, SampleBudget};
use crate::estimator_output::Diagnostics;
use crate::field::{CoefficientField, Coefficients};
use crate::known::sanitise;
use crate::local_surface::{Curvature, End, LocalSurface};
use crate::random::UniformSource;
use crate::sampling::PointSet;
use crate::surface::{Projected, SurfacePoint, SurfaceQuery};
use crate::uv_chart::UvChart;

/// Per-channel selection weights (1 = this channel takes the sample, 0 = it does not).
pub(crate) type Channels = Rgb;

/// Running weighted sums of σa and σs per channel.
///
/// Plain arrays rather than `Rgb` arithmetic: `Rgb`'s operators live in another crate without
/// `#[inline]`, and this is the innermost loop.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Accumulator {
    sigma_a: [f64; 3],
    sigma_s: [f64; 3],
    weight: [f64; 3],
}

impl Accumulator {
    /// Adds `c` to the channels selected by `channels` (0/1 per channel).
    #[inline]
    pub fn add(&mut self, c: &Coefficients, channels: Channels) {
        for k in 0..3 {
            let w = channels.0[k];
            self.sigma_a[k] += c.sigma_a.0[k] * w;
            self.sigma_s[k] += c.sigma_s.0[k] * w;
            self.weight[k] += w;
        }
    }

    pub fn merge(&mut self, o: &Accumulator) {
        for k in 0..3 {
            self.sigma_a[k] += o.sigma_a[k];
            self.sigma_s[k] += o.sigma_s[k];
            self.weight[k] += o.weight[k];
        }
    }

    /// Per-channel means; channels without samples are `None`.
    pub fn mean(&self) -> [Option<(f64, f64)>; 3] {
        std::array::from_fn(|k| {
            let w = self.weight[k];
            (w > 0.0).then(|| (self.sigma_a[k] / w, self.sigma_s[k] / w))
        })
    }

    /// Per-channel means, with `fallback` for channels without samples; also says whether the
    /// fallback was needed for a channel selected by `wanted`.
    pub fn mean_or(
        &self,
        wanted: Channels,
        fallback: impl FnOnce() -> Coefficients,
    ) -> (Coefficients, bool) {
        let means = self.mean();
        let missing = (0..3).any(|k| wanted[k] > 0.0 && means[k].is_none());
        let fb = if missing { Some(fallback()) } else { None };
        let mut out = Coefficients::default();
        for (k, m) in means.iter().enumerate() {
            let (a, s) = match (m, &fb) {
                (Some(v), _) => *v,
                (None, Some(f)) => (f.sigma_a[k], f.sigma_s[k]),
                (None, None) => (0.0, 0.0),
            };
            out.sigma_a[k] = a;
            out.sigma_s[k] = s;
        }
        (out, missing)
    }
}

/// The result of one averaging stage.
pub(crate) struct Averaged {
    pub acc: Accumulator,
    pub samples: u32,
    pub rel_se: Option<f64>,
}

/// Most points handed at once to a sampler of the averaging loop, and to
/// [`crate::SurfaceQuery::project_positions`] and [`crate::CoefficientField::averaged_at_points`].
pub const CHUNK: usize = 32;

/// Averages over a region whose points come from the point set `P`.
///
/// `sample(point, acc)` projects/looks up whatever it needs for one point and adds the results
/// to `acc`. `tracked` selects the channels (per coefficient) whose error counts for
/// [`SampleBudget::TargetRelError`].
pub(crate) fn average<P, U>(
    budget: SampleBudget,
    tracked: (Channels, Channels),
    rng: &mut U,
    mut sample: impl FnMut(P::Point, &mut Accumulator),
) -> Averaged
where
    P: PointSet,
    P::Point: Default,
    U: UniformSource + ?Sized,
{
    average_chunks::<P, U>(budget, tracked, rng, |points, acc| {
        for &p in points {
            sample(p, acc);
        }
    })
}

/// [`average`] with the points handed over in order, up to [`CHUNK`] at a time, so that a
/// sampler can project a chunk along one direction together
/// ([`crate::SurfaceQuery::project_positions`]).
pub(crate) fn average_chunks<P, U>(
    budget: SampleBudget,
    tracked: (Channels, Channels),
    rng: &mut U,
    mut sample: impl FnMut(&[P::Point], &mut Accumulator),
) -> Averaged
where
    P: PointSet,
    P::Point: Default,
    U: UniformSource + ?Sized,
{
    // Points lo..hi of `set`, in chunks (antithetic pairs computed together).
    let mut run = |set: &P, lo: u32, hi: u32, acc: &mut Accumulator| {
        let mut buf = [P::Point::default(); CHUNK];
        let mut k = lo;
        while k < hi {
            let mut n = 0;
            while n < CHUNK && k < hi {
                if k.is_multiple_of(2) && k + 1 < hi && n + 1 < CHUNK {
                    let [a, b] = set.point_pair(k);
                    (buf[n], buf[n + 1]) = (a, b);
                    (n, k) = (n + 2, k + 2);
                } else {
                    buf[n] = set.point(k);
                    (n, k) = (n + 1, k + 1);
                }
            }
            sample(&buf[..n], acc);
        }
    };
    match budget {
        SampleBudget::TargetRelError { rel_se, max } if max.get() >= REPLICATES => {
            let per_max = max.get() / REPLICATES;
            let sets: [P; REPLICATES as usize] = std::array::from_fn(|_| P::new(rng));
            let mut accs = [Accumulator::default(); REPLICATES as usize];
            let mut done = 0u32;
            loop {
                let target = (2 * done).clamp(1, per_max);
                for (set, acc) in sets.iter().zip(accs.iter_mut()) {
                    run(set, done, target, acc);
                }
                done = target;
                let err = relative_std_error(&accs, tracked);
                if err <= rel_se || done >= per_max {
                    let mut acc = Accumulator::default();
                    accs.iter().for_each(|a| acc.merge(a));
                    return Averaged {
                        acc,
                        samples: done * REPLICATES,
                        rel_se: Some(err),
                    };
                }
            }
        }
        SampleBudget::TargetRelError { max: n, .. } | SampleBudget::Fixed(n) => {
            let set = P::new(rng);
            let mut acc = Accumulator::default();
            run(&set, 0, n.get(), &mut acc);
            Averaged {
                acc,
                samples: n.get(),
                rel_se: None,
            }
        }
    }
}

/// The largest relative standard error over the tracked channels, estimated from the spread
/// of the replicate means (∞ while fewer than two replicates have samples in a channel).
fn relative_std_error(accs: &[Accumulator], tracked: (Channels, Channels)) -> f64 {
    let mut worst: f64 = 0.0;
    for k in 0..3 {
        for (coef, want) in [(0, tracked.0[k]), (1, tracked.1[k])] {
            if want == 0.0 {
                continue;
            }
            let (mut n, mut sum, mut sum_w, mut total_w) = (0.0, 0.0, 0.0, 0.0);
            let means = accs.iter().filter(|a| a.weight[k] > 0.0).map(|a| {
                let s = if coef == 0 {
                    a.sigma_a[k]
                } else {
                    a.sigma_s[k]
                };
                (s / a.weight[k], s, a.weight[k])
            });
            let mut m = [0.0; REPLICATES as usize];
            for (i, (mean, s, w)) in means.enumerate() {
                m[i] = mean;
                n += 1.0;
                sum += mean;
                sum_w += s;
                total_w += w;
            }
            if n < 2.0 {
                return f64::INFINITY;
            }
            let avg = sum / n;
            let var = m[..n as usize]
                .iter()
                .map(|x| (x - avg).powi(2))
                .sum::<f64>()
                / (n - 1.0);
            let se = (var / n).sqrt();
            let pooled = sum_w / total_w;
            let rel = if se == 0.0 {
                0.0
            } else if pooled > 0.0 {
                se / pooled
            } else {
                f64::INFINITY
            };
            worst = worst.max(rel);
        }
    }
    worst
}

/// Lookups and counters shared by the estimators for one (x_i, x_o) pair.
pub(crate) struct Probe<'a, S: SurfaceQuery + ?Sized, F: ?Sized> {
    pub surface: &'a S,
    pub field: &'a F,
    pub x_i: &'a S::Point,
    pub x_o: &'a S::Point,
    pub diag: Diagnostics,
    endpoints: Option<Coefficients>,
    /// The averaging region's texture-coordinate chart, for a field that reads them, once
    /// [`Probe::prepare_prefilter`] has found one.
    chart: Option<UvChart>,
    /// The pair's local surface model and the angle test's verdict, once
    /// [`Probe::prepare_prefilter`] has run ([`Prefilter`]).
    prefilter: Option<Prefilter>,
    /// How far from the plane projections look first ([`SurfaceQuery::project_within`]): the
    /// size of the region being sampled (∞ until one is).
    reach: f64,
}

/// What [`Probe::prepare_prefilter`] found for a pair: the local quadric (`None` where the
/// ends contradict every smooth surface, [`LocalSurface::new`]), whether the pair passes
/// [`crate::Flatness`]'s angle test (used for fields without a displacement scale), and the
/// criterion.
#[derive(Debug, Clone, Copy)]
struct Prefilter {
    model: Option<LocalSurface>,
    angle_flat: bool,
    flatness: crate::Flatness,
}

/// How one region's coefficients are read (the criterion: [`crate::Flatness`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Reading {
    /// The field's constant-time average over the flat footprint.
    ClosedForm,
    /// Points placed on the pair's local quadric ([`LocalSurface::lift`]) and read there,
    /// without rays.
    Lifted,
    /// Points projected onto the surface by rays (paper §3.2).
    Rays,
}

impl<'a, S, F> Probe<'a, S, F>
where
    S: SurfaceQuery + ?Sized,
    F: CoefficientField<S::Point> + ?Sized,
{
    pub fn new(surface: &'a S, field: &'a F, x_i: &'a S::Point, x_o: &'a S::Point) -> Self {
        Self {
            surface,
            field,
            x_i,
            x_o,
            diag: Diagnostics::default(),
            endpoints: None,
            chart: None,
            prefilter: None,
            reach: f64::INFINITY,
        }
    }

    /// One counted, sanitised lookup, in the field's averaging space
    /// ([`CoefficientField::averaged`]: σa and σs unless the field says otherwise).
    #[inline]
    pub fn lookup(&mut self, p: &S::Point) -> Coefficients {
        let c = self.field.averaged(p);
        self.counted(c)
    }

    /// A value the field returned, counted as a lookup and sanitised.
    #[inline]
    fn counted(&mut self, c: Coefficients) -> Coefficients {
        self.diag.lookups += 1;
        sanitise(c)
    }

    /// [`Probe::lookup`] at a point of space, for fields defined there
    /// ([`CoefficientField::averaged_at_point`]); `None`, uncounted, where the field has no
    /// value without a surface point.
    #[inline]
    pub fn lookup_at_point(&mut self, x: DVec3) -> Option<Coefficients> {
        let c = self.field.averaged_at_point(x)?;
        Some(self.counted(c))
    }

    /// The coefficients of a mean in the averaging space
    /// ([`CoefficientField::coefficients_of_mean`]); the mean itself, at no cost, for fields
    /// that average their coefficients.
    #[inline]
    pub fn to_coefficients(&self, mean: Coefficients) -> Coefficients {
        if !self.field.capabilities().own_averaging_space {
            mean
        } else {
            sanitise(self.field.coefficients_of_mean(mean))
        }
    }

    /// The chord x_i → x_o and its averaging-plane normal, recording the normal fallback in the
    /// diagnostics; `None` (recorded as [`crate::Region::Endpoints`]) when x_i and x_o coincide,
    /// in which case the caller returns [`Probe::endpoints`].
    pub fn chord(&mut self) -> Option<crate::chord::Chord> {
        let (x_i, x_o) = (self.x_i, self.x_o);
        match crate::chord::Chord::new(x_i.position(), x_i.normal(), x_o.position(), x_o.normal()) {
            Some(chord) => {
                self.diag.normal_fallback = chord.normal_fallback;
                Some(chord)
            }
            None => {
                self.diag.region = crate::estimator_output::Region::Endpoints;
                None
            }
        }
    }

    /// Prepares prefiltered reading for the pair on `chord` under `flatness`: fits the local
    /// quadric to the two ends ([`LocalSurface`]; a surface without curvature is taken as
    /// flat between them, its curvature counted as the model's error), runs the angle test
    /// for fields without a displacement scale, and, for a field that reads texture
    /// coordinates, takes the region's chart from the charts at x_i and x_o
    /// ([`UvChart::between`], kept for the reads; a pair whose charts disagree is recorded as a
    /// chart fallback). Then [`Probe::reading`] decides region by region.
    pub fn prepare_prefilter(&mut self, flatness: crate::Flatness, chord: &crate::chord::Chord) {
        let end = |p: &S::Point| End {
            position: p.position(),
            normal: p.normal().normalize(),
            curvature: self.surface.curvature(p).unwrap_or(Curvature::ZERO),
        };
        let (e_i, e_o) = (end(self.x_i), end(self.x_o));
        let model = LocalSurface::new(
            chord.mid,
            chord.half_len,
            chord.x_hat,
            chord.minor_dir,
            chord.normal,
            [&e_i, &e_o],
        );
        let angle_flat = flatness.is_flat(e_i.normal, e_o.normal, chord.x_hat);
        if model.is_some() && self.field.capabilities().reads_uv {
            self.chart = match (
                self.surface.uv_chart(self.x_i),
                self.surface.uv_chart(self.x_o),
            ) {
                (Some(a), Some(b)) => UvChart::between(&a, &b),
                _ => None,
            };
            self.diag.chart_fallback = self.chart.is_none();
        }
        self.prefilter = Some(Prefilter {
            model,
            angle_flat,
            flatness,
        });
    }

    /// How to read the region `e` of a pair [`Probe::prepare_prefilter`] prepared
    /// ([`crate::Flatness`]): in closed form (only if `closed_form`, the field offering an
    /// ellipse average), at points lifted onto the local quadric (for a field read at points
    /// of space or through a chart), or by rays. A region read by rays is recorded as a
    /// prefilter fallback, one read on the quadric as lifted.
    pub fn reading(&mut self, e: &crate::PlanarEllipse, closed_form: bool) -> Reading {
        let reading = self.decide(e, closed_form);
        match reading {
            Reading::Rays => self.diag.prefilter_fallback = true,
            Reading::Lifted => self.diag.lifted = true,
            Reading::ClosedForm => {}
        }
        reading
    }

    /// [`Probe::reading`] without the records.
    fn decide(&self, e: &crate::PlanarEllipse, closed_form: bool) -> Reading {
        let Some(Prefilter {
            model: Some(model),
            angle_flat,
            flatness,
        }) = self.prefilter
        else {
            return Reading::Rays;
        };
        let reads_uv = self.field.capabilities().reads_uv;
        if reads_uv && self.chart.is_none() {
            return Reading::Rays;
        }
        let points = self.field.capabilities().point_lookup || reads_uv;
        match self.field.displacement_scale(e) {
            // The angle test; the plane stands for the surface (the model is flat there).
            None if angle_flat && closed_form => Reading::ClosedForm,
            None if angle_flat && points => Reading::Lifted,
            None => Reading::Rays,
            Some(scale) => {
                if !model.covers(e) {
                    return Reading::Rays;
                }
                let tolerance = flatness.tolerance() * scale;
                let error = model.model_error(e);
                if closed_form && model.max_height(e) + error <= tolerance {
                    Reading::ClosedForm
                } else if points && error <= tolerance {
                    Reading::Lifted
                } else {
                    Reading::Rays
                }
            }
        }
    }

    /// The largest distance from the chord's midpoint within which points of the plane may be
    /// lifted onto the local quadric and read there (by [`Probe::reading`]'s criterion for
    /// regions of that radius, the field's displacement scale taken for the step-1 disk
    /// `disk`, the smallest region and so the most demanding); 0 where none may.
    pub fn lifting_radius(&self, disk: &crate::PlanarEllipse) -> f64 {
        let Some(Prefilter {
            model: Some(model),
            angle_flat,
            flatness,
        }) = self.prefilter
        else {
            return 0.0;
        };
        let reads_uv = self.field.capabilities().reads_uv;
        if !(self.field.capabilities().point_lookup || reads_uv)
            || (reads_uv && self.chart.is_none())
        {
            return 0.0;
        }
        match self.field.displacement_scale(disk) {
            None if angle_flat => f64::INFINITY,
            None => 0.0,
            Some(scale) => model.lifting_radius(flatness.tolerance() * scale),
        }
    }

    /// The pair's local quadric, where [`Probe::prepare_prefilter`] found one.
    pub fn model(&self) -> Option<&LocalSurface> {
        self.prefilter.as_ref().and_then(|p| p.model.as_ref())
    }

    /// The field's constant-time average over `e` ([`CoefficientField::ellipse_average`], or
    /// [`CoefficientField::ellipse_average_in_chart`] through the region's chart for a field
    /// that reads texture coordinates); only for a region [`Probe::reading`] reads in closed
    /// form.
    #[inline]
    pub fn field_ellipse_average(&self, e: &crate::PlanarEllipse) -> Option<Coefficients> {
        match &self.chart {
            Some(chart) => self.field.ellipse_average_in_chart(e, chart),
            None if self.field.capabilities().reads_uv => None,
            None => self.field.ellipse_average(e),
        }
    }

    /// ½(σ(x_i) + σ(x_o)) (in the averaging space), looked up once per pair (the d'Eon–Irving endpoint reading and the
    /// fallback of the region estimators).
    pub fn endpoints(&mut self) -> Coefficients {
        if let Some(c) = self.endpoints {
            return c;
        }
        let (a, b) = (self.lookup(self.x_i), self.lookup(self.x_o));
        let c = Coefficients {
            sigma_a: (a.sigma_a + b.sigma_a) * 0.5,
            sigma_s: (a.sigma_s + b.sigma_s) * 0.5,
        };
        self.endpoints = Some(c);
        c
    }

    /// Projects `origin` along ±`dir` and adds the coefficients at the hit to `acc` for
    /// `channels`; on a miss, adds the endpoint average if `miss_endpoints`, else nothing.
    #[inline]
    pub fn project_and_add(
        &mut self,
        origin: DVec3,
        dir: DVec3,
        channels: Channels,
        miss_endpoints: bool,
        acc: &mut Accumulator,
    ) {
        let value = self.project_value(origin, dir);
        self.add_or_miss(value, channels, miss_endpoints, acc);
    }

    /// The coefficients at the projection of `origin` along ±`dir` (the nearer hit), counted;
    /// `None` on a miss (counted too). Fields defined in space need only the hit's position,
    /// which some surfaces give without building a point
    /// ([`SurfaceQuery::project_position`]).
    #[inline]
    pub fn project_value(&mut self, origin: DVec3, dir: DVec3) -> Option<Coefficients> {
        let position = if self.field.capabilities().point_lookup {
            self.surface.project_position(origin, dir)
        } else {
            Projected::Undecided
        };
        self.value_at(origin, dir, position)
    }

    /// [`Probe::project_and_add`] at the points `centre + u.x·semi_major + u.y·semi_minor` of
    /// the ellipse `e` for the unit-disk points `us`, in order, projected along its normal (the
    /// positions are asked for [`CHUNK`] at a time, [`SurfaceQuery::project_positions`], and
    /// the field read at them together, [`CoefficientField::averaged_at_points`]); or, with
    /// [`Reading::Lifted`], the same points placed on the pair's local quadric and read there
    /// without rays (the field's point or chart reads; a chunk the field cannot read that way
    /// is projected).
    pub fn read_ellipse_points(
        &mut self,
        e: &crate::PlanarEllipse,
        us: &[glam::DVec2],
        channels: Channels,
        miss_endpoints: bool,
        acc: &mut Accumulator,
        reading: Reading,
    ) {
        let model = match reading {
            Reading::Lifted => self.model().copied(),
            _ => None,
        };
        self.reach = e.semi_major.length().max(e.semi_minor.length());
        for us in us.chunks(CHUNK) {
            let mut origins = [DVec3::ZERO; CHUNK];
            for (o, &u) in origins.iter_mut().zip(us) {
                *o = e.point(u);
            }
            let origins = &origins[..us.len()];
            if let Some(model) = &model {
                let mut lifted = [DVec3::ZERO; CHUNK];
                for (l, &o) in lifted.iter_mut().zip(origins) {
                    *l = model.lift(o);
                }
                let mut values = [Coefficients::default(); CHUNK];
                if self.lookup_at_points(&lifted[..us.len()], &mut values[..us.len()]) {
                    for c in &values[..us.len()] {
                        acc.add(c, channels);
                    }
                    continue;
                }
            }
            self.project_chunk(origins, e.normal, channels, miss_endpoints, acc);
        }
    }

    /// The values at the points `origins` of the plane (at most [`CHUNK`]), into `out`: those
    /// within `radius` of the chord's midpoint `mid` lifted onto the local quadric and read
    /// there ([`Probe::lifting_radius`]), the others projected along `dir` by rays
    /// ([`Probe::project_values`]; `None` for a miss).
    pub fn lift_or_project(
        &mut self,
        origins: &[DVec3],
        mid: DVec3,
        radius: f64,
        dir: DVec3,
        out: &mut [Option<Coefficients>],
    ) {
        debug_assert!(origins.len() <= CHUNK && out.len() == origins.len());
        // Projections look first as far from the plane as the chunk's points are from the
        // midpoint.
        self.reach = origins
            .iter()
            .map(|&o| (o - mid).length_squared())
            .fold(0.0, f64::max)
            .sqrt();
        let model = match self.model() {
            Some(m) if radius > 0.0 => *m,
            _ => return self.project_values(origins, dir, out),
        };
        let r2 = radius * radius;
        // Lifted points first, read together; then the others, projected together.
        let (mut near, mut far) = ([DVec3::ZERO; CHUNK], [DVec3::ZERO; CHUNK]);
        let (mut n_near, mut n_far) = (0, 0);
        for &o in origins {
            if (o - mid).length_squared() <= r2 {
                near[n_near] = model.lift(o);
                n_near += 1;
            } else {
                far[n_far] = o;
                n_far += 1;
            }
        }
        let mut near_values = [Coefficients::default(); CHUNK];
        if n_near > 0 && !self.lookup_at_points(&near[..n_near], &mut near_values[..n_near]) {
            // The field reads no points: project every one.
            return self.project_values(origins, dir, out);
        }
        let mut far_values = [None; CHUNK];
        if n_far > 0 {
            self.project_values(&far[..n_far], dir, &mut far_values[..n_far]);
        }
        let (mut i, mut j) = (0, 0);
        for (&o, slot) in origins.iter().zip(out.iter_mut()) {
            if (o - mid).length_squared() <= r2 {
                *slot = Some(near_values[i]);
                i += 1;
            } else {
                *slot = far_values[j];
                j += 1;
            }
        }
    }

    /// [`Probe::project_and_add`] for at most [`CHUNK`] origins along one direction.
    #[inline]
    fn project_chunk(
        &mut self,
        origins: &[DVec3],
        dir: DVec3,
        channels: Channels,
        miss_endpoints: bool,
        acc: &mut Accumulator,
    ) {
        let mut values = [None; CHUNK];
        let values = &mut values[..origins.len()];
        self.project_values(origins, dir, values);
        for &value in values.iter() {
            self.add_or_miss(value, channels, miss_endpoints, acc);
        }
    }

    /// [`Probe::project_value`] for at most [`CHUNK`] origins along one direction, into `out`
    /// (as long as `origins`), with the same counts: the positions are asked for together
    /// ([`SurfaceQuery::project_positions`]) and the field read at them together
    /// ([`CoefficientField::averaged_at_points`]).
    pub fn project_values(
        &mut self,
        origins: &[DVec3],
        dir: DVec3,
        out: &mut [Option<Coefficients>],
    ) {
        debug_assert!(origins.len() <= CHUNK && out.len() == origins.len());
        let mut positions = [Projected::Undecided; CHUNK];
        let positions = &mut positions[..origins.len()];
        let mut values = [Coefficients::default(); CHUNK];
        let mut read = false;
        if self.field.capabilities().point_lookup {
            self.surface.project_positions(origins, dir, positions);
            // The field at every position found, read together.
            let mut xs = [DVec3::ZERO; CHUNK];
            let mut n = 0;
            for p in positions.iter() {
                if let Projected::At(x) = *p {
                    xs[n] = x;
                    n += 1;
                }
            }
            read = n > 0 && self.field.averaged_at_points(&xs[..n], &mut values[..n]);
        }
        let mut next = 0;
        for ((&origin, &position), o) in origins.iter().zip(positions.iter()).zip(out) {
            *o = match position {
                Projected::At(_) if read => {
                    self.diag.projections += 1;
                    next += 1;
                    Some(self.counted(values[next - 1]))
                }
                _ => self.value_at(origin, dir, position),
            };
        }
    }

    /// [`Probe::lookup_at_point`] at every point of `xs` (at most [`CHUNK`]), read together
    /// ([`CoefficientField::averaged_at_points`]), into `out`; `false` (nothing counted, `out`
    /// unspecified) where the field has no value at some point without a surface point.
    pub fn lookup_at_points(&mut self, xs: &[DVec3], out: &mut [Coefficients]) -> bool {
        let read = match &self.chart {
            Some(chart) => self.field.averaged_at_points_in_chart(xs, chart, out),
            None => self.field.averaged_at_points(xs, out),
        };
        if !read {
            return false;
        }
        for o in out.iter_mut() {
            *o = self.counted(*o);
        }
        true
    }

    /// One counted projection, given what [`SurfaceQuery::project_position`] said about it.
    #[inline]
    fn value_at(&mut self, origin: DVec3, dir: DVec3, position: Projected) -> Option<Coefficients> {
        self.diag.projections += 1;
        let value = match position {
            Projected::At(x) => self
                .lookup_at_point(x)
                .or_else(|| self.lookup_projected(origin, dir)),
            Projected::Miss => None,
            Projected::Undecided => self.lookup_projected(origin, dir),
        };
        if value.is_none() {
            self.diag.misses += 1;
        }
        value
    }

    /// The coefficients at [`SurfaceQuery::project`]'s hit, `None` on a miss (uncounted).
    #[inline]
    fn lookup_projected(&mut self, origin: DVec3, dir: DVec3) -> Option<Coefficients> {
        let hit = self.surface.project_within(origin, dir, self.reach)?;
        debug_assert!(hit.position().is_finite());
        Some(self.lookup(&hit))
    }

    /// Adds `value` to `acc` for `channels`; a miss adds the endpoint mean under
    /// [`crate::MissPolicy::Endpoints`], else nothing.
    #[inline]
    fn add_or_miss(
        &mut self,
        value: Option<Coefficients>,
        channels: Channels,
        miss_endpoints: bool,
        acc: &mut Accumulator,
    ) {
        match value {
            Some(c) => acc.add(&c, channels),
            None if miss_endpoints => {
                let c = self.endpoints();
                acc.add(&c, channels);
            }
            None => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::SplitMix64;
    use crate::sampling::SegmentPoints;
    use std::num::NonZeroU32;

    /// The chunks hand over every point of the budget once, in order, at most [`CHUNK`] at a
    /// time, for fixed budgets of every length and for the replicates of an adaptive one
    /// (whose rounds start at odd indices); antithetic pairs split across chunks included.
    #[test]
    fn chunks_are_the_points_in_order() {
        use crate::sampling::{DiskPoints, PointSet};
        for n in 1..=70u32 {
            let mut rng = SplitMix64::new(u64::from(n));
            let mut got = Vec::new();
            average_chunks::<DiskPoints, _>(
                SampleBudget::fixed(n),
                (Rgb::ONE, Rgb::ONE),
                &mut rng,
                |pts, _| {
                    assert!(!pts.is_empty() && pts.len() <= CHUNK);
                    got.extend_from_slice(pts);
                },
            );
            let set = DiskPoints::new(&mut SplitMix64::new(u64::from(n)));
            let want: Vec<_> = (0..n).map(|k| set.point(k)).collect();
            assert_eq!(got, want, "n = {n}");
        }
        // An unreachable target: every round up to max, replicate by replicate.
        let max = REPLICATES * 40;
        let mut got = Vec::new();
        average_chunks::<DiskPoints, _>(
            SampleBudget::TargetRelError {
                rel_se: 1e-300,
                max: NonZeroU32::new(max).unwrap(),
            },
            (Rgb::ONE, Rgb::ONE),
            &mut SplitMix64::new(9),
            |pts, acc| {
                got.extend_from_slice(pts);
                // Values that vary (and do not cancel in antithetic pairs), so that the error
                // stays above the target.
                for p in pts {
                    let c = Coefficients::grey(1.0 + p.x * p.x, 1.0);
                    acc.add(&c, Rgb::ONE);
                }
            },
        );
        let mut rng = SplitMix64::new(9);
        let sets: Vec<DiskPoints> = (0..REPLICATES).map(|_| DiskPoints::new(&mut rng)).collect();
        let mut want = Vec::new();
        let mut done = 0;
        while done < max / REPLICATES {
            let target = (2 * done).clamp(1, max / REPLICATES);
            for set in &sets {
                want.extend((done..target).map(|k| set.point(k)));
            }
            done = target;
        }
        assert_eq!(got, want);
    }

    /// The adaptive budget stops at the target, or at `max` for an unreachable target, and
    /// its pooled mean agrees with the exact mean of t ↦ t² (1/3) within the claimed error.
    #[test]
    fn target_rel_error_stops_where_it_should() {
        let all = (Rgb::ONE, Rgb::ZERO);
        let mut rng = SplitMix64::new(5);
        let budget = SampleBudget::TargetRelError {
            rel_se: 1e-3,
            max: NonZeroU32::new(1 << 16).unwrap(),
        };
        let r = average::<SegmentPoints, _>(budget, all, &mut rng, |t, acc| {
            acc.add(&Coefficients::grey(t * t, 0.0), Rgb::ONE)
        });
        let err = r.rel_se.unwrap();
        assert!(err <= 1e-3 && err > 0.0, "{err}");
        assert!(r.samples < 1 << 16);
        let mean = r.acc.mean()[0].unwrap().0;
        assert!((mean - 1.0 / 3.0).abs() < 5.0 * err / 3.0, "{mean}");
        // An unreachable target runs to max.
        let budget = SampleBudget::TargetRelError {
            rel_se: 1e-12,
            max: NonZeroU32::new(1000).unwrap(),
        };
        let r = average::<SegmentPoints, _>(budget, all, &mut rng, |t, acc| {
            acc.add(&Coefficients::grey(t * t, 0.0), Rgb::ONE)
        });
        assert_eq!(r.samples, 1000 / REPLICATES * REPLICATES);
        // max below the replicate count behaves as Fixed(max).
        let budget = SampleBudget::TargetRelError {
            rel_se: 0.1,
            max: NonZeroU32::new(3).unwrap(),
        };
        let r = average::<SegmentPoints, _>(budget, all, &mut rng, |_, _| {});
        assert_eq!((r.samples, r.rel_se), (3, None));
    }
}
