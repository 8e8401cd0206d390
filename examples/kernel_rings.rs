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

use glam::DVec2;

/// The stripe preset's σa values (σs = 1).
const VALUES: [f64; 2] = [0.005, 0.1];
/// Quadrature nodes in μ (across the confocal ellipses) and ν (around them).
const NODES: (usize, usize) = (600, 720);

/// One pair: the exact W₂-weighted fraction of value 1, and the ring masses on the way.
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

/// The closed forms a decomposition of `rings` rings and `shells` shell pairs reads for
/// `pair` (their sum, so that none is optimised away).
fn region_averages(stripe: &Stripe, pair: &Pair, rings: usize, shells: usize) -> f64 {
    let d = pair.x_o.length();
    let h = 0.5 * d;
    let (x_hat, mid) = (pair.x_o / d, 0.5 * pair.x_o);
    let geometry = Geometry::new(h, pair.sigma_t, rings, shells);
    let mut sum = 0.0;
    for k in 0..=rings {
        let s = geometry.boundary(k);
        let fp = PlaneFootprint {
            centre: mid,
            axis_u: s * x_hat,
            axis_v: (s * s - h * h).max(0.0).sqrt() * x_hat.perp(),
            weight: FootprintWeight::Uniform,
        };
        sum += stripe_fraction(stripe, &fp).unwrap_or(0.0);
    }
    for j in 0..shells {
        let r = geometry.radius(j);
        for c in [DVec2::ZERO, pair.x_o] {
            let fp = PlaneFootprint {
                centre: c,
                axis_u: DVec2::new(r, 0.0),
                axis_v: DVec2::new(0.0, r),
                weight: FootprintWeight::Uniform,
            };
            sum += stripe_fraction(stripe, &fp).unwrap_or(0.0);
        }
    }
    sum
}

/// The regions of a decomposition: ring boundaries (semi-major axes: h, then geometric in
/// s − h up to 80 mean free paths beyond the chord, where W₂ has fallen by e^{−80κ} or, at
/// κ → 0, by its power law) and focal shells' outer radii (geometric from 0.02 to 2h).
struct Geometry {
    h: f64,
    s_max: f64,
    rings: usize,
    shells: usize,
}

impl Geometry {
    fn new(h: f64, sigma_t: f64, rings: usize, shells: usize) -> Self {
        Self {
            h,
            s_max: h + 80.0 / sigma_t,
            rings,
            shells,
        }
    }

    fn boundary(&self, k: usize) -> f64 {
        if k == 0 {
            return self.h;
        }
        let (a, b) = ((0.02f64).ln(), (self.s_max - self.h).ln());
        self.h + (a + (b - a) * (k - 1) as f64 / (self.rings - 1) as f64).exp()
    }

    fn radius(&self, j: usize) -> f64 {
        let (a, b) = ((0.02f64).ln(), (2.0 * self.h).ln());
        (a + (b - a) * j as f64 / (self.shells.max(2) - 1) as f64).exp()
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
    let d = pair.x_o.length();
    let h = 0.5 * d;
    let (x_hat, mid) = (pair.x_o / d, 0.5 * pair.x_o);
    let y_hat = x_hat.perp();
    let geometry = Geometry::new(h, pair.sigma_t, rings, shells);
    let (s_max, boundary, radius) = (
        geometry.s_max,
        |k| geometry.boundary(k),
        |j| geometry.radius(j),
    );
    let shell_of = |rho: f64| (0..shells).find(|&j| rho <= radius(j));
    let n = rings + shells;
    // Normal equations of the area-weighted fit, and the exact sums.
    let mut gram = vec![0.0; n * n];
    let mut rhs = vec![0.0; n];
    let (mut total, mut ones) = (0.0, 0.0);
    // Elliptic coordinates: q = mid + h(cosh μ cos ν x̂ + sinh μ sin ν ŷ),
    // dA = h²(sinh²μ + sin²ν) dμ dν.
    let mu_max = (s_max / h).acosh();
    let (dmu, dnu) = (
        mu_max / NODES.0 as f64,
        std::f64::consts::TAU / NODES.1 as f64,
    );
    for i in 0..NODES.0 {
        let mu = (i as f64 + 0.5) * dmu;
        let s = h * mu.cosh();
        let ring = (1..=rings).find(|&k| s <= boundary(k)).unwrap_or(rings) - 1;
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
    // Each region's area and its area of value 1, from the closed forms: confocal ellipses
    // for the rings, disks about both foci for the shells.
    let ellipse = |s: f64| {
        let b = (s * s - h * h).max(0.0).sqrt();
        let fp = PlaneFootprint {
            centre: mid,
            axis_u: s * x_hat,
            axis_v: b * y_hat,
            weight: FootprintWeight::Uniform,
        };
        let area = std::f64::consts::PI * s * b;
        (area, area * stripe_fraction(stripe, &fp).unwrap_or(0.0))
    };
    let disks = |r: f64| {
        let area = std::f64::consts::PI * r * r;
        let ones: f64 = [DVec2::ZERO, pair.x_o]
            .iter()
            .map(|&c| {
                let fp = PlaneFootprint {
                    centre: c,
                    axis_u: DVec2::new(r, 0.0),
                    axis_v: DVec2::new(0.0, r),
                    weight: FootprintWeight::Uniform,
                };
                area * stripe_fraction(stripe, &fp).unwrap_or(0.0)
            })
            .sum();
        (2.0 * area, ones)
    };
    let mut regions = Vec::with_capacity(n);
    for k in 1..=rings {
        let (outer, inner) = (ellipse(boundary(k)), ellipse(boundary(k - 1)));
        regions.push((outer.0 - inner.0, outer.1 - inner.1));
    }
    for j in 0..shells {
        let outer = disks(radius(j));
        let inner = if j == 0 {
            (0.0, 0.0)
        } else {
            disks(radius(j - 1))
        };
        regions.push((outer.0 - inner.0, outer.1 - inner.1));
    }
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
