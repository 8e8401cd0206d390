//! Helpers shared by the test modules: random directions and an independent f64
//! ray/triangle test for brute-force comparisons.

use glam::DVec3;
use tracer::rng::Rng;

/// Uniform direction on the sphere.
pub fn random_dir(rng: &mut Rng) -> DVec3 {
    let z = 1.0 - 2.0 * rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * rng.uniform();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Möller–Trumbore in f64 (written independently of the tracer's watertight test): the
/// distance to triangle `v` along the ray, if hit with t in (t_min, t_max).
pub fn brute_triangle(o: DVec3, d: DVec3, v: [DVec3; 3], t_min: f64, t_max: f64) -> Option<f64> {
    let e1 = v[1] - v[0];
    let e2 = v[2] - v[0];
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - v[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let w = d.dot(q) * inv;
    if w < 0.0 || u + w > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > t_min && t < t_max).then_some(t)
}

/// The shared asset `name`, from `../shared/assets/` beside the repository's root. When it is
/// absent the test is skipped with a note, except in CI (the environment variable `CI` is
/// set), where a missing asset fails the test.
pub fn asset(name: &str) -> Option<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let p = root.join("../shared/assets").join(name);
    if p.is_file() {
        Some(p)
    } else if std::env::var_os("CI").is_some() {
        panic!(
            "shared asset `../shared/assets/{name}` (from the repository's root) is missing in CI"
        );
    } else {
        eprintln!("note: shared asset `../shared/assets/{name}` is absent: test skipped");
        None
    }
}

/// Irradiance at `p` (receiver normal `n`) from a Lambertian polygon of radiance 1:
/// E = ½ Σ θ_i · n·(R_i × R_{i+1})/|R_i × R_{i+1}| (Lambert 1760; e.g. Arvo 1995, eq. 1),
/// R_i the unit vectors toward the vertices and θ_i the angle between consecutive ones.
pub fn lambert_irradiance(p: DVec3, n: DVec3, verts: &[DVec3]) -> f64 {
    let r: Vec<DVec3> = verts.iter().map(|v| (*v - p).normalize()).collect();
    let mut e = 0.0;
    for i in 0..r.len() {
        let (a, b) = (r[i], r[(i + 1) % r.len()]);
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        e += theta * n.dot(a.cross(b).normalize());
    }
    (0.5 * e).abs()
}

/// Mean and standard error of `n` draws of `f`.
pub fn mc(n: usize, mut f: impl FnMut() -> f64) -> (f64, f64) {
    let (mut s, mut s2) = (0.0, 0.0);
    for _ in 0..n {
        let x = f();
        s += x;
        s2 += x * x;
    }
    let mean = s / n as f64;
    let var = (s2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}
