//! Artist parameters in scene files (`subsurface_color`, `subsurface_radius`, `radius_scale`,
//! `anisotropy`, `invert`): what loads, what it becomes, and the errors.

use std::path::Path;

use bssrdf_core::{AlbedoInversion, ProfileModel, Rgb};
use glam::DVec3;
use het_estimate::{CoefficientField, Coefficients};
use tracer::field::InvertAt;
use tracer::scene::{Material, Scene};

use crate::scene::{MINIMAL, check, load_err};

/// MINIMAL with its material replaced by `material` (the keys after `type`).
fn with_material(material: &str) -> String {
    MINIMAL.replace(
        "sigma_a = 0.1\nsigma_s = 1.0\n",
        &format!("{}\n", material.trim()),
    )
}

fn load(text: &str) -> Scene {
    Scene::from_toml_str(text, Path::new("."), "artist.toml").unwrap()
}

#[test]
fn artist_material_loads_and_inverts_through_its_profile() {
    let s = load(&with_material(
        r#"
subsurface_color = [0.8, 0.5, 0.2]
subsurface_radius = 2.0
radius_scale = [1.0, 0.5, 0.25]
anisotropy = 0.3
eta = 1.3
profile = "pbd"
unit_scale = 10.0
invert = "after"
"#,
    ));
    let Material::Translucent(t) = &s.objects()[0].material else {
        panic!("not translucent")
    };
    assert_eq!(t.g, 0.3);
    let map = t.medium.artist_map().unwrap();
    assert_eq!(map.invert(), InvertAt::After);
    assert_eq!(map.inversion().model(), ProfileModel::Pbd);
    // σt = 1 / (radius · radius_scale / unit_scale); α from the profile's own inversion.
    let inv = AlbedoInversion::shared(ProfileModel::Pbd, 0.3, 1.3).unwrap();
    let c = t.medium.at_point(DVec3::new(0.1, 0.2, -0.5));
    for (k, (colour, mfp)) in [(0.8, 0.2), (0.5, 0.1), (0.2, 0.05)]
        .into_iter()
        .enumerate()
    {
        let alpha = inv.albedo(colour).unwrap();
        let st = c.sigma_a[k] + c.sigma_s[k];
        assert!((st - 1.0 / mfp).abs() < 1e-9 * st, "channel {k}: σt {st}");
        assert!((c.sigma_s[k] / st - alpha).abs() < 1e-12);
    }
    assert_eq!(t.medium.majorant(), Rgb::new(5.0, 10.0, 20.0));
    assert!(t.medium.is_constant() && !t.medium.is_grey());
    // Inverted after averaging: the estimators average colour and radius (here constant).
    let b = CoefficientField::<tracer::geometry::Hit>::bounds(&t.medium).unwrap();
    assert_eq!(b.min.sigma_a, Rgb::new(0.8, 0.5, 0.2));
    // The material's profile (not a render's --profile) defines the medium; the default
    // profile follows the η.
    let s = load(&with_material(
        "subsurface_color = 0.5\nsubsurface_radius = 1.0\neta = 1.3",
    ));
    let t = s.objects()[0].material.translucent().unwrap();
    let map = t.medium.artist_map().unwrap();
    assert_eq!(map.inversion().model(), ProfileModel::default_for(1.3));
    assert_eq!(map.invert(), InvertAt::DEFAULT);
    // The CLI's override.
    let s = s.with_invert(InvertAt::After);
    assert_eq!(
        s.artist_inversions(),
        vec![("m".to_string(), InvertAt::After)]
    );
}

#[test]
fn zero_radius_is_a_diffuse_surface_of_the_colour() {
    let s = load(&with_material(
        "subsurface_color = [0.8, 0.5, 0.2]\nsubsurface_radius = 0.0",
    ));
    assert_eq!(
        s.objects()[0].material,
        Material::diffuse(Rgb::new(0.8, 0.5, 0.2))
    );
    // A radius scale of zero too.
    let s = load(&with_material(
        "subsurface_color = 0.4\nsubsurface_radius = 1.0\nradius_scale = 0.0",
    ));
    assert!(matches!(s.objects()[0].material, Material::Diffuse { .. }));
}

/// A stripe radius with a zero band: the band is raised to the floor (1e-3 of the largest
/// radius), so σt and the majorant stay finite; a huge radius is nearly transparent.
#[test]
fn radius_limits_stay_finite() {
    let s = load(&with_material(
        r#"
subsurface_color = 0.6
subsurface_radius = { type = "stripe", width = 0.5, values = [0.0, 2.0] }
"#,
    ));
    let t = s.objects()[0].material.translucent().unwrap();
    let floor = t.medium.artist_map().unwrap().mfp_floor();
    assert_eq!(floor, 2e-3);
    assert_eq!(t.medium.majorant(), Rgb::splat(1.0 / floor));
    for x in [0.1, 0.3, 0.6, 0.8] {
        let c = t.medium.at_point(DVec3::new(x, 0.0, -0.5));
        assert!(c.is_valid() && (c.sigma_a + c.sigma_s).max_component() <= 1.0 / floor);
    }
    let s = load(&with_material(
        "subsurface_color = 0.6\nsubsurface_radius = 1e9",
    ));
    let t = s.objects()[0].material.translucent().unwrap();
    let c: Coefficients = t.medium.at_point(DVec3::ZERO);
    assert!(c.is_valid() && (c.sigma_a + c.sigma_s).max_component() <= 1.0001e-9);
}

#[test]
fn artist_errors_name_the_key() {
    let e = load_err(&with_material(
        "sigma_a = 0.1\nsigma_s = 1.0\nsubsurface_color = 0.5\nsubsurface_radius = 1.0",
    ));
    check(&e, "material[0]", &["not a mix"]);
    let e = load_err(&with_material("sigma_a = 0.1\nsubsurface_radius = 1.0"));
    check(&e, "material[0]", &["subsurface_color"]);
    let e = load_err(&with_material(
        "sigma_a = 0.1\nsigma_s = 1.0\nradius_scale = 2.0",
    ));
    check(&e, "material[0]", &["not a mix"]);
    let e = load_err(&with_material(
        "subsurface_color = 0.5\nsubsurface_radius = 1.0\ng = 0.1\nanisotropy = 0.1",
    ));
    check(&e, "material[0].anisotropy", &["not both"]);
    let e = load_err(&with_material(
        "subsurface_color = 1.5\nsubsurface_radius = 1.0",
    ));
    check(&e, "material[0].subsurface_color", &["[0, 1]"]);
    let e = load_err(&with_material(
        "subsurface_color = -0.5\nsubsurface_radius = 1.0",
    ));
    check(&e, "material[0].subsurface_color", &["non-negative"]);
    let e = load_err(&with_material(
        "subsurface_color = 0.5\nsubsurface_radius = -1.0",
    ));
    check(&e, "material[0].subsurface_radius", &["non-negative"]);
    let e = load_err(&with_material(
        "subsurface_color = 0.5\nsubsurface_radius = 1.0\ninvert = \"during\"",
    ));
    check(&e, "material[0].invert", &["before", "after"]);
    let e = load_err(&with_material(
        "subsurface_color = 0.5\nsubsurface_radius = 1.0\nradius_scale = [1.0, -1.0, 1.0]",
    ));
    check(&e, "material[0].radius_scale", &["non-negative"]);
    let e = load_err(&with_material(
        "subsurface_color = { type = \"stripe\", width = 1.0, values = [0.2, 0.4] }\nsubsurface_radius = 0.0",
    ));
    check(&e, "material[0].subsurface_radius", &["diffuse"]);
    let e = load_err(&with_material(
        "subsurface_color = { type = \"stripe\", width = 1.0, values = [0.2, 1.4] }\nsubsurface_radius = 1.0",
    ));
    check(&e, "material[0].subsurface_color", &["at most 1"]);
}
