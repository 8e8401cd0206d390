//! Could the kernel's weight be averaged in constant time, as Sone's ellipse is? A measurement
//! for docs/kernel.md ("Constant-time averaging"), not a feature.
//!
//! The kernel's W₂ depends on a surface point only through its distances to x_i and x_o, so it
//! is tempting to cut the plane into confocal rings (uniform ellipses with foci x_i and x_o,
//! whose stripe and check averages have closed forms) and weight each ring by its share of
//! W₂. This example measures the best case of that: the ring masses are exact (a dense
//! quadrature of W₂ in elliptic coordinates), so the only error is the ring's uniform weight
//! in place of W₂'s own profile around the ring, which peaks at the foci.
//!
//! Rings alone cannot carry that peak, so the example also fits rings together with annuli
//! centred on x_i and x_o (whose averages are disk averages, closed forms too), by least
//! squares on the same quadrature: the best case of a table of fitted coefficients.
//!
//! For 40 pairs of the Figure 4 stripe preset (x_i at the origin, x_o uniform in [−15, 15]²,
//! d ≥ 1; index-matched, g = 0), with the kernel's weight at the endpoints' mean σa, it
//! prints the error of the power-mean σ̄a (p = 0.875, the kernel's default) given by each
//! decomposition against the quadrature's, then what one decomposition's closed forms cost
//! (about 30 s):
//!
//!     cargo run --release --example kernel_rings

use het_bssrdf::het_estimate::kernel_table::KernelTable;
use het_bssrdf::het_estimate::pattern::{BinaryPattern, Stripe};
use het_bssrdf::het_estimate::prefilter::{FootprintWeight, PlaneFootprint, stripe_fraction};
use het_bssrdf::het_estimate::{KernelParams, SplitMix64, UniformSource};

use bssrdf_core::glam::DVec2;

/// The stripe preset's σa values (σs = 1).
const VALUES: [f64; 2] = [0.005, 0.1];
/// Quadrature nodes in μ (across the confocal ellipses) and ν (around them).
const NODES: (usize, usize) = (600, 720);

/// One pair: x_o (x_i is the origin) and the material of its kernel weight.
struct Pair {
    x_o: DVec2,
    /// σt' (σs' = 1 + σa, g = 0) and κ = σtr/σt' of the weight.
    sigma_t: f64,
    kappa: f64,
}

impl Pair {
    fn new(stripe: &Stripe, x_o: DVec2) -> Self {
        let value = |q: DVec2| VALUES[stripe.select(q.x, q.y)];
        let sigma_a = 0.5 * (value(DVec2::ZERO) + value(x_o));
        let sigma_t = sigma_a + 1.0;
        let sigma_tr = (3.0 * sigma_a * sigma_t).sqrt();
        Self {
            x_o,
            sigma_t,
            kappa: sigma_tr / sigma_t,
        }
    }

    /// W₂ at q up to a constant factor (the table's scaled weight times e^{−κ(ρ_i + ρ_o − d)},
    /// transport units).
    fn weight(&self, table: &KernelTable, q: DVec2) -> f64 {
        let (ri, ro) = (
            q.length() * self.sigma_t,
            (q - self.x_o).length() * self.sigma_t,
        );
        let d = self.x_o.length() * self.sigma_t;
        (table.log_weight(ri, ro, self.kappa) - self.kappa * (ri + ro - d)).exp()
    }
}

fn main() {
    let table = KernelTable::build(1.0);
    let stripe = Stripe::new(4.0, std::f64::consts::FRAC_PI_4);
    let p = KernelParams::new().exponent;
    let power_mean = |f: f64| ((1.0 - f) * VALUES[0].powf(p) + f * VALUES[1].powf(p)).powf(1.0 / p);
    let mut rng = SplitMix64::new(11);
    let pairs: Vec<Pair> = (0..40)
        .map(|_| {
            loop {
                let x_o = DVec2::new(30.0 * rng.next_f64() - 15.0, 30.0 * rng.next_f64() - 15.0);
                if x_o.length() >= 1.0 {
                    break Pair::new(&stripe, x_o);
                }
            }
        })
        .collect();
    println!("rings  focal shells  mean |ln(σ̄a approx / σ̄a exact)|  median   max");
    for (rings, shells) in [
        (4, 0),
        (8, 0),
        (16, 0),
        (32, 0),
        (8, 4),
        (8, 8),
        (16, 8),
        (16, 16),
    ] {
        let mut errors: Vec<f64> = pairs
            .iter()
            .map(|pair| {
                let (exact, approx) = fractions(&table, &stripe, pair, rings, shells);
                (power_mean(approx) / power_mean(exact)).ln().abs()
            })
            .collect();
        errors.sort_by(f64::total_cmp);
        let mean = errors.iter().sum::<f64>() / errors.len() as f64;
        println!(
            "{rings:>5}  {shells:>12}  {mean:>32.4}  {:>6.4}  {:>6.4}",
            errors[errors.len() / 2],
            errors[errors.len() - 1]
        );
    }
    // What the closed forms of one decomposition cost: the region averages of 16 rings and
    // 8 shell pairs (17 ellipses and 16 disks) for each pair, timed over repetitions.
    let repeats = 2000;
    let start = std::time::Instant::now();
    let mut sink = 0.0;
    for _ in 0..repeats {
        for pair in &pairs {
            sink += region_averages(&stripe, pair, 16, 8);
        }
    }
    let ns = start.elapsed().as_nanos() as f64 / (repeats * pairs.len()) as f64;
    println!(
        "16 rings + 8 shells: {ns:.0} ns of closed forms per decomposition (one iteration; {sink:.1})"
    );
}

/// The closed forms one decomposition of `rings` rings and `shells` shell pairs reads for
/// `pair` (their total area of value 1, so that none is optimised away).
fn region_averages(stripe: &Stripe, pair: &Pair, rings: usize, shells: usize) -> f64 {
    let geometry = Geometry::new(pair, rings, shells);
    geometry.regions(stripe).iter().map(|r| r.1).sum()
}

/// The regions of a decomposition about a pair's chord: ring boundaries (semi-major axes: h,
/// then geometric in s − h up to 80 mean free paths beyond the chord, where W₂ has fallen by
/// e^{−80κ} or, at κ → 0, by its power law) and focal shells' outer radii (geometric from
/// 0.02 to 2h).
struct Geometry {
    x_o: DVec2,
    mid: DVec2,
    x_hat: DVec2,
    h: f64,
    s_max: f64,
    rings: usize,
    shells: usize,
}

impl Geometry {
    fn new(pair: &Pair, rings: usize, shells: usize) -> Self {
        let d = pair.x_o.length();
        let h = 0.5 * d;
        Self {
            x_o: pair.x_o,
            mid: 0.5 * pair.x_o,
            x_hat: pair.x_o / d,
            h,
            s_max: h + 80.0 / pair.sigma_t,
            rings,
            shells,
        }
    }

    /// The semi-major axis of ring boundary `k` (0: the chord itself).
    fn boundary(&self, k: usize) -> f64 {
        if k == 0 {
            return self.h;
        }
        let (a, b) = ((0.02f64).ln(), (self.s_max - self.h).ln());
        self.h + (a + (b - a) * (k - 1) as f64 / (self.rings - 1) as f64).exp()
    }

    /// The outer radius of shell `j`.
    fn radius(&self, j: usize) -> f64 {
        let (a, b) = ((0.02f64).ln(), (2.0 * self.h).ln());
        (a + (b - a) * j as f64 / (self.shells.max(2) - 1) as f64).exp()
    }

    /// Each region's (area, area of value 1): the rings, then the shell pairs, as differences
    /// of the closed forms of the confocal ellipses and of the disks about both foci that bound
    /// them (each boundary evaluated once).
    fn regions(&self, stripe: &Stripe) -> Vec<(f64, f64)> {
        let average = |centre: DVec2, axis_u: DVec2, axis_v: DVec2| {
            let fp = PlaneFootprint {
                centre,
                axis_u,
                axis_v,
                weight: FootprintWeight::Uniform,
            };
            stripe_fraction(stripe, &fp).unwrap_or(0.0)
        };
        let ellipse = |s: f64| {
            let b = (s * s - self.h * self.h).max(0.0).sqrt();
            let area = std::f64::consts::PI * s * b;
            let ones = area * average(self.mid, s * self.x_hat, b * self.x_hat.perp());
            (area, ones)
        };
        let disks = |r: f64| {
            let area = std::f64::consts::PI * r * r;
            let (u, v) = (DVec2::new(r, 0.0), DVec2::new(0.0, r));
            let ones = area * (average(DVec2::ZERO, u, v) + average(self.x_o, u, v));
            (2.0 * area, ones)
        };
        let difference =
            |outer: (f64, f64), inner: (f64, f64)| (outer.0 - inner.0, outer.1 - inner.1);
        let mut regions = Vec::with_capacity(self.rings + self.shells);
        let mut inner = ellipse(self.boundary(0));
        for k in 1..=self.rings {
            let outer = ellipse(self.boundary(k));
            regions.push(difference(outer, inner));
            inner = outer;
        }
        let mut inner = (0.0, 0.0);
        for j in 0..self.shells {
            let outer = disks(self.radius(j));
            regions.push(difference(outer, inner));
            inner = outer;
        }
        regions
    }
}

/// The W₂-weighted fraction of the stripe's value 1 around `pair`: by quadrature, and by a
/// weighted sum of uniform regions whose averages have closed forms: `rings` confocal rings
/// and `shells` pairs of annuli centred on x_i and x_o (one coefficient per pair, the weight
/// being symmetric). With no shells each ring's coefficient is its share of W₂ (its mass over
/// its area); with shells the coefficients are W₂'s least-squares fit on the quadrature's
/// nodes (area-weighted), the best any table of such coefficients could do.
fn fractions(
    table: &KernelTable,
    stripe: &Stripe,
    pair: &Pair,
    rings: usize,
    shells: usize,
) -> (f64, f64) {
    let geometry = Geometry::new(pair, rings, shells);
    let (h, mid, x_hat) = (geometry.h, geometry.mid, geometry.x_hat);
    let y_hat = x_hat.perp();
    let shell_of = |rho: f64| (0..shells).find(|&j| rho <= geometry.radius(j));
    let n = rings + shells;
    // Normal equations of the area-weighted fit, and the exact sums.
    let mut gram = vec![0.0; n * n];
    let mut rhs = vec![0.0; n];
    let (mut total, mut ones) = (0.0, 0.0);
    // Elliptic coordinates: q = mid + h(cosh μ cos ν x̂ + sinh μ sin ν ŷ),
    // dA = h²(sinh²μ + sin²ν) dμ dν.
    let mu_max = (geometry.s_max / h).acosh();
    let (dmu, dnu) = (
        mu_max / NODES.0 as f64,
        std::f64::consts::TAU / NODES.1 as f64,
    );
    for i in 0..NODES.0 {
        let mu = (i as f64 + 0.5) * dmu;
        let s = h * mu.cosh();
        let ring = (1..=rings)
            .find(|&k| s <= geometry.boundary(k))
            .unwrap_or(rings)
            - 1;
        for j in 0..NODES.1 {
            let nu = (j as f64 + 0.5) * dnu;
            let q = mid + h * mu.cosh() * nu.cos() * x_hat + h * mu.sinh() * nu.sin() * y_hat;
            let area = h * h * (mu.sinh().powi(2) + nu.sin().powi(2)) * dmu * dnu;
            let w = pair.weight(table, q);
            total += w * area;
            if stripe.select(q.x, q.y) == 1 {
                ones += w * area;
            }
            // The basis functions that are non-zero at q, with their values.
            let mut basis = [(ring, 1.0), (n, 0.0), (n, 0.0)];
            for (slot, rho) in [(1, q.length()), (2, (q - pair.x_o).length())] {
                if let Some(k) = shell_of(rho) {
                    basis[slot] = (rings + k, 1.0);
                }
            }
            for &(a, va) in basis.iter().filter(|b| b.0 < n) {
                rhs[a] += area * w * va;
                for &(b, vb) in basis.iter().filter(|b| b.0 < n) {
                    gram[a * n + b] += area * va * vb;
                }
            }
        }
    }
    let regions = geometry.regions(stripe);
    let coefficients = if shells == 0 {
        // Without overlaps the fit is each ring's mass over its area.
        (0..n).map(|k| rhs[k] / gram[k * n + k]).collect()
    } else {
        solve(gram, rhs)
    };
    let (mut sum, mut weight) = (0.0, 0.0);
    for (c, (area, area_ones)) in coefficients.iter().zip(&regions) {
        sum += c * area_ones;
        weight += c * area;
    }
    (ones / total, sum / weight)
}

/// Solves the symmetric positive semi-definite system `a x = b` (`a` row-major, n × n) by
/// Gaussian elimination with partial pivoting, after a relative ridge of 1e-12 on the diagonal.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    let scale = (0..n).map(|i| a[i * n + i]).fold(0.0, f64::max);
    for i in 0..n {
        a[i * n + i] += 1e-12 * scale;
    }
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&x, &y| a[x * n + col].abs().total_cmp(&a[y * n + col].abs()))
            .unwrap_or(col);
        for k in 0..n {
            a.swap(col * n + k, pivot * n + k);
        }
        b.swap(col, pivot);
        for row in col + 1..n {
            let f = a[row * n + col] / a[col * n + col];
            for k in col..n {
                a[row * n + k] -= f * a[col * n + k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let tail: f64 = (row + 1..n).map(|k| a[row * n + k] * x[k]).sum();
        x[row] = (b[row] - tail) / a[row * n + row];
    }
    x
}
