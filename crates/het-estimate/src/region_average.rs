//! The Monte Carlo averaging loop shared by the region estimators: accumulate sanitised
//! coefficients at projected sample points of a region, under a [`SampleBudget`].

use bssrdf_core::Rgb;
use glam::DVec3;

use crate::budget::{REPLICATES, SampleBudget};
use crate::estimate::Diagnostics;
use crate::field::{CoefficientField, Coefficients};
use crate::known::sanitise;
use crate::sampler::UniformSource;
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
    /// [`Probe::plane_stands_for_surface`] has found one.
    chart: Option<UvChart>,
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
        if self.field.averages_coefficients() {
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
                self.diag.region = crate::estimate::Region::Endpoints;
                None
            }
        }
    }

    /// Whether the pair is flat by `flatness` along the chord's direction `x_hat` (unit), so
    /// that its averaging plane stands for the surface (Sone's closed forms, the kernel's
    /// in-plane reading), and, for a field that reads texture coordinates, whether the charts
    /// at x_i and x_o are one affine map ([`UvChart::between`], kept for the reads); a pair
    /// that is not is recorded as a prefilter fallback.
    pub fn plane_stands_for_surface(&mut self, flatness: crate::Flatness, x_hat: DVec3) -> bool {
        let mut flat = flatness.is_flat(
            self.x_i.normal().normalize(),
            self.x_o.normal().normalize(),
            x_hat,
        );
        // A field read through texture coordinates also needs them to be one affine map over
        // the region: the charts at both ends must agree.
        if flat && self.field.reads_uv() {
            self.chart = match (
                self.surface.uv_chart(self.x_i),
                self.surface.uv_chart(self.x_o),
            ) {
                (Some(a), Some(b)) => UvChart::between(&a, &b),
                _ => None,
            };
            flat = self.chart.is_some();
            self.diag.chart_fallback = !flat;
        }
        self.diag.prefilter_fallback = !flat;
        flat
    }

    /// The field's constant-time average over `e` ([`CoefficientField::ellipse_average`], or
    /// [`CoefficientField::ellipse_average_in_chart`] through the region's chart for a field
    /// that reads texture coordinates); only for a pair [`Probe::plane_stands_for_surface`]
    /// accepted.
    #[inline]
    pub fn field_ellipse_average(&self, e: &crate::PlanarEllipse) -> Option<Coefficients> {
        match &self.chart {
            Some(chart) => self.field.ellipse_average_in_chart(e, chart),
            None if self.field.reads_uv() => None,
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
        let position = if self.field.has_point_lookup() {
            self.surface.project_position(origin, dir)
        } else {
            Projected::Undecided
        };
        self.value_at(origin, dir, position)
    }

    /// [`Probe::project_and_add`] at the points `centre + u.x·semi_major + u.y·semi_minor` of
    /// the ellipse `e` for the unit-disk points `us`, in order, projected along its normal: the
    /// positions are asked for [`CHUNK`] at a time ([`SurfaceQuery::project_positions`]) and
    /// the field read at them together ([`CoefficientField::averaged_at_points`]).
    pub fn project_ellipse_points(
        &mut self,
        e: &crate::PlanarEllipse,
        us: &[glam::DVec2],
        channels: Channels,
        miss_endpoints: bool,
        acc: &mut Accumulator,
    ) {
        for us in us.chunks(CHUNK) {
            let mut origins = [DVec3::ZERO; CHUNK];
            for (o, &u) in origins.iter_mut().zip(us) {
                *o = e.point(u);
            }
            self.project_chunk(
                &origins[..us.len()],
                e.normal,
                channels,
                miss_endpoints,
                acc,
            );
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
        if self.field.has_point_lookup() {
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
        let hit = self.surface.project(origin, dir)?;
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
    use crate::sampler::SplitMix64;
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
