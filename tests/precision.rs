//! f32 geometry meets f64 physics (issue 7): the tracer intersects `f32` triangles (scaled, see
//! `tracer::geometry`) while profiles, estimators and sampling densities are `f64`. These tests
//! probe the seams: rays spawned from BSSRDF incident points, probe densities at grazing
//! configurations, lookups exactly on pattern boundaries, and rays through shared edges and
//! vertices of closed meshes, at several scales and far from the origin.

use std::f64::consts::PI;

use bssrdf_core::{ProfileFamily, ProfileModel, Rgb, Scattering};
use glam::DVec3;
use het_estimate::analytic::{CheckField, PlanePoint, StripeField};
use het_estimate::pattern::{BinaryPattern, Check, Stripe};
use het_estimate::{CoefficientField, Coefficients, Estimator};
use tracer::field::{Axis, Field, MediumField, PlanarProjection};
use tracer::geometry::{Geometry, Hit, ObjectSurface, Ray, TriangleMesh, primitives};
use tracer::integrator::probe_gathering::{ProbeSampler, probe};
use tracer::rng::Rng;

/// Standard errors allowed in the statistical checks (fixed seeds).
const Z: f64 = 4.0;

/// Uniform direction on the sphere.
fn random_dir(rng: &mut Rng) -> DVec3 {
    let z = 1.0 - 2.0 * rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * rng.uniform();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A closed convex test object: name, mesh, characteristic size.
fn convex_objects() -> Vec<(&'static str, TriangleMesh, f64)> {
    let far = DVec3::new(1e4, -2e4, 3e4);
    let mut v = Vec::new();
    for (name, centre, size) in [
        ("unit", DVec3::ZERO, 1.0),
        ("1e3", DVec3::new(0.0, 2e3, 0.0), 1e3),
        ("1e-3", DVec3::new(1e-3, 0.0, -2e-3), 1e-3),
        ("far off-centre", far, 1.0),
    ] {
        v.push((
            match name {
                "unit" => "sphere, unit",
                "1e3" => "sphere, 1e3",
                "1e-3" => "sphere, 1e-3",
                _ => "sphere, far off-centre",
            },
            primitives::icosphere(centre, size, 4),
            size,
        ));
        v.push((
            match name {
                "unit" => "box, unit",
                "1e3" => "box, 1e3",
                "1e-3" => "box, 1e-3",
                _ => "box, far off-centre",
            },
            primitives::subdivided_cuboid(centre - size, centre + 0.5 * size, [3, 4, 5]),
            size,
        ));
    }
    v
}

/// Hits on object 0 from random rays aimed at its bounding box from outside.
fn surface_hits(g: &Geometry, n: usize, rng: &mut Rng) -> Vec<Hit> {
    let (lo, hi) = g.object_bounds(0);
    let c = 0.5 * (lo + hi);
    let r = 0.5 * (hi - lo).length();
    let mut hits = Vec::with_capacity(n);
    while hits.len() < n {
        let target = lo + (hi - lo) * DVec3::new(rng.uniform(), rng.uniform(), rng.uniform());
        let o = c + 3.0 * r * random_dir(rng);
        if let Some(h) = g.intersect_object(0, &Ray::new(o, (target - o).normalize())) {
            hits.push(h);
        }
    }
    hits
}

/// A grey homogeneous medium whose probe radius is a fraction of `size`.
fn medium_for(size: f64) -> (ProfileFamily, MediumField, Coefficients) {
    let c = Coefficients::grey(1.0 / size, 20.0 / size);
    let family =
        ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.0).expect("family");
    (family, MediumField::homogeneous(c).expect("medium"), c)
}

/// Incident points x_i found by the BSSRDF probe rays around random x_o never see their own
/// triangle again: rays spawned outward miss the (convex) object, rays spawned inward hit
/// another triangle, and shadow rays toward a point light above x_i's tangent plane are not
/// occluded. Probe hits come from the crossing query (`for_each_object_hit`), not the
/// closest-hit query the tracer's own offset tests use.
///
/// One exception is explained rather than forbidden: the spawn offset is 2⁻¹⁸ × (|p|∞ +
/// triangle extent), i.e. relative to the distance from the *scene origin*. For a unit box at
/// (1e4, −2e4, 3e4) that is 0.11 scene units, and a ray spawned inward from x_i within that
/// distance of an edge starts on (or numerically beyond) the adjacent face's plane, so it may
/// leave through that face without a hit. Such escapes must be within 2 offsets of another
/// face; anywhere else they fail the test.
#[test]
fn probe_incident_points_do_not_self_intersect_at_any_scale() {
    let mut rng = Rng::from_keys(71, &[]);
    for (name, mesh, size) in convex_objects() {
        let (lo, hi) = mesh.bounds();
        let is_box = name.starts_with("box");
        let g = Geometry::build(vec![mesh]);
        let (family, medium, coeffs) = medium_for(size);
        let sampler = ProbeSampler::new(family, &medium);
        let mut bad = Vec::new();
        let (mut incident, mut explained) = (0, 0);
        for x_o in surface_hits(&g, 200, &mut rng) {
            for found in probe(&g, 0, &x_o, coeffs, &sampler, &mut rng).iter() {
                incident += 1;
                let x_i = found.hit;
                assert!(found.weight.is_finite() && found.weight > 0.0 && x_i.p.is_finite());
                for _ in 0..4 {
                    let d = random_dir(&mut rng);
                    let outward = d.dot(x_i.ng) > 0.0;
                    match g.intersect_object(0, &x_i.spawn_ray(d)) {
                        Some(h) if outward => bad.push(format!("outward ray re-hit {h:?}")),
                        Some(h) if h.prim == x_i.prim => bad.push(format!("self-hit {h:?}")),
                        None if !outward => {
                            let near_other_face = is_box
                                && (0..3).any(|a| {
                                    x_i.ng[a].abs() < 0.5
                                        && ((x_i.p[a] - lo[a]).abs() <= 2.0 * x_i.p_error
                                            || (x_i.p[a] - hi[a]).abs() <= 2.0 * x_i.p_error)
                                });
                            if near_other_face {
                                explained += 1;
                            } else {
                                bad.push(format!(
                                    "inward ray escaped from {:?} (offset {:e})",
                                    x_i.p, x_i.p_error
                                ));
                            }
                        }
                        _ => {}
                    }
                }
                // A light above the tangent plane at x_i, offset sideways.
                let (t1, _) = tracer::volume::orthonormal_basis(x_i.ng);
                let light = x_i.p + size * (x_i.ng + 0.7 * t1);
                let dir = (light - x_i.p).normalize();
                let shadow = Ray::between(x_i.spawn_origin(dir), light).expect("distinct points");
                if g.occluded(&shadow) {
                    bad.push(format!(
                        "shadow ray toward {light:?} occluded at {:?}",
                        x_i.p
                    ));
                }
            }
        }
        if explained > 0 {
            eprintln!(
                "{name}: {explained} inward rays of {} escaped within 2 offsets of an edge",
                4 * incident
            );
        }
        assert!(incident > 200, "{name}: only {incident} probe hits");
        assert!(
            bad.is_empty(),
            "{name}: {} failures among {incident} incident points, e.g. {:?}",
            bad.len(),
            &bad[..bad.len().min(5)]
        );
    }
}

/// Mean and standard error of `f` over `n` draws.
fn mean_se(n: usize, mut f: impl FnMut() -> f64) -> (f64, f64) {
    let (mut s, mut s2) = (0.0, 0.0);
    for _ in 0..n {
        let v = f();
        s += v;
        s2 += v * v;
    }
    let m = s / n as f64;
    let var = (s2 / n as f64 - m * m).max(0.0) * n as f64 / (n as f64 - 1.0);
    (m, (var / n as f64).sqrt())
}

/// Area of the part of `mesh` within distance `rho` of `p`, by uniform area sampling of the
/// mesh (independent of the probe sampler): `(area, standard error)`.
fn area_within(mesh: &TriangleMesh, p: DVec3, rho: f64, n: usize, rng: &mut Rng) -> (f64, f64) {
    let areas: Vec<f64> = (0..mesh.triangle_count())
        .map(|i| {
            let [a, b, c] = mesh.triangle_vertices(i);
            0.5 * (b - a).cross(c - a).length()
        })
        .collect();
    // Only triangles that can reach the ball matter: sample those.
    let near: Vec<usize> = (0..areas.len())
        .filter(|&i| {
            let v = mesh.triangle_vertices(i);
            let c = (v[0] + v[1] + v[2]) / 3.0;
            let r = v.iter().map(|q| (*q - c).length()).fold(0.0, f64::max);
            (c - p).length() <= rho + r
        })
        .collect();
    let total: f64 = near.iter().map(|&i| areas[i]).sum();
    let mut cdf = Vec::with_capacity(near.len());
    let mut acc = 0.0;
    for &i in &near {
        acc += areas[i] / total;
        cdf.push(acc);
    }
    let (frac, se) = mean_se(n, || {
        let u = rng.uniform();
        let k = cdf.partition_point(|&c| c < u).min(near.len() - 1);
        let [a, b, c] = mesh.triangle_vertices(near[k]);
        let (mut s, mut t) = (rng.uniform(), rng.uniform());
        if s + t > 1.0 {
            (s, t) = (1.0 - s, 1.0 - t);
        }
        let q = a + s * (b - a) + t * (c - a);
        if (q - p).length() <= rho { 1.0 } else { 0.0 }
    });
    (frac * total, se * total)
}

/// The probe density is right where probe rays graze the surface: x_o exactly on a box edge,
/// on a box corner (probe chords along the tangent axes run inside the adjacent faces' planes)
/// and on a sphere. One call of `probe` (three chords) returns hits weighted by 1/p(x), whose
/// sum has expectation equal to the area of the surface inside the probe sphere of radius
/// r_max, known independently: two half-disks (πρ²) at an edge, three quarter-disks (3πρ²/4)
/// at a corner, and for the icosphere a uniform-area Monte Carlo estimate (≈ πρ², Archimedes'
/// cap area for a true sphere). Every weight must be finite and positive, every hit within ρ.
#[test]
fn probe_density_is_unbiased_at_edges_corners_and_on_spheres() {
    let mut rng = Rng::from_keys(72, &[]);
    let family =
        ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.0).expect("family");
    let unit = Coefficients::grey(0.5, 0.5);
    let medium = MediumField::homogeneous(unit).expect("medium");
    let sampler = ProbeSampler::new(family, &medium);
    // Scale α' = ½ so that the probe radius is 0.3 (the scaling law is exact in the table).
    let k = sampler.probe_radius(unit) / 0.3;
    let coeffs = Coefficients::grey(0.5 * k, 0.5 * k);
    let rho = sampler.probe_radius(coeffs);
    assert!((rho - 0.3).abs() < 1e-6, "{rho}");

    let boxed = primitives::cuboid(DVec3::splat(-1.0), DVec3::splat(1.0));
    let centre = DVec3::new(0.2, -0.1, 0.3);
    let sphere = primitives::icosphere(centre, 1.0, 5);
    let n = 200_000;
    let edge = DVec3::new(1.0, 0.0, 1.0);
    let corner = DVec3::ONE;
    let towards = |target: DVec3, from: DVec3| Ray::new(from, (target - from).normalize());
    let cases: Vec<(&str, &TriangleMesh, Ray)> = vec![
        (
            "box edge",
            &boxed,
            towards(edge, edge + DVec3::new(1.0, 0.0, 1.0)),
        ),
        (
            "box edge (oblique ray)",
            &boxed,
            towards(edge, edge + DVec3::new(1.0, 0.3, 0.6)),
        ),
        ("box corner", &boxed, towards(corner, 2.0 * corner)),
        (
            "sphere",
            &sphere,
            towards(centre, centre + DVec3::new(3.0, 1.0, 2.0)),
        ),
    ];
    for (name, mesh, ray) in cases {
        let g = Geometry::build(vec![mesh.clone()]);
        let x_o = g.intersect_object(0, &ray).expect("x_o");
        let reference = match name {
            "box corner" => (0.75 * PI * rho * rho, 0.0),
            "sphere" => area_within(mesh, x_o.p, rho, 2_000_000, &mut rng),
            _ => (PI * rho * rho, 0.0),
        };
        if name.starts_with("box") {
            let want = if name == "box corner" { corner } else { edge };
            assert!((x_o.p - want).length() < 1e-6, "{name}: x_o = {:?}", x_o.p);
        } else {
            // Archimedes: a true sphere's cap within ρ of a surface point has area πρ².
            let rel = (reference.0 - PI * rho * rho).abs() / (PI * rho * rho);
            assert!(rel < 0.01, "icosphere cap area {reference:?} vs πρ²");
        }
        // Σ 1/p over the hits inside radius ρ' (the whole probe sphere, and its inner half,
        // where the weights are smaller and the test sharper).
        let mut empty = 0usize;
        let (mut sum, mut sum2, mut inner, mut inner2) = (0.0, 0.0, 0.0, 0.0);
        for _ in 0..n {
            let set = probe(&g, 0, &x_o, coeffs, &sampler, &mut rng);
            if set.is_empty() {
                empty += 1;
            }
            let (mut all, mut half) = (0.0, 0.0);
            for h in set.iter() {
                assert!(
                    h.weight.is_finite() && h.weight > 0.0,
                    "{name}: weight {} at {:?}",
                    h.weight,
                    h.hit.p
                );
                let dist = (h.hit.p - x_o.p).length();
                assert!(dist <= rho * (1.0 + 1e-9), "{name}: hit at {dist} > {rho}");
                all += h.weight;
                if dist < 0.5 * rho {
                    half += h.weight;
                }
            }
            sum += all;
            sum2 += all * all;
            inner += half;
            inner2 += half * half;
        }
        let stats = |s: f64, s2: f64| {
            let m = s / n as f64;
            (
                m,
                ((s2 / n as f64 - m * m).max(0.0) / (n as f64 - 1.0)).sqrt(),
            )
        };
        let inner_reference = match name {
            "box corner" => (0.75 * PI * 0.25 * rho * rho, 0.0),
            "sphere" => area_within(mesh, x_o.p, 0.5 * rho, 1_000_000, &mut rng),
            _ => (PI * 0.25 * rho * rho, 0.0),
        };
        for (what, (est, se), reference) in [
            ("ρ", stats(sum, sum2), reference),
            ("ρ/2", stats(inner, inner2), inner_reference),
        ] {
            let se_tot = (se * se + reference.1 * reference.1).sqrt();
            eprintln!(
                "{name}, within {what}: E[Σ 1/p] = {est:.6} ± {se:.6}, reference {:.6} ± {:.6} ({empty} empty probe sets of {n})",
                reference.0, reference.1
            );
            assert!(
                (est - reference.0).abs() < Z * se_tot,
                "{name}, within {what}: probe area estimate {est} ± {se} vs {reference:?}"
            );
            assert!(
                se < 0.03 * reference.0,
                "{name}: SE {se} too large to test anything"
            );
        }
    }
}

/// Exactly on a stripe boundary u = (k − ½)w (representable values) the shared pattern
/// definition k = ⌊u/w + ½⌋ puts the point in cell k (the + side), and one ulp below it in
/// cell k − 1; the same at check corners. Rotated stripes: points 1e-9 either side of a
/// boundary take the two sides' values. Repeated lookups agree.
#[test]
fn pattern_lookups_on_boundaries_follow_the_definition() {
    let parity = |k: i64| k.rem_euclid(2) as usize;
    for w in [1.0, 0.25, 3.0, 1e-3] {
        let s = Stripe::new(w, 0.0);
        let c = Check { width: w };
        for k in -6i64..=6 {
            let u = (k as f64 - 0.5) * w;
            // 3.0 and 1e-3 are not powers of two: the product may round; use it only if it
            // round-trips.
            if (u / w + 0.5) != k as f64 {
                continue;
            }
            assert_eq!(s.select(u, 7.3), parity(k), "stripe w={w} k={k}");
            assert_eq!(s.select(u, -1e9), parity(k), "stripe w={w} k={k}");
            // A few ulps below: one ulp below u = w/2 still rounds to the boundary in
            // u/w + ½ (0.5 − 2⁻⁵⁴ + 0.5 rounds to 1), so the boundary is sharp only to
            // within an ulp of u.
            let below = u - 4.0 * f64::EPSILON * u.abs();
            assert_eq!(
                s.select(below, 0.0),
                parity(k - 1),
                "stripe w={w} k={k} below"
            );
            for j in -3i64..=3 {
                let v = (j as f64 - 0.5) * w;
                if (v / w + 0.5) != j as f64 {
                    continue;
                }
                assert_eq!(c.select(u, v), parity(k + j), "check w={w} ({k}, {j})");
            }
        }
    }
    // Rotated stripes: the boundary through u = w/2 at 30°, approached from both sides.
    let s = Stripe::new(0.7, 30f64.to_radians());
    let n = DVec3::new(s.angle().cos(), s.angle().sin(), 0.0);
    let along = DVec3::new(-n.y, n.x, 0.0);
    for t in [-1e6, -3.0, 0.0, 2.5, 1e6] {
        for k in -3i64..=3 {
            let on = (k as f64 - 0.5) * 0.7 * n + t * along;
            let eps = 1e-9 * (1.0 + t.abs());
            let plus = on + eps * n;
            let minus = on - eps * n;
            assert_eq!(s.select(plus.x, plus.y), parity(k), "t={t} k={k} +");
            assert_eq!(s.select(minus.x, minus.y), parity(k - 1), "t={t} k={k} −");
            let v = s.select(on.x, on.y);
            assert_eq!(v, s.select(on.x, on.y), "non-deterministic");
        }
    }
}

/// The tracer's fields read the shared patterns at surface hits, also when the hit lies on a
/// boundary: the lookup is one of the two values, deterministic, and equal to the pattern at
/// the hit's (f64) position; estimators with x_i and x_o on boundaries give finite
/// coefficients inside the field's bounds.
#[test]
fn tracer_fields_and_estimators_on_pattern_boundaries() {
    let v = [Rgb::new(0.01, 0.02, 0.03), Rgb::new(5.0, 4.0, 3.0)];
    let proj = PlanarProjection::new(Axis::Z, DVec3::new(0.25, -0.5, 0.0));
    let w = 0.5;
    let stripe = Field::stripe(w, 0.0, v, proj).expect("stripe");
    let check = Field::check(w, v, proj).expect("check");
    let slab = primitives::subdivided_cuboid(
        DVec3::new(-4.0, -4.0, -1.0),
        DVec3::new(4.0, 4.0, 0.0),
        [16, 16, 1],
    );
    let g = Geometry::build(vec![slab]);
    let surface = ObjectSurface::new(&g, 0);
    let mut rng = Rng::from_keys(73, &[]);
    let prepared: Vec<_> = Estimator::ALL
        .iter()
        .map(|e| e.prepare(0.2, 1.0).expect("estimator"))
        .collect();
    for (name, field, pattern) in [
        (
            "stripe",
            &stripe,
            &Stripe::new(w, 0.0) as &dyn BinaryPattern,
        ),
        ("check", &check, &Check { width: w } as &dyn BinaryPattern),
    ] {
        let medium = MediumField::new(field.clone(), Field::constant(Rgb::ONE).expect("c"));
        let bounds = CoefficientField::<Hit>::bounds(&medium).expect("bounds");
        // Hits on the top face exactly above boundary lines and corners (s = (k − ½)w).
        let mut boundary_hits = Vec::new();
        for i in -4..=4 {
            for j in -4..=4 {
                let s = (i as f64 - 0.5) * w;
                let t = (j as f64 - 0.5) * w + if name == "stripe" { 0.13 } else { 0.0 };
                let p = DVec3::new(s + 0.25, t - 0.5, 0.0);
                let h = g
                    .intersect_object(0, &Ray::new(p + DVec3::Z, -DVec3::Z))
                    .expect("hit");
                let (hs, ht) = proj.st(h.p);
                let want = v[pattern.select(hs, ht)];
                let got = medium.at_surface(h.p, h.uv).sigma_a;
                assert_eq!(
                    got, want,
                    "{name}: lookup at {:?} differs from the pattern",
                    h.p
                );
                assert_eq!(got, medium.at_surface(h.p, h.uv).sigma_a);
                // The hit is on the boundary to f64 rounding.
                assert!((h.p.x - p.x).abs() < 1e-12 && (h.p.y - p.y).abs() < 1e-12);
                boundary_hits.push(h);
            }
        }
        for (k, pair) in boundary_hits.windows(2).enumerate() {
            for (e, est) in prepared.iter().enumerate() {
                let (x_i, x_o) = if k % 2 == 0 {
                    (&pair[0], &pair[1])
                } else {
                    (&pair[1], &pair[1])
                };
                let c = est
                    .estimate(&surface, &medium, x_i, x_o, &mut rng)
                    .coefficients;
                assert!(c.is_valid(), "{name} {}: {c:?}", Estimator::ALL[e].name());
                for ch in 0..3 {
                    assert!(
                        c.sigma_a[ch] >= bounds.min.sigma_a[ch]
                            && c.sigma_a[ch] <= bounds.max.sigma_a[ch],
                        "{name}: {c:?} outside {bounds:?}"
                    );
                }
            }
        }
    }
    // The analytic plane agrees with the same definitions on the boundary.
    let f = StripeField {
        pattern: Stripe::new(1.0, 0.0),
        values: [Coefficients::grey(0.0, 1.0), Coefficients::grey(1.0, 0.0)],
    };
    assert_eq!(f.coefficients(&PlanePoint::new(0.5, 0.0)).sigma_a[0], 1.0);
    assert_eq!(f.coefficients(&PlanePoint::new(-0.5, 0.0)).sigma_a[0], 0.0);
    let c = CheckField {
        pattern: Check { width: 1.0 },
        values: [Coefficients::grey(0.0, 1.0), Coefficients::grey(1.0, 0.0)],
    };
    assert_eq!(c.coefficients(&PlanePoint::new(0.5, 0.5)).sigma_a[0], 0.0);
    assert_eq!(c.coefficients(&PlanePoint::new(0.5, -0.5)).sigma_a[0], 1.0);
}

/// Closed meshes at several scales and offsets, with their vertices and shared-edge midpoints.
fn closed_meshes() -> Vec<(String, TriangleMesh)> {
    let mut v = Vec::new();
    for (centre, size) in [
        (DVec3::ZERO, 1.0),
        (DVec3::ZERO, 1e3),
        (DVec3::new(2e-3, 0.0, -1e-3), 1e-3),
        (DVec3::new(1e4, -2e4, 3e4), 1.0),
    ] {
        v.push((
            format!("cube {size} at {centre}"),
            primitives::cuboid(centre - size, centre + size),
        ));
        v.push((
            format!("subdivided box {size} at {centre}"),
            primitives::subdivided_cuboid(centre - size, centre + 0.7 * size, [2, 3, 2]),
        ));
        v.push((
            format!("icosphere {size} at {centre}"),
            primitives::icosphere(centre, size, 2),
        ));
    }
    v
}

/// Every vertex and every edge midpoint of a mesh (f64, from the f32 vertices).
fn edge_points(mesh: &TriangleMesh) -> Vec<DVec3> {
    let mut pts: Vec<DVec3> = mesh.positions.clone();
    for t in &mesh.triangles {
        for e in 0..3 {
            let (a, b) = (t[e] as usize, t[(e + 1) % 3] as usize);
            if a < b {
                pts.push(0.5 * (mesh.positions[a] + mesh.positions[b]));
            }
        }
    }
    pts
}

/// Rays that start exactly on a shared edge or vertex of a closed mesh and point into it find
/// the boundary (the walk would otherwise count a leak); rays from the centroid through every
/// vertex and edge midpoint find it too; and the full line through the centroid and such a
/// point crosses the (convex) mesh exactly twice (the probe sampler's crossing query merges the
/// duplicate hits of adjacent triangles).
#[test]
fn rays_through_shared_edges_and_vertices_find_the_boundary() {
    let mut rng = Rng::from_keys(74, &[]);
    for (name, mesh) in closed_meshes() {
        let (lo, hi) = mesh.bounds();
        let centre = 0.5 * (lo + hi);
        let g = Geometry::build(vec![mesh.clone()]);
        let mut failures = Vec::new();
        for p in edge_points(&mesh) {
            let to_centre = (centre - p).normalize();
            // From the point itself, inward (towards the centroid, jittered within 30°).
            for _ in 0..3 {
                let d = (to_centre + 0.5 * random_dir(&mut rng)).normalize();
                if d.dot(to_centre) < 0.5 {
                    continue;
                }
                if g.intersect_object(0, &Ray::new(p, d)).is_none() {
                    failures.push(format!("inward ray from {p:?} along {d:?} found nothing"));
                }
            }
            // From the centroid through the point.
            if g.intersect_object(0, &Ray::new(centre, -to_centre))
                .is_none()
            {
                failures.push(format!("ray from the centroid through {p:?} leaked"));
            }
            // The full line: exactly two crossings.
            let extent = (hi - lo).length();
            let start = p - 2.0 * extent * to_centre;
            let mut crossings = 0;
            g.for_each_object_hit(0, &Ray::segment(start, to_centre, 4.0 * extent), |_| {
                crossings += 1
            });
            if crossings != 2 {
                failures.push(format!("line through {p:?}: {crossings} crossings"));
            }
        }
        assert!(
            failures.is_empty(),
            "{name}: {} failures, e.g. {:?}",
            failures.len(),
            &failures[..failures.len().min(5)]
        );
    }
}
