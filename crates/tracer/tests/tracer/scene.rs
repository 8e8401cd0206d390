//! Scene files: a full valid scene using every feature, and one test per class of bad input,
//! each checking that the message names the file and the key.

use std::path::Path;

use bssrdf_core::{ProfileModel, Rgb, Scattering};
use glam::DVec3;
use het_estimate::CoefficientField;
use tracer::camera::Camera;
use tracer::error::SceneError;
use tracer::field::Field;
use tracer::film::Film;
use tracer::geometry::Ray;
use tracer::light::Light;
use tracer::scene::{Material, Scene};

use crate::meshes::{CUBE_OBJ, write_gltf};

/// Writes the assets of the full scene: a 2x2 sRGB PNG, a 2x2 EXR, an OBJ cube, a glTF
/// tetrahedron.
fn write_assets(dir: &Path) {
    std::fs::create_dir_all(dir.join("textures")).unwrap();
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    let png = image::RgbImage::from_fn(2, 2, |x, y| {
        image::Rgb([(x * 255) as u8, (y * 128) as u8, 64])
    });
    png.save(dir.join("textures/marble.png")).unwrap();
    let mut f = Film::new(2, 2);
    f.set(0, 0, Rgb::new(0.5, 1.0, 2.0));
    f.set(1, 1, Rgb::splat(3.0));
    tracer::output::write_exr(&f, &dir.join("textures/density.exr")).unwrap();
    std::fs::write(dir.join("meshes/cube.obj"), CUBE_OBJ).unwrap();
    write_gltf(&dir.join("meshes"));
}

/// The sample scene given to the lead: every section, every field kind, every light and shape.
pub const FULL_SCENE: &str = r#"
# Lengths in scene units (cm here), angles in degrees, coefficients per scene unit after
# unit_scale, colours linear RGB (a number means grey).

[render]
width = 64
height = 48
spp = 16
seed = 7
max_depth = 256
estimator = "sone"
averaging = "monte-carlo"
scattering = "multiple"

[camera]
type = "perspective"
eye = [0.0, -40.0, 25.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 0.0, 1.0]
fov_y = 35.0

[[texture]]
name = "marble"
path = "textures/marble.png"   # 8-bit colour: decoded from sRGB
linear = false

[[texture]]
name = "density"
path = "textures/density.exr"  # EXR: always linear

[[texture]]
name = "unused"
path = "textures/does-not-exist.png"   # never decoded: no material that a shape uses refers to it

[[material]]
name = "stripes"
type = "translucent"
sigma_a = { type = "stripe", width = 2.0, angle = 45.0, values = [0.01, 0.5], axis = "z", origin = [0.0, 0.0, 0.0] }
sigma_s = 1.0
g = 0.0
eta = 1.0
profile = "dipole"

[[material]]
name = "checker"
type = "translucent"
sigma_a = { type = "check", width = 4.0, values = [[0.01, 0.02, 0.03], 0.5] }
sigma_s = [1.0, 1.2, 1.5]
g = 0.3
eta = 1.3
profile = "pbd"

[[material]]
name = "marble"
type = "translucent"
sigma_a = { type = "image", texture = "marble", mapping = "planar", axis = "z", origin = [0.0, 0.0, 0.0], size = [30.0, 30.0], wrap = "repeat", filter = "bilinear", scale = [0.5, 0.6, 0.7] }
sigma_s = { type = "image", texture = "density", mapping = "planar", axis = "x", size = [10.0, 10.0], wrap = "clamp", filter = "nearest", scale = 2.0 }
eta = 1.5
unit_scale = 10.0   # the coefficients above are per mm; the scene is in cm

[[material]]
name = "painted"
type = "translucent"
sigma_a = { type = "image", texture = "marble", mapping = "uv", scale = 0.2 }   # surface only
sigma_s = { type = "constant", value = 2.0 }
profile = "better-dipole"

[[material]]
name = "never-used"
type = "translucent"
sigma_a = { type = "image", texture = "unused", size = [1.0, 1.0] }
sigma_s = 1.0

[[material]]
name = "floor"
type = "diffuse"
albedo = [0.5, 0.5, 0.45]

[[light]]
type = "directional"
direction = [0.0, 0.0, -1.0]   # the direction the light travels
irradiance = [1.0, 1.0, 1.0]

[[light]]
type = "point"
position = [10.0, -10.0, 20.0]
intensity = 50.0

[[light]]
type = "quad"
corner = [-5.0, -5.0, 30.0]
edge_u = [0.0, 10.0, 0.0]
edge_v = [10.0, 0.0, 0.0]      # edge_u × edge_v = -z: emits downward
radiance = [4.0, 4.0, 4.0]

[[light]]
type = "environment"
radiance = 0.05

[[light]]
type = "beam"
origin = [0.0, 0.0, 1.0]
direction = [0.0, 0.0, -1.0]
power = 1.0

[[shape]]
type = "half_space"
name = "slab"
material = "stripes"
top = 0.0
centre = [0.0, 0.0]
size = 200.0
depth = 100.0
subdivisions = 16

[[shape]]
type = "box"
material = "checker"
min = [-2.0, -2.0, 0.0]
max = [2.0, 2.0, 4.0]
transform = { translate = [20.0, 0.0, 0.0] }

[[shape]]
type = "sphere"
name = "ball"
material = "marble"
centre = [0.0, 0.0, 5.0]
radius = 3.0
subdivisions = 4
transform = { scale = [1.0, 1.0, 0.5], rotate = { axis = [0.0, 0.0, 1.0], degrees = 30.0 }, translate = [-15.0, 0.0, 0.0] }

[[shape]]
type = "obj"
name = "cube"
material = "painted"
path = "meshes/cube.obj"
transform = { scale = 2.0, translate = [0.0, 20.0, 0.0] }

[[shape]]
type = "gltf"
name = "tet"
material = "floor"
path = "meshes/tet.gltf"
"#;

fn load_full() -> (tempfile::TempDir, Scene) {
    let dir = tempfile::tempdir().unwrap();
    write_assets(dir.path());
    let p = dir.path().join("full.toml");
    std::fs::write(&p, FULL_SCENE).unwrap();
    let scene = Scene::load(&p).unwrap_or_else(|e| panic!("{e}"));
    (dir, scene)
}

#[test]
fn full_scene_loads() {
    let (dir, s) = load_full();
    assert_eq!(
        s.source_path(),
        Some(dir.path().join("full.toml").as_path())
    );
    let r = &s.settings();
    assert_eq!(
        (r.width, r.height, r.spp, r.seed, r.max_depth),
        (64, 48, 16, 7, Some(256))
    );
    assert_eq!(r.estimator.map(|e| e.name()), Some("sone"));
    assert_eq!(r.averaging, Some(het_estimate::Averaging::MonteCarlo));
    assert_eq!(r.scattering, Some(Scattering::Multiple));
    assert!(matches!(s.camera(), Camera::Perspective(_)));
    assert_eq!(s.camera().resolution(), (64, 48));
    assert_eq!(s.lights().len(), 5);
    assert_eq!(s.beams().count(), 1);
    // 5 shapes + the quad light.
    assert_eq!(s.objects().len(), 6);
    assert_eq!(s.geometry().object_count(), 6);
    let names: Vec<&str> = s.objects().iter().map(|o| o.name.as_str()).collect();
    assert_eq!(
        names,
        ["slab", "shape[1]", "ball", "cube", "tet", "light[2]"]
    );
    let quad = &s.objects()[5];
    assert_eq!(quad.emitter, Some(2));
    assert!(matches!(quad.material, Material::Emissive { .. }));
    let Light::Quad(q) = s.lights()[2] else {
        panic!()
    };
    assert_eq!(q.object, Some(5));
    // The quad is hittable by a camera ray from below.
    let h = s
        .geometry()
        .intersect(&Ray::new(DVec3::new(0.0, 0.0, 29.0), DVec3::Z))
        .unwrap();
    assert_eq!(h.object, 5);
    assert!(s.lights()[2].emitted(&h, DVec3::NEG_Z) == Rgb::splat(4.0));

    // Materials.
    let Material::Translucent(stripes) = &s.objects()[0].material else {
        panic!()
    };
    assert_eq!(stripes.profile, Some(ProfileModel::Dipole));
    assert!(matches!(stripes.medium.sigma_a(), Field::Pattern { .. }));
    assert!(stripes.medium.is_grey() && stripes.medium.is_volumetric());
    let Material::Translucent(checker) = &s.objects()[1].material else {
        panic!()
    };
    assert!(!checker.medium.is_grey());
    assert_eq!((checker.g, checker.eta), (0.3, 1.3));
    let Material::Translucent(marble) = &s.objects()[2].material else {
        panic!()
    };
    assert_eq!(marble.unit_scale, 10.0);
    // sigma_s = 10 · 2 · texel: the EXR's largest texel is 3.
    assert_eq!(marble.medium.sigma_s().max(), Rgb::splat(60.0));
    let Material::Translucent(painted) = &s.objects()[3].material else {
        panic!()
    };
    assert!(!painted.medium.is_volumetric());
    assert!(matches!(s.objects()[4].material, Material::Diffuse { .. }));

    // Geometry: the half-space top at z = 0, the box translated, the cube scaled.
    let (lo, hi) = s.geometry().object_bounds(0);
    assert_eq!((lo.z, hi.z), (-100.0, 0.0));
    let (lo, _) = s.geometry().object_bounds(1);
    assert!(lo.abs_diff_eq(DVec3::new(18.0, -2.0, 0.0), 1e-6));
    let (lo, hi) = s.geometry().object_bounds(3);
    assert!(
        lo.abs_diff_eq(DVec3::new(0.0, 20.0, 0.0), 1e-6)
            && hi.abs_diff_eq(DVec3::new(2.0, 22.0, 2.0), 1e-6)
    );
    assert!(s.objects().iter().take(5).all(|o| o.report.is_closed()));

    // The stripe field read on the slab's surface is the shared pattern at (x, y).
    let pat = het_estimate::pattern::Stripe::new(2.0, 45f64.to_radians());
    use het_estimate::pattern::BinaryPattern;
    for (x, y) in [(0.3, 0.1), (1.2, 0.4), (-3.0, 2.2), (7.5, -1.0)] {
        let h = s
            .geometry()
            .intersect_object(0, &Ray::new(DVec3::new(x, y, 10.0), DVec3::NEG_Z))
            .unwrap();
        let c = stripes.medium.coefficients(&h);
        assert_eq!(c.sigma_a, Rgb::splat([0.01, 0.5][pat.select(x, y)]));
        assert_eq!(c.sigma_s, Rgb::ONE);
    }

    // The UV-mapped material is fine for BSSRDF renders and for the path tracer, which reads
    // it inside the body at the nearest surface point: its mesh has texture coordinates.
    assert!(s.require_volumetric().is_ok());
    assert!(s.require_closed_translucent().is_ok());
}

/// Loads `text` as `bad.toml` in a directory holding the full scene's assets.
pub(crate) fn load_err(text: &str) -> SceneError {
    let dir = tempfile::tempdir().unwrap();
    write_assets(dir.path());
    let p = dir.path().join("bad.toml");
    std::fs::write(&p, text).unwrap();
    match Scene::load(&p) {
        Ok(_) => panic!("loaded a bad scene:\n{text}"),
        Err(e) => e,
    }
}

/// Asserts the error names bad.toml and `key`, and its cause chain contains `words` (the
/// message itself does not repeat its source, which `source()` returns).
pub(crate) fn check(e: &SceneError, key: &str, words: &[&str]) {
    let mut msg = e.to_string();
    let mut cause = std::error::Error::source(e);
    while let Some(c) = cause {
        msg = format!("{msg}: {c}");
        cause = c.source();
    }
    assert!(msg.contains("bad.toml"), "no file name in: {msg}");
    assert_eq!(e.key(), key, "{msg}");
    assert!(msg.contains(&format!("`{key}`")), "no key in: {msg}");
    for w in words {
        assert!(msg.contains(w), "`{w}` missing from: {msg}");
    }
}

/// The shared minimal scene (`tests/fixtures/minimal-scene.toml`): an index-matched
/// translucent box seen by an orthographic camera, 8 × 8 pixels at 1 spp, no light.
pub(crate) const MINIMAL: &str = include_str!("../../../../tests/fixtures/minimal-scene.toml");

#[test]
fn minimal_scene_loads_and_orthographic_camera_works() {
    let s = Scene::from_toml_str(MINIMAL, Path::new("."), "minimal.toml").unwrap();
    let r = s.camera().ray(0.5, 0.5);
    assert!(r.origin.abs_diff_eq(
        DVec3::new(-10.0 / 2.0 + 10.0 / 16.0, 5.0 - 10.0 / 16.0, 5.0),
        1e-12
    ));
    assert!(s.require_path_traceable().is_ok());
}

#[test]
fn malformed_toml() {
    let e = load_err(&MINIMAL.replace("spp = 1", "spp = = 1"));
    assert!(matches!(e, SceneError::Parse { line: Some(4), .. }), "{e}");
    assert!(e.to_string().contains("bad.toml:4"), "{e}");
}

#[test]
fn unknown_keys_and_sections() {
    let e = load_err(&MINIMAL.replace("spp = 1", "spp = 1\nwidht = 3"));
    check(&e, "render.widht", &["unknown field", "width"]);
    let e = load_err(&MINIMAL.replace("radius", "x").replace(
        "max = [1.0, 1.0, 0.0]",
        "max = [1.0, 1.0, 0.0]\nradius = 2.0",
    ));
    check(&e, "shape[0].radius", &["unknown field"]);
    let e = load_err(&format!("{MINIMAL}\n[extra]\na = 1\n"));
    check(&e, "extra", &["unknown section"]);
    let e = load_err(&MINIMAL.replace(
        "sigma_a = 0.1",
        "sigma_a = { type = \"check\", width = 1.0, values = [0.1, 0.2], angle = 3.0 }",
    ));
    check(&e, "material[0].sigma_a.angle", &["does not apply"]);
    let e = load_err(&MINIMAL.replace(
        "sigma_a = 0.1",
        "sigma_a = { type = \"stripe\", width = 1.0, values = [0.1, 0.2], colour = 3.0 }",
    ));
    check(&e, "material[0].sigma_a.colour", &["unknown field"]);
}

#[test]
fn wrong_types_and_missing_keys() {
    let e = load_err(&MINIMAL.replace("min = [-1.0, -1.0, -1.0]", "min = \"low\""));
    check(&e, "shape[0].min", &["invalid type"]);
    let e = load_err(&MINIMAL.replace(
        "sigma_a = 0.1",
        "sigma_a = { type = \"stripe\", width = \"wide\", values = [0.1, 0.2] }",
    ));
    check(&e, "material[0].sigma_a.width", &["invalid type"]);
    let e = load_err(&MINIMAL.replace("max = [1.0, 1.0, 0.0]", ""));
    check(&e, "shape[0]", &["missing field `max`"]);
    let e = load_err(&MINIMAL.replace("type = \"box\"", "type = \"cone\""));
    check(&e, "shape[0].type", &["unknown shape type", "half_space"]);
}

#[test]
fn missing_files() {
    let text = MINIMAL.replace(
        "type = \"box\"\nmaterial = \"m\"\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 0.0]",
        "type = \"obj\"\nmaterial = \"m\"\npath = \"meshes/absent.obj\"",
    );
    let e = load_err(&text);
    assert!(matches!(e, SceneError::Io { .. }));
    check(&e, "shape[0].path", &["meshes/absent.obj"]);

    // A texture used by a used material must exist.
    let text = format!(
        "{}\n[[texture]]\nname = \"t\"\npath = \"textures/absent.png\"\n",
        MINIMAL.replace(
            "sigma_a = 0.1",
            "sigma_a = { type = \"image\", texture = \"t\", size = [1.0, 1.0] }"
        )
    );
    let e = load_err(&text);
    assert!(matches!(e, SceneError::Io { .. }));
    check(&e, "texture[0].path", &["textures/absent.png"]);

    // A missing scene file names itself.
    let e = Scene::load("/nonexistent/scene.toml").unwrap_err();
    assert!(
        matches!(e, SceneError::Io { .. }) && e.to_string().contains("/nonexistent/scene.toml")
    );
}

#[test]
fn unused_textures_are_never_decoded() {
    // A corrupt texture referenced by an unused material, and a missing one referenced by
    // nothing: the scene loads.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("corrupt.png"), b"this is not a png").unwrap();
    let text = format!(
        "{MINIMAL}\n[[texture]]\nname = \"c\"\npath = \"corrupt.png\"\n[[texture]]\nname = \"gone\"\npath = \"gone.exr\"\n\
         [[material]]\nname = \"unused\"\ntype = \"translucent\"\nsigma_a = {{ type = \"image\", texture = \"c\", size = [1.0, 1.0] }}\nsigma_s = 1.0\n"
    );
    std::fs::write(dir.path().join("s.toml"), &text).unwrap();
    Scene::load(dir.path().join("s.toml")).unwrap();
    // The same corrupt texture used by the shape's material is an error naming the image.
    let used = text.replace("material = \"m\"", "material = \"unused\"");
    std::fs::write(dir.path().join("bad.toml"), &used).unwrap();
    let e = Scene::load(dir.path().join("bad.toml")).unwrap_err();
    assert!(matches!(e, SceneError::Texture { .. }), "{e}");
    check(&e, "texture[0].path", &["corrupt.png"]);
}

#[test]
fn bad_material_references_and_duplicates() {
    let e = load_err(&MINIMAL.replace("material = \"m\"", "material = \"marble\""));
    check(&e, "shape[0].material", &["unknown material `marble`"]);
    let e = load_err(&format!(
        "{MINIMAL}\n[[material]]\nname = \"m\"\ntype = \"diffuse\"\nalbedo = 0.5\n"
    ));
    check(&e, "material[1].name", &["duplicate material name"]);
    let e = load_err(&MINIMAL.replace(
        "sigma_a = 0.1",
        "sigma_a = { type = \"image\", texture = \"nope\", size = [1.0, 1.0] }",
    ));
    check(
        &e,
        "material[0].sigma_a.texture",
        &["unknown texture `nope`"],
    );
    let two = format!(
        "{MINIMAL}\n[[shape]]\ntype = \"sphere\"\nname = \"shape[0]\"\nmaterial = \"m\"\ncentre = [0.0, 0.0, 3.0]\nradius = 1.0\n"
    );
    let e = load_err(&two);
    check(&e, "shape[1].name", &["duplicate shape name"]);
}

#[test]
fn out_of_range_values() {
    let e = load_err(&MINIMAL.replace("sigma_s = 1.0", "sigma_s = 1.0\ng = 1.0"));
    check(&e, "material[0].g", &["|g| must be < 1"]);
    let e = load_err(&MINIMAL.replace("sigma_s = 1.0", "sigma_s = 1.0\ng = -1.5"));
    check(&e, "material[0].g", &["-1.5"]);
    let e = load_err(&MINIMAL.replace("sigma_s = 1.0", "sigma_s = 1.0\neta = 0.9"));
    check(&e, "material[0].eta", &["[1, 3]", "0.9"]);
    let e = load_err(&MINIMAL.replace("sigma_a = 0.1", "sigma_a = -0.1"));
    check(&e, "material[0].sigma_a", &["non-negative"]);
    let e = load_err(&MINIMAL.replace(
        "sigma_a = 0.1",
        "sigma_a = { type = \"check\", width = 1.0, values = [0.1, [0.2, -1.0, 0.0]] }",
    ));
    check(&e, "material[0].sigma_a", &["values[1]", "non-negative"]);
    let e = load_err(&MINIMAL.replace("sigma_a = 0.1", "sigma_a = nan"));
    check(&e, "material[0].sigma_a", &["NaN"]);
    let e = load_err(&MINIMAL.replace("spp = 1", "spp = 0"));
    check(&e, "render.spp", &["at least 1"]);
    let e = load_err(&MINIMAL.replace("width = 8", "width = 0"));
    check(&e, "render.width", &["at least 1"]);
    let e = load_err(&MINIMAL.replace("spp = 1", "spp = -4"));
    check(&e, "render.spp", &["invalid value"]);
    let e = load_err(&MINIMAL.replace("max = [1.0, 1.0, 0.0]", "max = [1.0, -2.0, 0.0]"));
    check(&e, "shape[0].max", &["min < max"]);
    let e = load_err(&MINIMAL.replace(
        "direction = [0.0, 0.0, -1.0]",
        "direction = [0.0, 1.0, 0.0]",
    ));
    check(&e, "camera.up", &["parallel"]);
    let e = load_err(&format!(
        "{MINIMAL}\n[[light]]\ntype = \"quad\"\ncorner = [0.0, 0.0, 0.0]\nedge_u = [1.0, 0.0, 0.0]\nedge_v = [2.0, 0.0, 0.0]\nradiance = 1.0\n"
    ));
    check(&e, "light[0].edge_v", &["parallel"]);
    let e = load_err(&format!(
        "{MINIMAL}\n[[light]]\ntype = \"point\"\nposition = [0.0, 0.0, 0.0]\nintensity = -1.0\n"
    ));
    check(&e, "light[0].intensity", &["non-negative"]);
}

#[test]
fn nan_texel_names_the_image_and_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let mut f = Film::new(3, 2);
    f.set(2, 1, Rgb::new(0.0, f64::NAN, 0.0));
    tracer::output::write_exr(&f, &dir.path().join("nan.exr")).unwrap();
    let text = format!(
        "{}\n[[texture]]\nname = \"t\"\npath = \"nan.exr\"\n",
        MINIMAL.replace(
            "sigma_a = 0.1",
            "sigma_a = { type = \"image\", texture = \"t\", size = [1.0, 1.0] }"
        )
    );
    std::fs::write(dir.path().join("bad.toml"), &text).unwrap();
    let e = Scene::load(dir.path().join("bad.toml")).unwrap_err();
    assert!(matches!(e, SceneError::Texture { .. }), "{e}");
    check(&e, "texture[0].path", &["nan.exr", "x = 2", "y = 1", "NaN"]);
}

#[test]
fn open_translucent_mesh_is_an_error_only_for_the_path_tracer() {
    let dir = tempfile::tempdir().unwrap();
    let open: String = CUBE_OBJ
        .lines()
        .filter(|l| !l.starts_with("f 2/1/6"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(dir.path().join("open.obj"), open).unwrap();
    let text = MINIMAL.replace(
        "type = \"box\"\nmaterial = \"m\"\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 0.0]",
        "type = \"obj\"\nmaterial = \"m\"\npath = \"open.obj\"",
    );
    std::fs::write(dir.path().join("bad.toml"), &text).unwrap();
    let s = Scene::load(dir.path().join("bad.toml")).unwrap();
    assert!(s.require_volumetric().is_ok());
    let e = s.require_closed_translucent().unwrap_err();
    check(&e, "shape[0]", &["open.obj", "4 boundary edges", "closed"]);
    assert!(s.require_path_traceable().is_err());
}

/// A UV-mapped field has a value inside the body (the texture at the nearest surface point)
/// on a mesh with texture coordinates: on a box (which has them) the path tracer takes it. A
/// sphere has none, and a UV-mapped material on it is refused when the scene loads, naming
/// the shape.
#[test]
fn uv_field_is_refused_only_when_used_volumetrically() {
    let dir = tempfile::tempdir().unwrap();
    write_assets(dir.path());
    let text = format!(
        "{}\n[[texture]]\nname = \"t\"\npath = \"textures/marble.png\"\n",
        MINIMAL.replace(
            "sigma_s = 1.0",
            "sigma_s = { type = \"image\", texture = \"t\", mapping = \"uv\" }"
        )
    );
    std::fs::write(dir.path().join("box.toml"), &text).unwrap();
    let s = Scene::load(dir.path().join("box.toml")).unwrap();
    assert!(
        s.require_path_traceable().is_ok(),
        "a box has texture coordinates"
    );
    let sphere = text.replace(
        "type = \"box\"\nmaterial = \"m\"\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 0.0]",
        "type = \"sphere\"\nmaterial = \"m\"\ncentre = [0.0, 0.0, 0.0]\nradius = 1.0",
    );
    assert_ne!(sphere, text, "MINIMAL's box was replaced");
    let e = load_err(&sphere);
    check(
        &e,
        "shape[0]",
        &["no texture coordinates", "mapping = \"uv\""],
    );
    let e = load_err(&text.replace("mapping = \"uv\"", "mapping = \"uv\", size = [1.0, 1.0]"));
    check(&e, "material[0].sigma_s.size", &["does not apply"]);
}

/// Without a profile asked for, a material uses the tabulated exact profile where the table
/// reaches (η ≤ 1.6) and photon beam diffusion above; a material's own profile and an explicit
/// model override it, in that order.
#[test]
fn the_default_profile_is_tabulated_where_it_applies() {
    use tracer::field::MediumField;
    use tracer::scene::Translucent;
    let medium = MediumField::new(
        Field::constant(Rgb::splat(0.01)).unwrap(),
        Field::constant(Rgb::splat(1.0)).unwrap(),
    );
    let model = |m: &Translucent, asked: Option<ProfileModel>| {
        let (family, _) = m
            .prepare_bssrdf(asked, Scattering::Multiple, "sone".parse().unwrap())
            .expect("valid material");
        family.model()
    };
    for (eta, want) in [
        (1.0, ProfileModel::Tabulated),
        (1.3, ProfileModel::Tabulated),
        (1.6, ProfileModel::Tabulated),
        (1.61, ProfileModel::Pbd),
        (2.5, ProfileModel::Pbd),
    ] {
        let mut m = Translucent::new("m", medium.clone(), 0.0, eta);
        assert_eq!(model(&m, None), want, "η {eta}");
        m.profile = Some(ProfileModel::Dipole);
        assert_eq!(
            model(&m, None),
            ProfileModel::Dipole,
            "η {eta}: own profile"
        );
        assert_eq!(
            model(&m, Some(ProfileModel::BetterDipole)),
            ProfileModel::BetterDipole,
            "η {eta}: asked"
        );
    }
}

/// `shape_correction_seed` reaches the material (the correction's own Monte Carlo seed);
/// without it the material has the default seed; given while the material turns the correction
/// off, it is an error naming the key.
#[test]
fn shape_correction_seed_is_read_and_needs_the_correction() {
    use tracer::scene::{Material, Translucent};
    let with = |keys: &str| MINIMAL.replace("sigma_s = 1.0\n", &format!("sigma_s = 1.0\n{keys}"));
    let seed_of = |text: &str| {
        let s = Scene::from_toml_str(text, Path::new("."), "s.toml").unwrap();
        match &s.objects()[0].material {
            Material::Translucent(t) => (t.shape_correction, t.correction_seed),
            other => panic!("not translucent: {other:?}"),
        }
    };
    assert_eq!(
        seed_of(&with(
            "shape_correction = true\nshape_correction_seed = 7\n"
        )),
        (Some(true), 7)
    );
    assert_eq!(
        seed_of(&with("shape_correction = true\n")),
        (Some(true), Translucent::DEFAULT_CORRECTION_SEED)
    );
    // Without the key the render decides (`--shape-correction auto` corrects small objects):
    // a seed is meaningful.
    assert_eq!(seed_of(&with("shape_correction_seed = 7\n")), (None, 7));
    let e = load_err(&with(
        "shape_correction = false\nshape_correction_seed = 7\n",
    ));
    check(
        &e,
        "material[0].shape_correction_seed",
        &["shape_correction = false"],
    );
}
