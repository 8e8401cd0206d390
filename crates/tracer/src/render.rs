//! The render loop shared by every integrator: rows rendered in parallel with rayon, one random
//! stream per (pixel, sample), a fixed sample count or a time budget, and a progress callback.
//!
//! Determinism: every pixel sample draws from `Rng::for_pixel_sample(seed, x, y, s)` and each
//! pixel's samples are added to its running sum in increasing `s` by one thread, so the image is
//! bit-identical whatever the number of threads or the scheduling order. A time-budget render
//! adds passes of doubling size to the same running sums, so it equals a fixed-count render
//! with the sample count it reached.

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
}

/// Options of [`render`].
#[derive(Debug, Clone)]
pub struct RenderOptions {
    /// Sample count or time budget.
    pub budget: Budget,
    /// Seed of every random stream.
    pub seed: u64,
}

/// Receives the progress of a render (to draw a progress bar, log, or ignore it). Calls come
/// from the rendering threads.
pub trait Progress: Sync {
    /// A pass over `rows` rows starts (a time-budget render makes several passes).
    fn start_pass(&self, rows: u64);
    /// One row of the current pass is finished.
    fn row_done(&self);
    /// The render is finished.
    fn finish(&self);
}

/// A [`Progress`] that ignores every call.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn start_pass(&self, _: u64) {}
    fn row_done(&self) {}
    fn finish(&self) {}
}

/// Renders `width × height` pixels with `estimator` (see the module docs), reporting no
/// progress.
pub fn render<E: PixelEstimator>(
    width: u32,
    height: u32,
    estimator: &E,
    options: &RenderOptions,
) -> Rendered<E::Counters> {
    render_with_progress(width, height, estimator, options, &NoProgress)
}

/// [`render`], reporting each finished row to `progress`.
pub fn render_with_progress<E: PixelEstimator>(
    width: u32,
    height: u32,
    estimator: &E,
    options: &RenderOptions,
    progress: &dyn Progress,
) -> Rendered<E::Counters> {
    let start = Instant::now();
    let n = width as usize * height as usize;
    let mut sums = vec![Rgb::ZERO; n];
    let mut counters = E::Counters::default();
    // Fixed count: one pass. Time budget: passes of 1, 1, 2, 4, … samples.
    let mut done = 0u32;
    let mut pass = match options.budget {
        Budget::Samples(s) => s.max(1),
        Budget::Time(_) => 1,
    };
    loop {
        progress.start_pass(height as u64);
        let end = done.saturating_add(pass);
        let pass_start = Instant::now();
        let row_counters: Vec<E::Counters> = sums
            .par_chunks_mut(width as usize)
            .enumerate()
            .map(|(y, row)| {
                let mut c = E::Counters::default();
                for (x, sum) in row.iter_mut().enumerate() {
                    for s in done..end {
                        let mut rng = Rng::for_pixel_sample(options.seed, x as u32, y as u32, s);
                        let fx = x as f64 + rng.uniform();
                        let fy = y as f64 + rng.uniform();
                        let v = estimator.sample(fx, fy, &mut rng, &mut c);
                        debug_assert!(v.is_finite(), "non-finite sample at ({x}, {y})");
                        *sum += v;
                    }
                }
                progress.row_done();
                c
            })
            .collect();
        for c in &row_counters {
            counters.merge(c);
        }
        let per_sample = pass_start.elapsed().as_secs_f64() / (end - done) as f64;
        done = end;
        let Budget::Time(limit) = options.budget else {
            break;
        };
        // The next pass doubles the count; stop if it is predicted to overshoot the budget.
        let next = done;
        let predicted = start.elapsed().as_secs_f64() + per_sample * next as f64;
        if predicted > limit.as_secs_f64() || done >= u32::MAX / 2 {
            break;
        }
        pass = next;
    }
    progress.finish();
    let inv = 1.0 / done as f64;
    Rendered {
        width,
        height,
        pixels: sums.into_iter().map(|s| s * inv).collect(),
        spp: done,
        seconds: start.elapsed().as_secs_f64(),
        counters,
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
        RenderOptions { budget, seed: 5 }
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

    #[test]
    fn time_budget_equals_fixed_count_with_the_same_spp() {
        let t = render(8, 4, &Noise, &opts(Budget::Time(Duration::from_millis(30))));
        assert!(t.spp >= 1);
        let f = render(8, 4, &Noise, &opts(Budget::Samples(t.spp)));
        assert_eq!(t.pixels, f.pixels);
    }
}
