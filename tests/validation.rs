//! Validation of the reference path tracer against exact transport results (issue 7): the
//! light tracer of the beam experiment on a homogeneous, isotropic, index-matched half-space
//! against Chandrasekhar's exact albedo and the exact single-scattering albedo.

use bssrdf_core::Scattering;
use experiments::beam::{BeamSetup, BeamTexture, PhotonBudget, trace_photons};

use crate::common::chandrasekhar::{half_space_albedo, single_scattering_albedo};

/// 4 standard errors: with fixed seeds a correct tracer fails with probability ~6e-5 per check.
const Z: f64 = 4.0;

fn homogeneous(omega: f64) -> BeamSetup {
    let mut s = BeamSetup::paper(BeamTexture::Const { value: 1.0 - omega });
    s.sigma_s = omega;
    s.scattering = Scattering::All;
    s.resolution = 8;
    s
}

#[test]
fn half_space_albedo_matches_chandrasekhar_and_orders_split_exactly() {
    for (k, omega) in [0.5, 0.9, 0.99].into_iter().enumerate() {
        let setup = homogeneous(omega);
        let map = trace_photons(
            &setup,
            PhotonBudget::Count(1 << 17),
            100 + k as u64,
            &|_| {},
        )
        .expect("beam scene");
        let exits = map.exits.expect("light tracing counts exits");
        let want = half_space_albedo(omega);
        let (a, se) = exits.reflectance(Scattering::All);
        assert!(
            (a - want).abs() < Z * se,
            "ϖ={omega}: albedo {a} ± {se}, exact {want}"
        );
        let want_ss = single_scattering_albedo(omega);
        let (ss, se_ss) = exits.reflectance(Scattering::Single);
        assert!(
            (ss - want_ss).abs() < Z * se_ss,
            "ϖ={omega}: single {ss} ± {se_ss}, exact {want_ss}"
        );
        let (ms, se_ms) = exits.reflectance(Scattering::Multiple);
        let want_ms = want - want_ss;
        assert!(
            (ms - want_ms).abs() < Z * se_ms,
            "ϖ={omega}: multiple {ms} ± {se_ms}, exact {want_ms}"
        );
        // The orders partition the exits: nothing leaves unscattered at normal incidence.
        assert_eq!(exits.unscattered, 0);
        assert_eq!(
            map.counters.capped + map.counters.leaks,
            0,
            "{:?}",
            map.counters
        );
    }
}

/// Photons injected at surface point `from` with cosine-distributed directions into the beam
/// experiment's medium; the fraction leaving through the disk of radius `radius` around `to`.
fn diffuse_transfer(
    setup: &BeamSetup,
    from: [f64; 2],
    to: [f64; 2],
    radius: f64,
    photons: u64,
    seed: u64,
) -> (u64, u64) {
    use glam::DVec3;
    use tracer::geometry::Ray;
    use tracer::integrator::PathCounters;
    use tracer::integrator::walk::{Interface, WalkEnd, WalkMedium, WalkStart};
    use tracer::rng::Rng;
    use tracer::scene::Material;
    use tracer::volume::ChannelView;
    use tracer::volume::direction_about;
    let scene = setup.scene().unwrap();
    let entry = scene
        .geometry()
        .intersect(&Ray::new(DVec3::new(from[0], from[1], 1.0), DVec3::NEG_Z))
        .unwrap();
    let Material::Translucent(t) = &scene.objects()[0].material else {
        unreachable!()
    };
    let view = ChannelView::new(&t.medium, 0);
    let walk = WalkMedium {
        geometry: scene.geometry(),
        object: 0,
        medium: &view,
        g: t.g,
        interface: Interface::smooth(1.0),
    };
    let mut counters = PathCounters::default();
    let mut hits = 0;
    for k in 0..photons {
        let mut rng = Rng::from_keys(seed, &[k]);
        let u = rng.uniform2();
        let dir = direction_about(DVec3::NEG_Z, u[0].sqrt(), std::f64::consts::TAU * u[1]);
        let mut order = 0;
        let from = WalkStart {
            origin: entry.spawn_origin(dir),
            dir,
            last_scatter: None,
        };
        if let WalkEnd::Exited { hit, .. } =
            walk.walk(from, &mut order, &mut rng, &mut counters, |_, _, _, _| {})
            && hit.ng.z > 0.5
            && (hit.p.x - to[0]).hypot(hit.p.y - to[1]) < radius
        {
            hits += 1;
        }
    }
    assert_eq!(counters.capped + counters.leaks, 0);
    (hits, photons)
}

#[test]
fn transport_is_reciprocal_in_a_heterogeneous_medium() {
    // With a cosine-weighted (diffuse) source and hemispherical detection, reciprocity of the
    // radiative transfer equation makes the transfer from a to b equal that from b to a, even
    // though a and b lie in bands of different absorption (a: σa = 0.005, b: 0.1).
    let setup = BeamSetup::paper(BeamTexture::preset("stripe").unwrap());
    let (a, b) = ([0.0, 0.0], [2.5, 1.5]);
    let n = 600_000;
    let (ab, _) = diffuse_transfer(&setup, a, b, 0.5, n, 1);
    let (ba, _) = diffuse_transfer(&setup, b, a, 0.5, n, 2);
    let se = ((ab + ba) as f64).sqrt();
    assert!(ab > 1000 && ba > 1000, "too few counts: {ab}, {ba}");
    assert!(
        (ab as f64 - ba as f64).abs() < 4.0 * se,
        "a→b {ab}, b→a {ba}"
    );
}

#[test]
fn stripe_beam_map_has_the_texture_symmetries() {
    // The 45° stripe pattern is symmetric under reflection across the line along the stripes
    // ((x, y) → (−y, −x)) and across the perpendicular line ((x, y) → (y, x)); so must be the
    // path tracer's exitance map of a beam at the origin. Compare each pixel's count with its
    // mirror's: Σ (c₁ − c₂)²/(c₁ + c₂) over pairs is χ² with one degree of freedom per pair.
    let mut setup = BeamSetup::paper(BeamTexture::preset("stripe").unwrap());
    setup.resolution = 16;
    setup.extent = 8.0;
    let photons = 1 << 18;
    let map = trace_photons(&setup, PhotonBudget::Count(photons), 5, &|_| {}).unwrap();
    let n = setup.resolution as usize;
    let scale = map.samples as f64 * setup.pixel_size().powi(2);
    let count = |i: usize, j: usize| (map.values[i * n + j] * scale).round();
    for (name, mirror) in [
        (
            "along the stripes",
            (|i, j, n| (n - 1 - j, n - 1 - i)) as fn(usize, usize, usize) -> (usize, usize),
        ),
        ("across the stripes", |i, j, _| (j, i)),
    ] {
        let (mut chi2, mut dof) = (0.0, 0usize);
        for i in 0..n {
            for j in 0..n {
                let (mi, mj) = mirror(i, j, n);
                if (mi, mj) <= (i, j) {
                    continue; // each pair once; fixed points carry no information
                }
                let (c1, c2) = (count(i, j), count(mi, mj));
                if c1 + c2 >= 20.0 {
                    chi2 += (c1 - c2).powi(2) / (c1 + c2);
                    dof += 1;
                }
            }
        }
        // Upper quantile of χ²(dof), the two mirrors Šidák-corrected to family level 1e-4.
        let level = bssrdf_core::chi_square::ChiSquareTest::family(1e-4, 2).level();
        let crit = bssrdf_core::chi_square::critical(dof, level);
        assert!(dof > 50, "{name}: too few pairs ({dof})");
        assert!(
            chi2 < crit,
            "{name}: χ² = {chi2:.1} over {dof} pairs (critical {crit:.1})"
        );
    }
    // And the map is not symmetric under a transformation that breaks the pattern: a
    // quarter turn maps 45° stripes to −45° ones (a sanity check that the test can fail).
    let (mut chi2, mut dof) = (0.0, 0usize);
    for i in 0..n {
        for j in 0..n {
            let (mi, mj) = (j, n - 1 - i);
            let (c1, c2) = (count(i, j), count(mi, mj));
            if (mi, mj) > (i, j) && c1 + c2 >= 20.0 {
                chi2 += (c1 - c2).powi(2) / (c1 + c2);
                dof += 1;
            }
        }
    }
    assert!(
        chi2 > 3.0 * dof as f64,
        "a quarter turn looks symmetric: χ² = {chi2} over {dof}"
    );
}
