//! The render loop shared by every integrator: rows rendered in parallel with rayon, one random
//! stream per (pixel, sample), a fixed sample count or a time budget, and a progress callback.
//!
//! Determinism: every pixel sample draws from `Rng::for_pixel_sample(seed, x, y, s)` and each
//! pixel's samples are added to its running sum in increasing `s` by one thread, so the image is
//! bit-identical whatever the number of threads or the scheduling order. A time-budget render
//! adds passes of doubling size to the same running sums, so it equals a fixed-count render
//! with the sample count it reached. A render can be restricted to one [`Shard`] of the rows
//! (for renders split across machines); the rows it holds get exactly the values of the whole
//! render, since their streams do not depend on the others. Renders run in passes (see [`render_observed`]), which
//! neither change a pixel nor depend on the thread count; an interrupt
//! ([`crate::interrupt`]) keeps the completed passes.

use std::time::{Duration, Instant};

use bssrdf_core::Rgb;
use rayon::prelude::*;

use crate::rng::Rng;

/// How many samples per pixel to take.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Budget {
    /// Exactly this many samples per pixel (> 0).
    Samples(u32),
    /// As many doubling passes (1, 1, 2, 4, … samples) as fit in this wall-clock time; at least
    /// one sample per pixel is always taken.
    Time(Duration),
}

/// Counters accumulated by integrators; merged deterministically across rows.
pub trait Counters: Default + Send + Sync {
    /// Adds `other` into `self`.
    fn merge(&mut self, other: &Self);
}

impl Counters for () {
    fn merge(&mut self, _: &Self) {}
}

/// Something that estimates the radiance reaching film position `(film_x, film_y)` (pixels,
/// (0, 0) the top-left corner of the image) with one sample.
pub trait PixelEstimator: Sync {
    /// Per-sample statistics this estimator keeps.
    type Counters: Counters;
    /// One radiance sample.
    fn sample(&self, film_x: f64, film_y: f64, rng: &mut Rng, counters: &mut Self::Counters)
    -> Rgb;
}

/// The result of a render.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Rendered<C> {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Mean radiance per pixel, row-major, row 0 at the top.
    pub pixels: Vec<Rgb>,
    /// Samples per pixel taken.
    pub spp: u32,
    /// Wall-clock time of the sampling (seconds).
    pub seconds: f64,
    /// Merged integrator counters.
    pub counters: C,
    /// True when [`RenderObserver::stop_requested`] ended the render before its budget: the
    /// image holds the passes completed before the request (`spp` of them).
    pub interrupted: bool,
}

/// Options of [`render`].
#[derive(Debug, Clone)]
pub struct RenderOptions {
    /// Sample count or time budget.
    pub budget: Budget,
    /// Seed of every random stream.
    pub seed: u64,
    /// The rows rendered ([`Shard::WHOLE`]: all of them); the others are left black.
    pub shard: Shard,
}

impl RenderOptions {
    /// The whole image at `spp` samples per pixel with `seed`.
    pub fn samples(spp: u32, seed: u64) -> Self {
        Self {
            budget: Budget::Samples(spp),
            seed,
            shard: Shard::WHOLE,
        }
    }
}

/// Shard `index` of `count` of an image: the rows `y` with `y mod count = index` (interleaved
/// rows). Interleaving balances the load, since every shard samples every band of the image
/// (a bright object in one band costs every shard alike), and any image height works: shards
/// differ by at most one row. Written `index/count`, e.g. `2/8`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Shard {
    index: u32,
    count: u32,
}

impl Shard {
    /// The whole image (`0/1`).
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// Shard `index` of `count`; `None` unless `index < count`.
    pub fn new(index: u32, count: u32) -> Option<Self> {
        (index < count).then_some(Self { index, count })
    }

    /// Its index (`0 ≤ index < count`).
    pub fn index(self) -> u32 {
        self.index
    }

    /// The number of shards of the image.
    pub fn count(self) -> u32 {
        self.count
    }

    /// True when row `y` belongs to this shard.
    #[inline]
    pub fn holds_row(self, y: u32) -> bool {
        y % self.count == self.index
    }

    /// How many of `height` rows belong to this shard.
    pub fn rows(self, height: u32) -> u32 {
        (height + self.count - 1 - self.index) / self.count
    }

    /// True for [`Shard::WHOLE`].
    pub fn is_whole(self) -> bool {
        self.count == 1
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl std::str::FromStr for Shard {
    type Err = String;
    /// Parses `I/N` with `0 ≤ I < N`.
    fn from_str(s: &str) -> Result<Self, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("expected I/N (shard I of N, 0 ≤ I < N), got `{s}`"))?;
        let parse = |v: &str, what: &str| {
            v.trim().parse::<u32>().map_err(|_| {
                format!("expected I/N (shard I of N, 0 ≤ I < N): `{v}` is not a valid {what}")
            })
        };
        let (i, n) = (parse(i, "shard index I")?, parse(n, "shard count N")?);
        if n == 0 {
            return Err(format!("the shard count N must be at least 1, got `{s}`"));
        }
        Shard::new(i, n).ok_or_else(|| {
            format!("the shard index I must be below the count N (0 ≤ I < N), got `{s}`")
        })
    }
}

/// The image after a completed pass, for checkpoints.
#[derive(Debug)]
pub struct Partial<'a, C> {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Sum of the samples of each pixel (row-major); divide by `spp` for the mean.
    pub sums: &'a [Rgb],
    /// Samples per pixel completed.
    pub spp: u32,
    /// Wall-clock seconds so far.
    pub seconds: f64,
    /// Counters of the completed passes.
    pub counters: &'a C,
}

impl<C> Partial<'_, C> {
    /// The mean radiance per pixel so far.
    pub fn mean(&self) -> Vec<Rgb> {
        let inv = 1.0 / f64::from(self.spp.max(1));
        self.sums.iter().map(|&s| s * inv).collect()
    }
}

/// What the render loop reports while it runs, and how it is stopped early. Called from the
/// worker threads, hence `Sync`.
pub trait RenderObserver<C>: Sync {
    /// A pass of samples `first..end` starts; `total` is the budget's sample count when it is
    /// fixed.
    fn pass_started(&self, first: u32, end: u32, total: Option<u32>) {
        let _ = (first, end, total);
    }
    /// `pixel_samples` more pixel samples were taken (reported pixel by pixel, so a time
    /// estimate is available from the first samples, not after the first row).
    fn advance(&self, pixel_samples: u64) {
        let _ = pixel_samples;
    }
    /// True to stop: the pass in progress is abandoned and the render returns the completed
    /// ones. Polled once per pixel. The default follows [`crate::interrupt`].
    fn stop_requested(&self) -> bool {
        crate::interrupt::requested()
    }
    /// A pass completed; `partial` is the image so far (for checkpoints).
    fn pass_finished(&self, partial: &Partial<'_, C>) {
        let _ = partial;
    }
}

/// The observer [`render`] uses: no progress, stopped by [`crate::interrupt`]. Applications
/// draw progress with an observer of their own (the experiments crate's bar).
#[derive(Debug, Clone, Copy, Default)]
pub struct NoObserver;

impl<C> RenderObserver<C> for NoObserver {}

/// A pass is not made longer than this (seconds, predicted), so that an interrupt loses at most
/// about this much work and checkpoints can be written between passes.
const PASS_SECONDS: f64 = 2.0;

/// Renders `width × height` pixels with `estimator` (see the module docs), reporting no
/// progress.
pub fn render<E: PixelEstimator>(
    width: u32,
    height: u32,
    estimator: &E,
    options: &RenderOptions,
) -> Rendered<E::Counters> {
    render_observed(width, height, estimator, options, &NoObserver)
}

/// [`render`] reporting to `observer` (progress, early stops, checkpoints).
///
/// The samples are taken in passes: `1, 1, 2, 4, …` samples per pixel, doubling while a pass
/// is predicted to take under 2 s. A pass is accumulated into a copy of the running
/// sums, each pixel's samples in increasing index, and replaces them only when it completes, so
/// the pass boundaries (and whether checkpoints are written, or an interrupt abandons a pass)
/// never change a pixel: the image is the same as a single pass's.
pub fn render_observed<E: PixelEstimator, O: RenderObserver<E::Counters> + ?Sized>(
    width: u32,
    height: u32,
    estimator: &E,
    options: &RenderOptions,
    observer: &O,
) -> Rendered<E::Counters> {
    let start = Instant::now();
    let w = width as usize;
    let n = w * height as usize;
    let mut sums = vec![Rgb::ZERO; n];
    let mut next_sums = vec![Rgb::ZERO; n];
    let mut counters = E::Counters::default();
    let total = match options.budget {
        Budget::Samples(s) => Some(s.max(1)),
        Budget::Time(_) => None,
    };
    let mut done = 0u32;
    let mut pass = 1u32;
    let mut interrupted = false;
    while pass > 0 {
        let end = done.saturating_add(pass);
        observer.pass_started(done, end, total);
        let pass_start = Instant::now();
        let rows: Vec<Option<E::Counters>> = next_sums
            .par_chunks_mut(w.max(1))
            .zip(sums.par_chunks(w.max(1)))
            .enumerate()
            .map(|(y, (row, old))| {
                let mut c = E::Counters::default();
                row.copy_from_slice(old);
                if !options.shard.holds_row(y as u32) {
                    return Some(c);
                }
                for (x, sum) in row.iter_mut().enumerate() {
                    if observer.stop_requested() {
                        return None;
                    }
                    for s in done..end {
                        let mut rng = Rng::for_pixel_sample(options.seed, x as u32, y as u32, s);
                        let fx = x as f64 + rng.uniform();
                        let fy = y as f64 + rng.uniform();
                        let v = estimator.sample(fx, fy, &mut rng, &mut c);
                        debug_assert!(v.is_finite(), "non-finite sample at ({x}, {y})");
                        *sum += v;
                    }
                    observer.advance(u64::from(end - done));
                }
                Some(c)
            })
            .collect();
        if observer.stop_requested() || rows.iter().any(Option::is_none) {
            interrupted = true;
            break;
        }
        for c in rows.iter().flatten() {
            counters.merge(c);
        }
        std::mem::swap(&mut sums, &mut next_sums);
        let per_sample = pass_start.elapsed().as_secs_f64() / f64::from(end - done);
        done = end;
        observer.pass_finished(&Partial {
            width,
            height,
            sums: &sums,
            spp: done,
            seconds: start.elapsed().as_secs_f64(),
            counters: &counters,
        });
        pass = next_pass(
            options.budget,
            done,
            per_sample,
            start.elapsed().as_secs_f64(),
        );
    }
    let inv = 1.0 / f64::from(done.max(1));
    Rendered {
        width,
        height,
        pixels: sums.into_iter().map(|s| s * inv).collect(),
        spp: done,
        seconds: start.elapsed().as_secs_f64(),
        counters,
        interrupted,
    }
}

/// The size of the pass after `done` samples per pixel (0: stop); see [`next_pass_size`].
fn next_pass(budget: Budget, done: u32, per_sample: f64, elapsed: f64) -> u32 {
    let (total, limit) = match budget {
        Budget::Samples(total) => (Some(u64::from(total.max(1))), None),
        Budget::Time(limit) => (None, Some(limit.as_secs_f64())),
    };
    let pass = next_pass_size(u64::from(done), per_sample, elapsed, total, limit);
    // A time budget stops before the sample count could overflow.
    if limit.is_some() && done >= u32::MAX / 2 {
        return 0;
    }
    u32::try_from(pass).unwrap_or(u32::MAX / 2)
}

/// The schedule of work done in passes, shared by every renderer that takes a budget (the
/// render loop's samples per pixel, the beam experiment's photon batches): after `done` units,
/// which took `per_unit` seconds each and `elapsed` seconds in all, the next pass doubles the
/// work so far, but holds no more than about 2 s of predicted work (so that an interrupt
/// loses little and checkpoints come regularly) and no more than what is left of a fixed
/// `total`. Under a time `limit` (seconds) it is 0 — stop — when it is predicted to overshoot.
/// Always at least 1 unit until the budget is spent. Passes never change a result: every unit
/// draws from its own random stream.
pub fn next_pass_size(
    done: u64,
    per_unit: f64,
    elapsed: f64,
    total: Option<u64>,
    limit: Option<f64>,
) -> u64 {
    let by_time = if per_unit > 0.0 {
        (PASS_SECONDS / per_unit)
            .floor()
            .clamp(1.0, u64::MAX as f64) as u64
    } else {
        u64::MAX
    };
    let pass = done.min(by_time).max(1);
    match (total, limit) {
        (Some(total), _) => pass.min(total.saturating_sub(done)),
        (None, Some(limit)) if elapsed + per_unit * pass as f64 > limit => 0,
        _ => pass,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Returns a deterministic function of the random stream, so images can be compared.
    struct Noise;
    impl PixelEstimator for Noise {
        type Counters = ();
        fn sample(&self, fx: f64, fy: f64, rng: &mut Rng, _: &mut ()) -> Rgb {
            Rgb::new(fx.fract() + rng.uniform(), fy, 1.0)
        }
    }

    fn opts(budget: Budget) -> RenderOptions {
        RenderOptions {
            budget,
            seed: 5,
            shard: Shard::WHOLE,
        }
    }

    #[test]
    fn identical_whatever_the_thread_count() {
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let two = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let a = one.install(|| render(13, 7, &Noise, &opts(Budget::Samples(5))));
        let b = two.install(|| render(13, 7, &Noise, &opts(Budget::Samples(5))));
        assert_eq!(a.spp, 5);
        assert_eq!(a.pixels, b.pixels);
    }

    /// Records what the render loop reports, and stops it after `stop_after` passes.
    struct Recorder {
        stop_after: usize,
        passes: std::sync::Mutex<Vec<(u32, Vec<Rgb>)>>,
        advances: std::sync::atomic::AtomicU64,
        calls: std::sync::atomic::AtomicU64,
    }
    impl RenderObserver<()> for Recorder {
        fn advance(&self, n: u64) {
            use std::sync::atomic::Ordering::Relaxed;
            self.advances.fetch_add(n, Relaxed);
            self.calls.fetch_add(1, Relaxed);
        }
        fn stop_requested(&self) -> bool {
            self.passes.lock().unwrap().len() >= self.stop_after
        }
        fn pass_finished(&self, p: &Partial<'_, ()>) {
            self.passes.lock().unwrap().push((p.spp, p.mean()));
        }
    }

    #[test]
    fn passes_progress_and_interrupts() {
        use std::sync::atomic::Ordering::Relaxed;
        let rec = |stop_after| Recorder {
            stop_after,
            passes: Default::default(),
            advances: Default::default(),
            calls: Default::default(),
        };
        // Progress is reported pixel by pixel (a time estimate from the first samples), and
        // every pixel sample is counted once.
        let r = rec(usize::MAX);
        let full = render_observed(13, 7, &Noise, &opts(Budget::Samples(9)), &r);
        assert!(!full.interrupted);
        assert_eq!(r.advances.load(Relaxed), 13 * 7 * 9);
        let passes = r.passes.lock().unwrap().len() as u64;
        assert_eq!(r.calls.load(Relaxed), 13 * 7 * passes);
        // Every completed pass is the image of a single-pass render with its spp, computed
        // here directly: each pixel's samples summed in increasing index.
        let reference = |spp: u32| -> Vec<Rgb> {
            let mut out = Vec::new();
            for y in 0..7u32 {
                for x in 0..13u32 {
                    let mut sum = Rgb::ZERO;
                    for s in 0..spp {
                        let mut rng = Rng::for_pixel_sample(5, x, y, s);
                        let fx = f64::from(x) + rng.uniform();
                        let fy = f64::from(y) + rng.uniform();
                        sum += Noise.sample(fx, fy, &mut rng, &mut ());
                    }
                    out.push(sum * (1.0 / f64::from(spp)));
                }
            }
            out
        };
        assert!(passes > 1);
        for (spp, mean) in r.passes.lock().unwrap().iter() {
            assert_eq!(&reference(*spp), mean, "pass at {spp} spp");
        }
        assert_eq!(full.pixels, reference(9));
        // Stopped after two passes: the completed ones are kept, marked as interrupted.
        let r = rec(2);
        let cut = render_observed(13, 7, &Noise, &opts(Budget::Samples(9)), &r);
        assert!(cut.interrupted);
        let (spp, mean) = r.passes.lock().unwrap()[1].clone();
        assert_eq!((cut.spp, &cut.pixels), (spp, &mean));
        assert!(cut.spp < 9);
    }

    #[test]
    fn shards_hold_their_rows_and_tile_the_image() {
        let full = render(5, 7, &Noise, &opts(Budget::Samples(3)));
        let mut covered = vec![0u32; 7];
        for i in 0..3 {
            let shard = Shard::new(i, 3).unwrap();
            let part = render(
                5,
                7,
                &Noise,
                &RenderOptions {
                    shard,
                    ..opts(Budget::Samples(3))
                },
            );
            let rows = (0..7).filter(|&y| shard.holds_row(y)).count() as u32;
            assert_eq!(shard.rows(7), rows);
            for (y, covers) in covered.iter_mut().enumerate() {
                let (a, b) = (&part.pixels[y * 5..][..5], &full.pixels[y * 5..][..5]);
                if shard.holds_row(y as u32) {
                    *covers += 1;
                    assert_eq!(a, b, "row {y} of shard {shard}");
                } else {
                    assert!(a.iter().all(|p| *p == Rgb::ZERO), "row {y} of {shard}");
                }
            }
        }
        assert_eq!(covered, vec![1; 7]);
    }

    #[test]
    fn shard_syntax() {
        assert_eq!("2/3".parse::<Shard>(), Ok(Shard::new(2, 3).unwrap()));
        assert_eq!(Shard::new(2, 3).unwrap().to_string(), "2/3");
        for bad in ["3/3", "1/0", "-1/3", "1", "a/3", "1/b", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    #[test]
    fn time_budget_equals_fixed_count_with_the_same_spp() {
        let t = render(8, 4, &Noise, &opts(Budget::Time(Duration::from_millis(30))));
        assert!(t.spp >= 1);
        let f = render(8, 4, &Noise, &opts(Budget::Samples(t.spp)));
        assert_eq!(t.pixels, f.pixels);
    }
}
