//! Light sampling against closed forms: a rectangle's irradiance (Lambert's polygon formula)
//! and solid angle (Van Oosterom & Strackee), a constant environment's irradiance (πL).

use std::f64::consts::PI;

use bssrdf_core::Rgb;
use glam::DVec3;
use tracer::light::Light;
use tracer::rng::Rng;

use crate::common::{lambert_irradiance, mc};

/// Solid angle of triangle (a, b, c) seen from p (Van Oosterom & Strackee 1983).
fn triangle_solid_angle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (a, b, c) = (a - p, b - p, c - p);
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c)).abs();
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * num.atan2(den)
}

#[test]
fn quad_sampling_reproduces_irradiance_and_solid_angle() {
    let corner = DVec3::new(-0.5, 1.0, 2.0);
    let (eu, ev) = (DVec3::new(0.0, 1.5, 0.0), DVec3::new(2.0, 0.0, 0.3));
    let radiance = Rgb::new(1.0, 2.0, 0.5);
    let light = Light::quad(corner, eu, ev, radiance).unwrap();
    // The quad emits along eu × ev, which points to -z here (downward): receivers below.
    assert!(eu.cross(ev).z < 0.0);
    let verts = [corner, corner + eu, corner + eu + ev, corner + ev];
    let mut rng = Rng::from_keys(41, &[]);
    for (p, n) in [
        (DVec3::new(0.0, 0.0, 0.0), DVec3::Z),
        (DVec3::new(3.0, -1.0, 0.5), DVec3::new(0.0, 0.6, 0.8)),
        (DVec3::new(0.5, 1.5, 1.5), DVec3::Z), // close to the light
    ] {
        let closed = lambert_irradiance(p, n, &verts);
        let (e, se) = mc(200_000, || match light.sample_li(p, rng.uniform2()) {
            Some(s) => s.li[1] / radiance[1] * s.wi.dot(n).max(0.0),
            None => 0.0,
        });
        assert!(
            (e - closed).abs() < 5.0 * se + 1e-12,
            "irradiance {e} ± {se} vs closed form {closed}"
        );
        // The pdf is a density over the subtended solid angle: E[1/pdf] = Ω.
        let omega = triangle_solid_angle(p, verts[0], verts[1], verts[2])
            + triangle_solid_angle(p, verts[0], verts[2], verts[3]);
        let (w, wse) = mc(200_000, || {
            light
                .sample_li(p, rng.uniform2())
                .map_or(0.0, |s| 1.0 / s.pdf)
        });
        assert!(
            (w - omega).abs() < 5.0 * wse + 1e-12,
            "solid angle {w} ± {wse} vs {omega}"
        );
    }
    // Behind the emitting side: no light at all.
    assert!(
        light
            .sample_li(DVec3::new(0.0, 1.5, 5.0), [0.5, 0.5])
            .is_none()
    );
}

#[test]
fn environment_irradiance_is_pi_l() {
    let l = 0.7;
    let env = Light::environment(Rgb::splat(l)).unwrap();
    let mut rng = Rng::from_keys(42, &[]);
    let n = DVec3::new(0.0, 0.6, -0.8);
    let (e, se) = mc(400_000, || {
        let s = env.sample_li(DVec3::ZERO, rng.uniform2()).unwrap();
        assert!((s.pdf - 0.25 / PI).abs() < 1e-15);
        s.li[0] * s.wi.dot(n).max(0.0)
    });
    assert!((e - PI * l).abs() < 5.0 * se, "{e} ± {se} vs {}", PI * l);
    assert_eq!(env.le(DVec3::X), Rgb::splat(l));
}

#[test]
fn pdf_li_matches_sample_li_for_area_lights() {
    let light = Light::quad(
        DVec3::new(0.0, 0.0, 3.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, -1.0, 0.0),
        Rgb::ONE,
    )
    .unwrap();
    let mut rng = Rng::from_keys(43, &[]);
    let p = DVec3::new(0.2, -0.3, 0.0);
    for _ in 0..1000 {
        let s = light.sample_li(p, rng.uniform2()).unwrap();
        let y = p + s.dist * s.wi;
        let pdf = light.pdf_li(p, s.wi, y);
        assert!((pdf - s.pdf).abs() < 1e-9 * s.pdf);
    }
}
