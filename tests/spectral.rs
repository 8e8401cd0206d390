//! Spectral MIS in chromatic media (docs/physics.md#spectral-mis): a half-space whose
//! coefficients differ a hundredfold between channels renders, channel by channel, what each
//! channel's own problem gives — the exact plane albedo under a uniform sky (index-matched),
//! and the grey render of that channel's coefficients behind a refractive boundary.

use bssrdf_core::{Rgb, Scattering};
use glam::DVec3;
use tracer::field::{Axis, Field, MediumField, PlanarProjection};
use tracer::integrator::{Method, PathOptions};
use tracer::light::Light;
use tracer::scene::{Scene, Translucent};

use crate::common::chandrasekhar::{half_space_albedo, single_scattering_albedo};
use crate::common::half_space::{half_space_lit, mean_and_se_rgb};

/// Single-scattering albedo per channel.
const OMEGA: Rgb = Rgb::new(0.99, 0.5, 0.9);
/// Extinction per channel in the top layer (1/length): a hundredfold spread, each channel's
/// diffusion length (at most 8.2 for green) far below the 200 deep, 400 wide half-space box.
const SIGMA_T: Rgb = Rgb::new(10.0, 0.1, 1.0);

/// The chromatic half-space medium: σt = `SIGMA_T` in layers 0.3 thick alternating with 3 ×
/// `SIGMA_T` with depth (so that delta tracking meets null collisions and shadow rays ratio
/// tracking), at the constant albedo `OMEGA`. A plane-parallel medium whose σt varies with
/// depth only is the homogeneous one in optical depth, so each channel's radiance is its
/// homogeneous half-space's.
fn layered(omega: Rgb, sigma_t: Rgb) -> MediumField {
    // Axis x: (s, t) = (y, z); at 90° the stripes' coordinate is z.
    let depth = PlanarProjection::new(Axis::X, DVec3::ZERO);
    let field =
        |v: Rgb| Field::stripe(0.3, std::f64::consts::FRAC_PI_2, [v, v * 3.0], depth).unwrap();
    let sigma_s = omega * sigma_t;
    let sigma_a = (Rgb::ONE - omega) * sigma_t;
    MediumField::new(field(sigma_a), field(sigma_s))
}

fn scene(medium: MediumField, eta: f64) -> Scene {
    half_space_lit(
        Translucent::new("m", medium, 0.0, eta),
        Light::environment(Rgb::ONE).unwrap(),
    )
}

/// Renders per channel: image mean and standard error over 8 seeds of `spp` samples (4 × 4
/// pixels). Paths that leak are dropped: a scattering vertex closer to the surface than the
/// hit test resolves (a few 10⁻⁶ at σt = 30, against the top face's 10-unit triangles) finds
/// no boundary. A handful of the 16·spp·8 paths may, which is far below the noise; more would
/// be a fault.
fn render(scene: &Scene, scattering: Scattering, spp: u32) -> (Rgb, Rgb) {
    let (m, se, lost) = mean_and_se_rgb(scene, Method::PathTraced, options(scattering), spp, 8);
    let paths = 16 * u64::from(spp) * 8;
    assert!(
        lost * 10_000 <= paths,
        "{lost} of {paths} paths capped or leaked"
    );
    (m, se)
}

fn options(scattering: Scattering) -> PathOptions {
    PathOptions {
        scattering,
        max_depth: 64,
    }
}

/// Under unit sky radiance the radiance leaving toward the normal is, by reciprocity, the
/// plane albedo at normal incidence A(ϖ, 1) = 1 − H(1)√(1 − ϖ) (all orders) and
/// (ϖ/2)(1 − ln 2) (single scattering) — per channel, at that channel's ϖ, whatever its σt.
/// Next-event estimation through the boundary (ratio tracking per channel), the environment
/// reached by direction sampling (MIS), delta tracking with the hero and the weights over the
/// channels all take part. 8 seeds, 4 standard errors per channel.
#[test]
fn chromatic_half_space_under_a_uniform_sky_has_each_channels_albedo() {
    let medium = layered(OMEGA, SIGMA_T);
    assert!(!medium.is_grey() && !medium.is_constant());
    let scene = scene(medium, 1.0);
    for scattering in [Scattering::All, Scattering::Single] {
        let (m, se) = render(&scene, scattering, 256);
        for c in 0..3 {
            let want = match scattering {
                Scattering::All => half_space_albedo(OMEGA[c]),
                _ => single_scattering_albedo(OMEGA[c]),
            };
            assert!(
                (m[c] - want).abs() < 4.0 * se[c],
                "{scattering}, channel {c} (ϖ {}, σt {}): {} ± {}, exact {want}",
                OMEGA[c],
                SIGMA_T[c],
                m[c],
                se[c]
            );
            assert!(
                se[c] < 0.02 * want,
                "test too weak: channel {c} se {}",
                se[c]
            );
        }
    }
}

/// Behind a refractive boundary (η = 1.3: no next-event estimation inside, the path leaves by
/// Fresnel refraction and finds the sky by chance) each channel of the chromatic render equals
/// the grey render of that channel's coefficients (the analog one-channel walk, validated
/// against Chandrasekhar above and in `validation.rs`), within 4 combined standard errors.
#[test]
fn chromatic_refractive_half_space_equals_each_channel_rendered_grey() {
    let eta = 1.3;
    let refractive = |medium: MediumField| render(&scene(medium, eta), Scattering::All, 512);
    let (m, se) = refractive(layered(OMEGA, SIGMA_T));
    for c in 0..3 {
        let (g, g_se) = refractive(layered(Rgb::splat(OMEGA[c]), Rgb::splat(SIGMA_T[c])));
        let tol = 4.0 * (se[c] * se[c] + g_se[0] * g_se[0]).sqrt();
        assert!(
            (m[c] - g[0]).abs() < tol,
            "channel {c}: chromatic {} ± {}, grey {} ± {}",
            m[c],
            se[c],
            g[0],
            g_se[0]
        );
        assert!(
            se[c] < 0.02 * g[0],
            "test too weak: channel {c} se {}",
            se[c]
        );
    }
}
