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
//! For 40 pairs of the Figure 4 stripe preset (x_i at the origin, x_o uniform in [−15, 15]²,
//! d ≥ 1; index-matched, g = 0), with the kernel's weight at the endpoints' mean σa, it
//! prints the error of the power-mean σ̄a (p = 0.875, the kernel's default) given by K rings
//! against the quadrature's:
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
    println!("rings  mean |ln(σ̄a rings / σ̄a exact)|  median   max");
    for rings in [4usize, 8, 16, 32] {
        let mut errors: Vec<f64> = pairs
            .iter()
            .map(|pair| {
                let (exact, by_rings) = fractions(&table, &stripe, pair, rings);
                (power_mean(by_rings) / power_mean(exact)).ln().abs()
            })
            .collect();
        errors.sort_by(f64::total_cmp);
        let mean = errors.iter().sum::<f64>() / errors.len() as f64;
        println!(
            "{rings:>5}  {mean:>31.4}  {:>6.4}  {:>6.4}",
            errors[errors.len() / 2],
            errors[errors.len() - 1]
        );
    }
}

/// The W₂-weighted fraction of the stripe's value 1 around `pair`: by quadrature, and by
/// `rings` confocal rings whose masses come from the same quadrature.
fn fractions(table: &KernelTable, stripe: &Stripe, pair: &Pair, rings: usize) -> (f64, f64) {
    let d = pair.x_o.length();
    let h = 0.5 * d;
    let (x_hat, mid) = (pair.x_o / d, 0.5 * pair.x_o);
    let y_hat = x_hat.perp();
    // Semi-major axes of the ring boundaries: h, then geometric in s − h up to 80 mean free
    // paths beyond the chord (W₂ has fallen by e^{-80κ} or, at κ → 0, by its power law).
    let s_max = h + 80.0 / pair.sigma_t;
    let boundary = |k: usize| {
        if k == 0 {
            return h;
        }
        let (a, b) = ((0.02f64).ln(), (s_max - h).ln());
        h + (a + (b - a) * (k - 1) as f64 / (rings - 1) as f64).exp()
    };
    // Elliptic coordinates: q = mid + h(cosh μ cos ν x̂ + sinh μ sin ν ŷ),
    // dA = h²(sinh²μ + sin²ν) dμ dν.
    let mu_max = (s_max / h).acosh();
    let (dmu, dnu) = (
        mu_max / NODES.0 as f64,
        std::f64::consts::TAU / NODES.1 as f64,
    );
    let mut mass = vec![0.0; rings + 1];
    let (mut total, mut ones) = (0.0, 0.0);
    for i in 0..NODES.0 {
        let mu = (i as f64 + 0.5) * dmu;
        let s = h * mu.cosh();
        let ring = (1..=rings).find(|&k| s <= boundary(k)).unwrap_or(rings);
        for j in 0..NODES.1 {
            let nu = (j as f64 + 0.5) * dnu;
            let q = mid + h * mu.cosh() * nu.cos() * x_hat + h * mu.sinh() * nu.sin() * y_hat;
            let area = h * h * (mu.sinh().powi(2) + nu.sin().powi(2)) * dmu * dnu;
            let w = pair.weight(table, q) * area;
            total += w;
            if stripe.select(q.x, q.y) == 1 {
                ones += w;
            }
            mass[ring] += w;
        }
    }
    // Each ring's uniform mean of value 1, from the closed forms of the two confocal ellipses
    // that bound it.
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
    let (mut sum, mut weight) = (0.0, 0.0);
    let mut inner = ellipse(boundary(0));
    for (k, m) in mass.iter().enumerate().skip(1) {
        let outer = ellipse(boundary(k));
        sum += m * (outer.1 - inner.1) / (outer.0 - inner.0);
        weight += m;
        inner = outer;
    }
    (ones / total, sum / weight)
}
