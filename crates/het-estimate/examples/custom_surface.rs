//! A renderer author's view: implement the two traits for your own surface (here an analytic
//! sphere with procedural marble-like bands) and call an estimator.
//!
//! Run: `cargo run -p het-estimate --example custom_surface`

use het_estimate::glam::DVec3;
use het_estimate::{
    CoefficientField, Coefficients, Estimator, FieldBounds, SplitMix64, SurfacePoint, SurfaceQuery,
};

/// A sphere of radius `r` at the origin (the medium is inside).
struct Sphere {
    r: f64,
}

/// A point on the sphere. A mesh renderer would also keep triangle ids and UVs here.
#[derive(Clone, Copy)]
struct Hit {
    p: DVec3,
}

impl SurfacePoint for Hit {
    fn position(&self) -> DVec3 {
        self.p
    }
    fn normal(&self) -> DVec3 {
        self.p.normalize() // outward, i.e. out of the medium
    }
}

impl SurfaceQuery for Sphere {
    type Point = Hit;
    /// Both rays ±dir lie on one line: intersect the line and keep the root nearest `origin`.
    fn project(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        let b = origin.dot(dir);
        let disc = b * b - (origin.length_squared() - self.r * self.r);
        if disc < 0.0 {
            return None; // the line misses the sphere: both rays miss
        }
        let s = disc.sqrt();
        let t = if (-b - s).abs() < (-b + s).abs() {
            -b - s
        } else {
            -b + s
        };
        Some(Hit {
            p: origin + t * dir,
        })
    }
}

/// Bands of strong absorption along z; σs constant (so it is never averaged).
struct Bands;

impl CoefficientField<Hit> for Bands {
    fn coefficients(&self, h: &Hit) -> Coefficients {
        let dark = (h.p.z * 0.8 + 0.3 * (h.p.x * 0.5).sin()).sin() > 0.3;
        Coefficients::grey(if dark { 0.2 } else { 0.01 }, 1.5)
    }
    fn bounds(&self) -> Option<FieldBounds> {
        Some(FieldBounds {
            min: Coefficients::grey(0.01, 1.5),
            max: Coefficients::grey(0.2, 1.5),
        })
    }
}

fn main() {
    let sphere = Sphere { r: 10.0 };
    let on_sphere = |v: DVec3| Hit {
        p: sphere.r * v.normalize(),
    };
    let x_i = on_sphere(DVec3::new(1.0, 0.0, 0.1));
    let x_o = on_sphere(DVec3::new(1.0, 0.35, 0.6));
    let (g, eta) = (0.3, 1.3); // the material's HG g and relative index

    for estimator in Estimator::ALL {
        // Once per material (validates, and computes ⟨θ²⟩ for Sone, the table for the kernel).
        let prepared = estimator.prepare(g, eta).expect("valid parameters");
        // Per (x_i, x_o) pair, with the pixel's random stream.
        let mut rng = SplitMix64::new(42);
        let est = prepared.estimate(&sphere, &Bands, &x_i, &x_o, &mut rng);
        let (c, d) = (est.coefficients, est.diagnostics);
        println!(
            "{:<10} sigma_a = {:.4}  sigma_s = {:.2}  region {:?}, {} projections, {} misses{}",
            estimator.name(),
            c.sigma_a[0],
            c.sigma_s[0],
            d.region,
            d.projections,
            d.misses,
            d.width
                .map_or(String::new(), |w| format!(", w = {:.3}", w[0])),
        );
    }
}
