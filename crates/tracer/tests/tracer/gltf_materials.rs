//! Reading glTF materials: the translucent-volume extensions of `examples/models/jade.gltf`
//! (written by `scripts/make_gltf_jade.py`), the split by material, the base-colour image,
//! and the errors for out-of-range values.

use std::path::PathBuf;

use tracer::field::Wrap;
use tracer::geometry::gltf::load_gltf_parts;

fn jade() -> PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/models/jade.gltf")
}

#[test]
fn jade_reads_its_volume_extensions_per_material() {
    let model = load_gltf_parts(&jade()).unwrap();
    assert_eq!(model.parts.len(), 2);
    let (jade, stand) = (&model.parts[0], &model.parts[1]);
    // The script's sphere: 16 stacks × 32 slices, two triangles a quad except at the poles.
    assert_eq!(jade.mesh.triangles.len(), 2 * 32 * 15);
    assert_eq!(stand.mesh.triangles.len(), 2);
    let m = &jade.material;
    assert_eq!(m.name, "jade");
    let v = m.volume.expect("KHR_materials_volume");
    assert_eq!(v.thickness, 1.0);
    assert!((v.attenuation_distance - 0.01).abs() < 1e-12);
    assert_eq!(v.attenuation_color, [0.5, 0.8, 0.6]);
    assert_eq!(m.diffuse_transmission.map(|d| d.factor), Some(1.0));
    assert!((m.ior - 1.3).abs() < 1e-12);
    assert!(m.volume_scatter.is_none());
    let tex = m.base_color_texture.as_ref().expect("baseColorTexture");
    // wrapS repeat, wrapT clamp: anything but clamp in both reads as repeat.
    assert_eq!(tex.wrap, Wrap::Repeat);
    // roughnessFactor is not read, but a non-default roughness is not an error either.
    assert!(m.ignored.is_empty(), "{:?}", m.ignored);
    let s = &stand.material;
    assert_eq!(s.base_color, [0.5, 0.5, 0.5]);
    assert!(s.volume.is_none() && s.base_color_texture.is_none());
}

#[test]
fn jade_base_colour_image_decodes_from_srgb() {
    let model = load_gltf_parts(&jade()).unwrap();
    let t = model.decode_image(0).unwrap();
    assert_eq!((t.width, t.height), (64, 32));
    // The script's vein formula, evaluated here independently: linear colour, then the
    // 8-bit sRGB round trip of the PNG (tolerance: half a code value, through sRGB's slope).
    let expect = |i: u32, j: u32| {
        let (u, v) = (i as f64 / 64.0, j as f64 / 32.0);
        let tau = std::f64::consts::TAU;
        let s = (tau * (2.0 * u + 0.35 * (tau * v).sin())).sin().abs();
        let t = (s / 0.25).min(1.0);
        let (green, dark) = ([0.45, 0.80, 0.55], [0.12, 0.25, 0.15]);
        [0, 1, 2].map(|k| dark[k] + (green[k] - dark[k]) * t)
    };
    for (i, j) in [(0, 0), (5, 3), (17, 20), (40, 31), (63, 16)] {
        let got = t.texel(i, j);
        let want = expect(i, j);
        for c in 0..3 {
            let tol = 0.5 / 255.0 * 12.92f64.max(1.0) * want[c].max(0.05) + 1e-3;
            assert!(
                (got[c] as f64 - want[c]).abs() < tol,
                "texel ({i}, {j}) channel {c}: {} vs {}",
                got[c],
                want[c]
            );
        }
    }
    // A missing image is an error naming the file.
    let e = model.decode_image(7).unwrap_err().to_string();
    assert!(e.contains("jade.gltf") && e.contains("image 7"), "{e}");
}

/// jade.gltf with `from` replaced by `to` (once), written to a temporary directory.
fn edited(from: &str, to: &str) -> (tempfile::TempDir, PathBuf) {
    let text = std::fs::read_to_string(jade()).unwrap();
    assert!(text.contains(from), "jade.gltf no longer contains {from:?}");
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("edited.gltf");
    std::fs::write(&p, text.replacen(from, to, 1)).unwrap();
    (dir, p)
}

#[test]
fn out_of_range_material_values_name_the_field() {
    for (from, to, field) in [
        (
            "\"attenuationDistance\": 0.01",
            "\"attenuationDistance\": -1",
            "KHR_materials_volume.attenuationDistance",
        ),
        ("\"ior\": 1.3", "\"ior\": 0.5", "KHR_materials_ior.ior"),
        (
            "\"attenuationColor\": [\n      0.5,",
            "\"attenuationColor\": [\n      1.5,",
            "KHR_materials_volume.attenuationColor",
        ),
        (
            "\"diffuseTransmissionFactor\": 1.0",
            "\"diffuseTransmissionFactor\": \"a lot\"",
            "diffuseTransmissionFactor",
        ),
    ] {
        let (_dir, p) = edited(from, to);
        let e = load_gltf_parts(&p).unwrap_err().to_string();
        assert!(
            e.contains("edited.gltf") && e.contains(field) && e.contains("jade"),
            "{field}: {e}"
        );
    }
}

#[test]
fn unread_extensions_and_textures_are_listed_and_scatter_drafts_read() {
    let (_dir, p) = edited(
        "\"KHR_materials_ior\": {",
        "\"KHR_materials_clearcoat\": {\"clearcoatFactor\": 1},
        \"KHR_materials_scatter\": {\"multiscatterColorFactor\": [0.9, 0.6, 0.3],
            \"scatterStrengthFactor\": 0.5, \"scatterAnisotropy\": 0.4,
            \"multiscatterColorTexture\": {\"index\": 0}},
        \"KHR_materials_ior\": {",
    );
    let model = load_gltf_parts(&p).unwrap();
    let m = &model.parts[0].material;
    assert!(
        m.ignored.iter().any(|s| s == "KHR_materials_clearcoat"),
        "{:?}",
        m.ignored
    );
    assert!(
        m.ignored
            .iter()
            .any(|s| s == "KHR_materials_scatter.multiscatterColorTexture"),
        "{:?}",
        m.ignored
    );
    let s = m.volume_scatter.expect("KHR_materials_scatter");
    assert_eq!(s.multiscatter_color, [0.45, 0.3, 0.15]);
    assert_eq!(s.anisotropy, 0.4);
}

#[test]
fn materials_are_interpreted_as_translucent_absorbing_or_diffuse() {
    use tracer::geometry::gltf_material::{GltfColour, GltfInterpretation};
    let model = load_gltf_parts(&jade()).unwrap();
    // jade: volume + diffuse transmission → translucent, base colour texture as its colour,
    // mean free path d / −ln(attenuationColor).
    let (jade, notes) = model.parts[0].material.interpret();
    let GltfInterpretation::Translucent {
        colour,
        mean_free_path,
        anisotropy,
        eta,
    } = jade
    else {
        panic!("jade: {jade:?}");
    };
    assert!(matches!(
        colour,
        GltfColour::Texture {
            factor: [1.0, 1.0, 1.0],
            ..
        }
    ));
    for (got, c) in mean_free_path.iter().zip([0.5f64, 0.8, 0.6]) {
        assert!((got - 0.01 / -c.ln()).abs() < 1e-12, "{mean_free_path:?}");
    }
    assert_eq!((anisotropy, eta), (0.0, 1.3));
    assert!(notes.is_empty(), "{notes:?}");
    // stand: no volume → diffuse of its base colour factor.
    let (stand, _) = model.parts[1].material.interpret();
    assert_eq!(stand, GltfInterpretation::Diffuse { albedo: [0.5; 3] });

    // Thin-walled (thickness 0) → diffuse, with a note saying why.
    let (_d, p) = edited("\"thicknessFactor\": 1.0", "\"thicknessFactor\": 0.0");
    let (m, notes) = load_gltf_parts(&p).unwrap().parts[0].material.interpret();
    assert!(matches!(m, GltfInterpretation::Diffuse { .. }), "{m:?}");
    assert!(notes.iter().any(|n| n.contains("thin-walled")), "{notes:?}");

    // Without diffuse transmission: a clear absorbing volume, σa = −ln(c)/d.
    let (_d, p) = edited(
        "\"KHR_materials_diffuse_transmission\": {",
        "\"KHR_materials_not_diffuse_transmission\": {",
    );
    let (m, notes) = load_gltf_parts(&p).unwrap().parts[0].material.interpret();
    let GltfInterpretation::Absorbing { sigma_a, eta } = m else {
        panic!("{m:?}");
    };
    assert!((sigma_a[1] - -0.8f64.ln() / 0.01).abs() < 1e-12 && eta == 1.3);
    assert!(
        notes
            .iter()
            .any(|n| n.contains("KHR_materials_not_diffuse_transmission")),
        "{notes:?}"
    );
}

/// `examples/scenes/gltf-jade.toml` with `extra` appended to its shape table, loaded from
/// the examples directory (so that its relative model path resolves).
fn jade_scene(extra: &str) -> Result<tracer::scene::Scene, tracer::error::SceneError> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let text = std::fs::read_to_string(dir.join("gltf-jade.toml")).unwrap();
    tracer::scene::Scene::from_toml_str(&format!("{text}{extra}"), &dir, "gltf-jade.toml")
}

#[test]
fn gltf_scene_takes_one_object_per_file_material() {
    use bssrdf_core::{AlbedoInversion, ProfileModel, Rgb};
    use glam::{DVec2, DVec3};
    use std::sync::Arc;
    use tracer::field::{ArtistMap, Field, Filter, ImageMapping, InvertAt, MediumField};
    use tracer::scene::Material;
    let scene = jade_scene("").unwrap();
    let names: Vec<&str> = scene.objects().iter().map(|o| o.name.as_str()).collect();
    assert!(names.starts_with(&["jade/jade", "jade/stand"]), "{names:?}");
    assert!(scene.load_notes().is_empty(), "{:?}", scene.load_notes());
    let Material::Translucent(t) = &scene.objects()[0].material else {
        panic!("jade is not translucent");
    };
    assert_eq!((t.eta, t.g), (1.3, 0.0));
    let Material::Diffuse(d) = &scene.objects()[1].material else {
        panic!("the stand is not diffuse");
    };
    assert_eq!(d.albedo, tracer::field::Field::Constant(Rgb([0.5; 3])));
    // The same medium built by hand from the file's values (docs/gltf.md): colour = the base
    // colour image through UVs, mean free path = d / −ln(attenuationColor), the default
    // profile's inversion at η 1.3.
    let model = load_gltf_parts(&jade()).unwrap();
    let image = Field::image(
        Arc::new(model.decode_image(0).unwrap()),
        ImageMapping::Uv,
        Wrap::Repeat,
        Filter::Bilinear,
        Rgb([1.0; 3]),
    )
    .unwrap();
    let mfp = Field::constant(Rgb([0.5f64, 0.8, 0.6].map(|c| 0.01 / -c.ln()))).unwrap();
    let inversion = AlbedoInversion::shared(ProfileModel::default_for(1.3), 0.0, 1.3).unwrap();
    let want =
        MediumField::artist(image, mfp, ArtistMap::new(inversion, InvertAt::DEFAULT)).unwrap();
    for (p, uv) in [
        (DVec3::new(0.0, 2.0, 0.0), DVec2::new(0.3, 0.9)),
        (DVec3::new(1.0, 1.0, 0.0), DVec2::new(0.71, 0.5)),
        (DVec3::new(0.0, 1.0, -1.0), DVec2::new(0.05, 0.25)),
    ] {
        assert_eq!(
            t.medium.at_surface(p, uv),
            want.at_surface(p, uv),
            "at uv {uv}"
        );
    }

    // A scaled shape scales the mean free path with it (a mean free path of 1/σt: twice the
    // size, half the extinction).
    let big = jade_scene("transform = { scale = 2.0 }\n").unwrap();
    let Material::Translucent(b) = &big.objects()[0].material else {
        panic!()
    };
    let uv = DVec2::new(0.3, 0.9);
    let (small, large) = (
        t.medium.at_surface(DVec3::ZERO, uv),
        b.medium.at_surface(DVec3::ZERO, uv),
    );
    for c in 0..3 {
        let (s, l) = (
            small.sigma_a[c] + small.sigma_s[c],
            large.sigma_a[c] + large.sigma_s[c],
        );
        assert!((l - 0.5 * s).abs() < 1e-12 * s, "channel {c}: {l} vs {s}");
    }

    // A `material` key covers the whole file with that material, as for OBJ.
    let one = jade_scene("material = \"plain\"\n[[material]]\nname = \"plain\"\ntype = \"diffuse\"\nalbedo = [0.2, 0.2, 0.2]\n").unwrap();
    assert_eq!(one.objects()[0].name, "jade");
    assert_eq!(
        one.objects()[0].report.triangles,
        2 * 32 * 15 + 2,
        "one object holds the whole file"
    );
}

#[test]
fn gltf_scene_warns_about_what_it_does_not_read_and_other_meshes_need_a_material() {
    use tracer::integrator::{Method, warnings::scene_warnings};
    // The scene with a clearcoat layer on the jade: the render's warnings name it.
    let text = std::fs::read_to_string(jade()).unwrap().replacen(
        "\"KHR_materials_ior\": {",
        "\"KHR_materials_clearcoat\": {\"clearcoatFactor\": 1}, \"KHR_materials_ior\": {",
        1,
    );
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("jade.gltf"), text).unwrap();
    let scene_text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/scenes/gltf-jade.toml"),
    )
    .unwrap()
    .replace("../models/jade.gltf", "jade.gltf");
    let scene =
        tracer::scene::Scene::from_toml_str(&scene_text, dir.path(), "clearcoat.toml").unwrap();
    for method in [
        Method::PathTraced,
        Method::bssrdf(het_estimate::Estimator::Sone(Default::default()), None),
    ] {
        let w = scene_warnings(&scene, method);
        assert!(
            w.iter().any(|m| m.contains("jade.gltf")
                && m.contains("`jade`")
                && m.contains("KHR_materials_clearcoat")),
            "{w:?}"
        );
    }
    // Only glTF shapes may leave out `material`.
    std::fs::write(
        dir.path().join("x.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let e = tracer::scene::Scene::from_toml_str(
        &scene_text
            .replace("type = \"gltf\"", "type = \"obj\"")
            .replace("jade.gltf", "x.obj"),
        dir.path(),
        "obj.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("shape[0].material") && e.contains("missing `material`"),
        "{e}"
    );
}
