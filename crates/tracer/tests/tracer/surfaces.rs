//! Scene keys of image-based lighting and rough surfaces (docs/lighting-and-surfaces.md): an
//! environment map read from a Radiance `.hdr` or an EXR file with its `scale`, `rotation` and
//! `up`; the `roughness` of translucent and diffuse materials and the textured `albedo` of
//! diffuse ones; and the errors that name the file and the key for bad input.

use std::path::Path;

use bssrdf_core::Rgb;
use glam::DVec3;
use tracer::error::SceneError;
use tracer::field::Field;
use tracer::film::Film;
use tracer::light::Light;
use tracer::scene::{Material, Scene};

use crate::scene::{MINIMAL, check, load_err};

/// Writes a Radiance RGBE image (new-style run-length scanlines, every byte as a literal
/// dump, no runs) of `w × h` texels (row 0 at the top) given by `f`.
pub fn write_hdr(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 3]) {
    let mut out = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes();
    for y in 0..h {
        let rgbe: Vec<[u8; 4]> = (0..w)
            .map(|x| {
                let c = f(x, y);
                let v = c[0].max(c[1]).max(c[2]);
                if v < 1e-32 {
                    return [0; 4];
                }
                // v = m · 2^e with m in [0.5, 1).
                let e = v.log2().floor() as i32 + 1;
                let scale = 256.0 / 2f32.powi(e);
                [
                    (c[0] * scale) as u8,
                    (c[1] * scale) as u8,
                    (c[2] * scale) as u8,
                    (e + 128) as u8,
                ]
            })
            .collect();
        out.extend([2, 2, (w >> 8) as u8, (w & 255) as u8]);
        for ch in 0..4 {
            for chunk in rgbe.chunks(128) {
                out.push(chunk.len() as u8);
                out.extend(chunk.iter().map(|p| p[ch]));
            }
        }
    }
    std::fs::write(path, out).unwrap();
}

/// MINIMAL with its lights replaced by `light` (a `[[light]]` table's body).
fn with_light(light: &str) -> String {
    format!("{MINIMAL}\n[[light]]\ntype = \"environment\"\n{light}\n")
}

/// Loads `text` as `dir/scene.toml`.
fn load_in(dir: &Path, text: &str) -> Result<Scene, SceneError> {
    let p = dir.join("bad.toml");
    std::fs::write(&p, text).unwrap();
    Scene::load(&p)
}

/// A 16 × 8 sky: the top row (straight up) [0.5, 1, 2], the bottom row (straight down) 0.25
/// grey, the rows between blue-ish; read from `.hdr` (RGBE keeps these values exactly) with a
/// per-channel `scale`, its up axis `y` and a rotation: up reads the top row times the scale.
#[test]
fn an_hdr_environment_map_loads_with_its_keys() {
    let dir = tempfile::tempdir().unwrap();
    write_hdr(&dir.path().join("sky.hdr"), 16, 8, |_, y| match y {
        0 => [0.5, 1.0, 2.0],
        7 => [0.25; 3],
        _ => [0.125, 0.25, 0.5],
    });
    let text =
        with_light("filename = \"sky.hdr\"\nscale = [2.0, 1.0, 0.5]\nrotation = 45.0\nup = \"y\"");
    let scene = load_in(dir.path(), &text).unwrap();
    let Light::Environment(env) = &scene.lights()[0] else {
        panic!("not an environment light");
    };
    assert!(env.map.is_some());
    let up = scene.lights()[0].le(DVec3::Y);
    assert!(
        (up - Rgb::new(1.0, 1.0, 1.0)).max_component().abs() < 1e-6,
        "{up:?}"
    );
    let down = scene.lights()[0].le(DVec3::NEG_Y);
    assert!(
        (down - Rgb::new(0.5, 0.25, 0.125)).max_component().abs() < 1e-6,
        "{down:?}"
    );
    // The map is a scene input (provenance, cache keys).
    assert!(scene.input_files().iter().any(|p| p.ends_with("sky.hdr")));
}

/// Bad environment keys: each error names the scene file and the key, and for a file, the
/// file.
#[test]
fn bad_environment_maps_are_refused_with_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    write_hdr(&dir.path().join("sky.hdr"), 4, 2, |_, _| [1.0; 3]);
    // A NaN texel (EXR can hold one).
    let mut f = Film::new(2, 2);
    f.set(1, 0, Rgb::new(0.5, f64::NAN, 1.0));
    tracer::output::write_exr(&f, &dir.path().join("nan.exr")).unwrap();
    std::fs::write(dir.path().join("sky.png"), b"not an image").unwrap();
    let cases: [(&str, &str, &[&str]); 9] = [
        (
            "filename = \"missing.hdr\"",
            "light[0].filename",
            &["missing.hdr"],
        ),
        (
            "filename = \"nan.exr\"",
            "light[0].filename",
            &["nan.exr", "x = 1", "y = 0", "NaN"],
        ),
        (
            "filename = \"sky.png\"",
            "light[0].filename",
            &["sky.png", ".exr", ".hdr"],
        ),
        (
            "filename = \"sky.hdr\"\nradiance = 1.0",
            "light[0].radiance",
            &["not both"],
        ),
        (
            "filename = \"sky.hdr\"\nscale = [1.0, -1.0, 1.0]",
            "light[0].scale",
            &["non-negative"],
        ),
        (
            "filename = \"sky.hdr\"\nrotation = nan",
            "light[0].rotation",
            &["finite"],
        ),
        (
            "radiance = 1.0\nrotation = 10.0",
            "light[0].rotation",
            &["environment map"],
        ),
        ("", "light[0]", &["radiance", "filename"]),
        (
            "filename = \"sky.hdr\"\nup = \"w\"",
            "light[0].up",
            &["unknown variant"],
        ),
    ];
    for (body, key, words) in cases {
        let e = load_in(dir.path(), &with_light(body)).unwrap_err();
        check(&e, key, words);
    }
}

/// The `roughness` of translucent and diffuse materials, and a diffuse `albedo` given as a
/// field: loaded as fields; bad values named by key.
#[test]
fn roughness_and_textured_albedo_load_and_are_checked() {
    let text = format!(
        "{}\n[[material]]\nname = \"floor\"\ntype = \"diffuse\"\nroughness = 0.5\n\
         albedo = {{ type = \"check\", width = 0.5, values = [0.2, [0.9, 0.5, 0.1]] }}\n\
         [[shape]]\ntype = \"box\"\nmaterial = \"floor\"\nmin = [-3.0, -3.0, -2.0]\n\
         max = [3.0, 3.0, -1.5]\n",
        MINIMAL.replace("sigma_s = 1.0", "sigma_s = 1.0\neta = 1.4\nroughness = 0.3")
    );
    let scene = Scene::from_toml_str(&text, Path::new("."), "ok.toml").unwrap();
    let Material::Translucent(t) = &scene.objects()[0].material else {
        panic!("not translucent");
    };
    assert_eq!(t.roughness, Some(Field::Constant(Rgb::splat(0.3))));
    let Material::Diffuse(d) = &scene.objects()[1].material else {
        panic!("not diffuse");
    };
    assert_eq!(d.roughness, Some(Field::Constant(Rgb::splat(0.5))));
    assert_eq!(d.albedo.max(), Rgb::new(0.9, 0.5, 0.2));
    let bad = |from: &str, to: &str| load_err(&text.replace(from, to));
    check(
        &bad("roughness = 0.3", "roughness = -0.1"),
        "material[0].roughness",
        &["non-negative"],
    );
    check(
        &bad("roughness = 0.3", "roughness = 1.5"),
        "material[0].roughness",
        &["[0, 1]"],
    );
    check(
        &bad("roughness = 0.3", "roughness = [0.1, 0.2, 0.3]"),
        "material[0].roughness",
        &["grey"],
    );
    check(
        &bad("roughness = 0.5", "roughness = nan"),
        "material[1].roughness",
        &["non-negative"],
    );
    check(
        &bad(
            "values = [0.2, [0.9, 0.5, 0.1]]",
            "values = [0.2, [1.2, 0.5, 0.1]]",
        ),
        "material[1].albedo",
        &["[0, 1]"],
    );
}
