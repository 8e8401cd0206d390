//! What a new user runs into (issue 16), through the built binary: opaque objects inside a
//! translucent volume, overlapping media, the background of a chromatic-medium scene, warnings
//! for lights the path tracer cannot reach and for scenes with nothing to render, `--out`
//! names, reproducible EXR bytes, and flags that do not apply.

mod common;

use common::{MINIMAL, Scratch, edit};
use tracer::film::Film;
use tracer::output::read_exr;

/// An orthographic camera looking down −z at a `size` × `size` window, and a uniform
/// environment of radiance 1.
fn header(pixels: u32, spp: u32, size: f64) -> String {
    view(pixels, spp, size) + "\n[[light]]\ntype = \"environment\"\nradiance = 1.0\n"
}

/// `[render]` and an orthographic camera looking down −z at a `size` × `size` window.
fn view(pixels: u32, spp: u32, size: f64) -> String {
    format!(
        r#"[render]
width = {pixels}
height = {pixels}
spp = {spp}
seed = 3

[camera]
type = "orthographic"
centre = [0.0, 0.0, 5.0]
direction = [0.0, 0.0, -1.0]
up = [0.0, 1.0, 0.0]
width = {size}
height = {size}
"#
    )
}

/// A diffuse box of albedo 0.3 (top face at z = 0.5, upper x bound `x_max`) inside an almost
/// clear, index-matched sphere of radius 2, seen from above over [x0 ± 0.4] × [±0.4].
fn core_in_clear_sphere(x0: f64, x_max: f64) -> String {
    let view = header(16, 16, 0.8);
    let view = edit(&view, "[0.0, 0.0, 5.0]", &format!("[{x0}, 0.0, 5.0]"));
    view + &format!(
        r#"
[[material]]
name = "clear"
type = "translucent"
sigma_a = 0.0
sigma_s = 1e-4

[[material]]
name = "grey"
type = "diffuse"
albedo = 0.3

[[shape]]
type = "sphere"
name = "shell"
material = "clear"
centre = [0.0, 0.0, 0.0]
radius = 2.0
subdivisions = 3

[[shape]]
type = "box"
name = "core"
material = "grey"
min = [-0.5, -0.5, -0.5]
max = [{x_max}, 0.5, 0.5]
"#
    )
}

/// Mean and standard error of the per-pixel values of channel 0 (pixels are independent
/// estimates of the same radiance).
fn mean_and_se(film: &Film) -> (f64, f64) {
    let v: Vec<f64> = film.pixels.iter().map(|p| p[0]).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

fn render_ok(s: &Scratch, scene: &str, out: &str, extra: &[&str]) -> (Film, String) {
    let mut args = vec!["render", scene, "--method", "pt", "--out", out];
    args.extend_from_slice(extra);
    let r = s.run(&args);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    (read_exr(&s.join(out)).unwrap(), r.stderr)
}

/// The repro of the issue: under a uniform environment of 1 a convex Lambertian surface of
/// albedo 0.3 has radiance 0.3 (its irradiance is π); the medium (σa = 0, σs = 1e-4) changes
/// that by O(1e-4), far below the noise. The camera sees only the box's top face, so every
/// pixel estimates 0.3: the mean must lie within 4 standard errors. In the second scene the box
/// pokes out of the sphere (an object sunk into the medium) and the view straddles the sphere's
/// boundary (at x ≈ 1.9 on the top face): seen through the medium or directly, it is the same.
#[test]
fn a_diffuse_core_inside_a_clear_medium_renders_its_albedo() {
    let s = Scratch::new();
    for (name, x0, x_max) in [("inside", 0.0, 0.5), ("crossing", 1.9, 3.0)] {
        let scene = format!("{name}.toml");
        s.write(&scene, core_in_clear_sphere(x0, x_max));
        // Light reaching the camera off the core has scattered 0 times in the medium: count
        // every order.
        let (film, _) = render_ok(&s, &scene, &format!("{name}.exr"), &["--scattering", "all"]);
        let (mean, se) = mean_and_se(&film);
        assert!(se < 0.01, "{name}: too noisy to test (se {se})");
        assert!(
            (mean - 0.3).abs() < 4.0 * se,
            "{name}: mean {mean} ± {se}, expected 0.3"
        );
    }
}

#[test]
fn overlapping_translucent_objects_are_refused_naming_both() {
    let s = Scratch::new();
    let two = MINIMAL.to_string()
        + r#"
[[shape]]
type = "sphere"
name = "second"
material = "m"
centre = [0.5, 0.5, 0.0]
radius = 0.8
subdivisions = 2
"#;
    let two = edit(
        &two,
        "type = \"box\"\n",
        "type = \"box\"\nname = \"first\"\n",
    );
    s.write("bad.toml", &two);
    s.assert_rejected(
        &["render", "bad.toml", "--out", "out.exr"],
        1,
        &["bad.toml", "`first`", "`second`", "overlap"],
    );
    // Nested without touching: refused too.
    let nested = edit(&two, "radius = 0.8", "radius = 0.2");
    let nested = edit(&nested, "[0.5, 0.5, 0.0]", "[0.0, 0.0, -0.5]");
    s.write("nested.toml", &nested);
    s.assert_rejected(
        &["render", "nested.toml", "--out", "out.exr"],
        1,
        &["`first`", "`second`", "overlap"],
    );
}

/// A chromatic sphere in the middle of the view: camera rays that miss it see the
/// environment of 1 directly, so their pixels must be exactly 1 in every channel.
#[test]
fn the_background_of_a_chromatic_medium_scene_has_no_variance() {
    let s = Scratch::new();
    let scene = header(16, 4, 4.0)
        + r#"
[[material]]
name = "jade"
type = "translucent"
sigma_a = [0.1, 0.5, 2.0]
sigma_s = 1.0

[[shape]]
type = "sphere"
name = "ball"
material = "jade"
centre = [0.0, 0.0, 0.0]
radius = 1.0
subdivisions = 3
"#;
    s.write("jade.toml", scene);
    let (film, _) = render_ok(&s, "jade.toml", "jade.exr", &[]);
    let mut background = 0;
    let mut ball = Vec::new();
    for y in 0..film.height {
        for x in 0..film.width {
            // Pixel centre in scene units; pixels more than 1.3 from the axis miss the ball.
            let px = -2.0 + (x as f64 + 0.5) * 0.25;
            let py = 2.0 - (y as f64 + 0.5) * 0.25;
            let v = film.get(x, y);
            if px.hypot(py) > 1.3 {
                background += 1;
                assert_eq!(v.0, [1.0; 3], "background pixel ({x}, {y})");
            } else if px.hypot(py) < 0.7 {
                ball.push(v);
            }
        }
    }
    assert!(background > 100);
    // The ball itself is still traced one channel at a time, and absorbs more in blue.
    let mean = ball
        .iter()
        .fold([0.0; 3], |a, v| [a[0] + v[0], a[1] + v[1], a[2] + v[2]]);
    assert!(mean[0] > mean[2], "{mean:?}");
}

#[test]
fn refractive_objects_warn_for_each_delta_light_with_its_share_of_the_power() {
    let s = Scratch::new();
    let scene = edit(MINIMAL, "sigma_s = 1.0", "sigma_s = 1.0\neta = 1.3");
    let scene = edit(
        &scene,
        "type = \"box\"\n",
        "type = \"box\"\nname = \"ball\"\n",
    );
    let scene = scene + "\n[[light]]\ntype = \"environment\"\nradiance = 0.001\n";
    s.write("refr.toml", &scene);
    let r = s.run(&["render", "refr.toml", "--method", "pt", "--out", "refr.exr"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    // Power: directional E·πR², environment L·4π²R² (R the scene's bounding radius), so the
    // directional light carries 1 / (1 + 0.004π) = 98.759 % of it.
    assert!(
        r.stderr.contains("light[0]") && r.stderr.contains("`ball`"),
        "{}",
        r.stderr
    );
    assert!(r.stderr.contains("98.759 %"), "{}", r.stderr);
    assert!(!r.stderr.contains("light[1]"), "{}", r.stderr);
}

#[test]
fn scenes_with_nothing_to_render_warn() {
    let s = Scratch::new();
    let light =
        "[[light]]\ntype = \"directional\"\ndirection = [0.0, 0.0, -1.0]\nirradiance = 1.0\n";
    let beam = "[[light]]\ntype = \"beam\"\norigin = [0.0, 0.0, 2.0]\ndirection = [0.0, 0.0, -1.0]\npower = 1.0\n";
    let shape = "[[shape]]\ntype = \"box\"\nmaterial = \"m\"\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 0.0]\n";
    for (name, scene, needle) in [
        ("dark", edit(MINIMAL, light, ""), "no lights"),
        ("beam", edit(MINIMAL, light, beam), "only lights are beams"),
        ("empty", edit(MINIMAL, shape, ""), "no shapes"),
    ] {
        let file = format!("{name}.toml");
        s.write(&file, &scene);
        for method in ["pt", "sone"] {
            let out = format!("{name}-{method}.exr");
            let r = s.run(&["render", &file, "--method", method, "--out", &out]);
            assert_eq!(r.code, Some(0), "{name}: {}", r.stderr);
            assert!(r.stderr.contains(needle), "{name}, {method}: {}", r.stderr);
        }
    }
}

#[test]
fn out_must_name_an_exr() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    for out in ["x.png", "x.json", "x"] {
        s.assert_rejected(&["render", "ok.toml", "--out", out], 2, &["--out", ".exr"]);
        s.assert_rejected(
            &[
                "beam",
                "--method",
                "endpoints",
                "--resolution",
                "4",
                "--out",
                out,
            ],
            2,
            &["--out", ".exr"],
        );
    }
}

/// The EXR header declares INCREASING_Y line order (value 0 of `lineOrder`), and the file's
/// bytes do not depend on the thread count.
#[test]
fn exr_bytes_do_not_depend_on_the_thread_count() {
    let s = Scratch::new();
    let scene = edit(
        MINIMAL,
        "width = 8\nheight = 8",
        "width = 160\nheight = 120",
    );
    let scene = edit(&scene, "height = 10.0", "height = 7.5");
    s.write("wide.toml", scene);
    let mut files = Vec::new();
    for threads in ["1", "2"] {
        let out = s.join(&format!("t{threads}.exr"));
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
            .args(["render", "wide.toml", "--method", "sone", "--spp", "1"])
            .arg("--out")
            .arg(&out)
            .env("RAYON_NUM_THREADS", threads)
            .current_dir(s.path())
            .status()
            .unwrap();
        assert!(status.success());
        files.push(std::fs::read(out).unwrap());
    }
    let key = b"lineOrder\0lineOrder\0\x01\0\0\0";
    let at = files[0]
        .windows(key.len())
        .position(|w| w == key)
        .expect("lineOrder attribute");
    assert_eq!(
        files[0][at + key.len()],
        0,
        "line order is not INCREASING_Y"
    );
    assert!(
        files[0] == files[1],
        "EXR bytes differ between 1 and 2 threads"
    );
}

#[test]
fn converge_on_a_scene_takes_scattering_and_max_depth() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    let r = s.run(&[
        "converge",
        "ok.toml",
        "--methods",
        "pt",
        "--scattering",
        "single",
        "--max-depth",
        "5",
        "--reference-spp",
        "2",
        "--max-spp",
        "1",
        "--out",
        "study",
    ]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.join("study/pt.json")).unwrap()).unwrap();
    assert_eq!(json["scattering"], "single");
    assert_eq!(json["max_depth"], 5);
}

#[test]
fn flags_that_do_not_apply_are_refused() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    let converge = |extra: &[&str]| {
        let mut a = vec!["converge", "ok.toml", "--out", "study", "--max-spp", "1"];
        a.extend_from_slice(extra);
        a.iter().map(|x| x.to_string()).collect::<Vec<_>>()
    };
    let cases: Vec<(Vec<String>, &str)> = vec![
        (converge(&["--sigma-s", "2"]), "--sigma-s"),
        (converge(&["--preset", "stripe"]), "--preset"),
        (converge(&["--min-radius", "2"]), "--min-radius"),
        (
            converge(&["--methods", "pt", "--profile", "pbd"]),
            "--profile",
        ),
        (
            converge(&["--methods", "pt,jensen-out", "--estimator-samples", "4"]),
            "--estimator-samples",
        ),
        (
            ["converge", "--beam", "--max-spp", "2", "--out", "study"]
                .map(String::from)
                .to_vec(),
            "--max-spp",
        ),
    ];
    for (args, needle) in &cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        s.assert_rejected(&args, 1, &[needle, "does not apply"]);
    }
    let render = ["render", "ok.toml", "--out", "out.exr", "--method"];
    s.assert_rejected(
        &[&render[..], &["pt", "--profile", "pbd"]].concat(),
        1,
        &["--profile"],
    );
    s.assert_rejected(
        &[&render[..], &["endpoints", "--estimator-samples", "3"]].concat(),
        1,
        &["--estimator-samples"],
    );
    let beam = ["beam", "--resolution", "4", "--out", "b.exr", "--method"];
    s.assert_rejected(
        &[&beam[..], &["pt", "--profile", "pbd"]].concat(),
        1,
        &["--profile"],
    );
    s.assert_rejected(
        &[&beam[..], &["jensen-out", "--estimator-samples", "3"]].concat(),
        1,
        &["--estimator-samples"],
    );
}

/// A diffuse floor (albedo 0.5) seen directly, lit by a directional light (irradiance 1 at
/// 45°) through a purely absorbing chromatic slab: every light path crosses the slab over a
/// length √2, so each pixel is exactly (0.5/π)·cos 45°·exp(−σa·√2) per channel (delta light,
/// exact transmittance of a constant medium). The camera paths never enter the medium, so they
/// stay RGB and their shadow rays must carry each channel's own transmittance. Tolerance: ray
/// origins are moved off surfaces by about 4e-6 × the scene's scale (10 here), which changes
/// the length inside the slab by ~1e-4 and the transmittance by up to σa × that. The light
/// crosses the medium without scattering, so it counts only with `--scattering all` (the
/// default; under `multiple` both strategies drop it alike).
#[test]
fn rgb_shadow_rays_through_a_chromatic_medium_are_exact_per_channel() {
    let s = Scratch::new();
    let scene = view(8, 2, 0.8)
        + r#"
[[material]]
name = "filter"
type = "translucent"
sigma_a = [0.1, 0.5, 1.0]
sigma_s = 0.0

[[material]]
name = "floor"
type = "diffuse"
albedo = 0.5

[[light]]
type = "directional"
direction = [-0.70710678118654752, 0.0, -0.70710678118654752]
irradiance = 1.0

[[shape]]
type = "box"
material = "floor"
min = [-5.0, -5.0, -1.0]
max = [5.0, 5.0, 0.0]

[[shape]]
type = "box"
material = "filter"
min = [0.5, -5.0, 1.0]
max = [3.0, 5.0, 2.0]
"#;
    s.write("filter.toml", &scene);
    let (film, _) = render_ok(&s, "filter.toml", "filter.exr", &["--scattering", "all"]);
    let sigma_a = [0.1, 0.5, 1.0];
    for p in &film.pixels {
        for c in 0..3 {
            let expected = 0.5 / std::f64::consts::PI
                * std::f64::consts::FRAC_1_SQRT_2
                * (-sigma_a[c] * std::f64::consts::SQRT_2).exp();
            assert!(
                (p[c] - expected).abs() < 1e-3 * expected,
                "channel {c}: {} vs {expected}",
                p[c]
            );
        }
    }
}

/// The BSSRDF methods do not see an opaque core: they say so.
#[test]
fn bssrdf_renders_warn_about_an_opaque_core() {
    let s = Scratch::new();
    s.write("core.toml", core_in_clear_sphere(0.0, 0.5));
    let r = s.run(&[
        "render",
        "core.toml",
        "--method",
        "sone",
        "--spp",
        "1",
        "--out",
        "c.exr",
    ]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(
        r.stderr.contains("`core`") && r.stderr.contains("`shell`") && r.stderr.contains("BSSRDF"),
        "{}",
        r.stderr
    );
}

/// A translucent object thinner than a few diffusion lengths gets a warning with BSSRDF
/// methods (the half-space assumption): one line in the terminal naming the object and the
/// fix, the full text with `--verbose` and in the sidecar; a large one and the path tracer
/// get none. MINIMAL's box is 1 thick with 1/σtr = 1/√(3 · 0.1 · 1.1) = 1.741.
#[test]
fn small_translucent_objects_warn_with_bssrdf_methods() {
    let s = Scratch::new();
    s.write("small.toml", MINIMAL);
    s.write(
        "large.toml",
        edit(
            MINIMAL,
            "min = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 0.0]",
            "min = [-100.0, -100.0, -100.0]\nmax = [100.0, 100.0, 0.0]",
        ),
    );
    let r = s.run(&["render", "small.toml", "--method", "sone", "--out", "s.exr"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let line = r
        .stderr
        .lines()
        .find(|l| l.starts_with("warning:") && l.contains("diffusion lengths"))
        .unwrap_or_else(|| panic!("no warning line: {}", r.stderr));
    assert!(
        line.contains("`shape[0]`") && line.contains("--method auto") && !line.contains("1/σtr"),
        "{line}"
    );
    assert!(
        r.stderr.contains("s.json, or run with --verbose"),
        "{}",
        r.stderr
    );
    let verbose = s.run(&[
        "render",
        "small.toml",
        "--method",
        "sone",
        "--verbose",
        "--out",
        "v.exr",
    ]);
    assert!(
        verbose.stderr.contains("1/σtr = 1.741")
            && verbose.stderr.contains("`shape_correction = true`"),
        "{}",
        verbose.stderr
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(s.join("s.json")).unwrap()).unwrap();
    assert!(
        json["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains("1/σtr = 1.741")),
        "{json}"
    );
    for (scene, method) in [("large.toml", "sone"), ("small.toml", "pt")] {
        let r = s.run(&["render", scene, "--method", method, "--out", "o.exr"]);
        assert_eq!(r.code, Some(0), "{}", r.stderr);
        assert!(
            !r.stderr.contains("diffusion lengths"),
            "{scene} {method}: {}",
            r.stderr
        );
    }
    // The warning points at the shape correction; with it on, the warning says so and the
    // render notes what measuring it took.
    assert!(line.contains("--shape-correction on"), "{line}");
    s.write(
        "corrected.toml",
        edit(
            MINIMAL,
            "sigma_s = 1.0\n",
            "sigma_s = 1.0\nshape_correction = true\n",
        ),
    );
    let r = s.run(&[
        "render",
        "corrected.toml",
        "--method",
        "sone",
        "--out",
        "c.exr",
    ]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(
        r.stderr.contains("the shape correction scales the BSSRDF")
            && r.stderr.contains("note: shape correction of `")
            && !r.stderr.contains("--shape-correction on"),
        "{}",
        r.stderr
    );
    // The sidecar keeps the note and the preparation's time, apart from the sampling time.
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(s.join("c.json")).unwrap()).unwrap();
    assert!(
        json["notes"][0]
            .as_str()
            .is_some_and(|n| n.starts_with("shape correction of `"))
            && json["prepare_seconds"].as_f64().is_some_and(|t| t > 0.0),
        "{json}"
    );
}

/// Every example scene (the README points at them) loads and renders with the path tracer and with
/// Sone (1 spp), to a finite image that is not black. A scene whose mesh is downloaded by a
/// script (`if_missing`: the bunny) fails, while the mesh is missing, with an error that names
/// the script; it is then rendered with the shared assets' copy of the mesh beside the
/// repository, when there is one.
#[test]
fn example_scenes_render() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let s = Scratch::new();
    let mut rendered = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let mut path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let mut text = std::fs::read_to_string(&path).unwrap();
        if text.contains("if_missing") && !dir.join("../models/bunny.obj").is_file() {
            assert!(text.contains("../models/bunny.obj"), "{}", path.display());
            let r = s.run(&[
                "render",
                path.to_str().unwrap(),
                "--spp",
                "1",
                "--out",
                "b.exr",
            ]);
            assert_eq!(r.code, Some(1), "{}: {}", path.display(), r.stderr);
            assert!(
                r.stderr.contains("sh scripts/fetch-bunny.sh")
                    && r.stderr.contains("shape[0].path"),
                "{}",
                r.stderr
            );
            let shared = dir.join("../../../shared/assets/bunny.obj");
            if !shared.is_file() {
                continue;
            }
            text = text.replace("../models/bunny.obj", shared.to_str().unwrap());
            path = s.write("bunny-shared.toml", &text);
        }
        // Every scene, the UV-painted ones included: the path tracer reads a UV-mapped medium
        // inside the body at the nearest surface point.
        let methods: &[&str] = &["pt", "sone"];
        for &method in methods {
            let out = format!(
                "{}-{method}.exr",
                path.file_stem().unwrap().to_string_lossy()
            );
            let r = s.run(&[
                "render",
                path.to_str().unwrap(),
                "--method",
                method,
                "--spp",
                "1",
                "--out",
                &out,
            ]);
            assert_eq!(r.code, Some(0), "{}: {}", path.display(), r.stderr);
            let json: serde_json::Value = serde_json::from_slice(
                &std::fs::read(s.join(&out.replace(".exr", ".json"))).unwrap(),
            )
            .unwrap();
            let mean: Vec<f64> = json["mean_rgb"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            assert!(
                mean.iter().all(|m| m.is_finite()) && mean.iter().any(|&m| m > 0.0),
                "{} {method}: mean {mean:?}",
                path.display()
            );
        }
        rendered += 1;
    }
    assert!(rendered >= 4, "only {rendered} example scenes rendered");
}

/// The glTF of a cube [−1, 1]³ (8 `f32` positions, then 36 `u16` indices in `cube.bin`)
/// whose one material is a clear absorbing dielectric as Khronos' DragonAttenuation writes it:
/// `KHR_materials_transmission` + `KHR_materials_volume` (thickness, attenuation distance 1,
/// attenuation colour `c`) + `KHR_materials_ior` 1.5, and no scattering extension.
fn absorbing_cube_gltf(s: &Scratch, c: [f64; 3]) {
    let mut bin = Vec::new();
    for i in 0..8u32 {
        for axis in 0..3 {
            let v: f32 = if i >> axis & 1 == 1 { 1.0 } else { -1.0 };
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    // Two triangles per face, each face's corners as bit patterns of (x, y, z).
    let faces: [[u16; 4]; 6] = [
        [0, 2, 6, 4], // x = −1
        [1, 5, 7, 3], // x = +1
        [0, 4, 5, 1], // y = −1
        [2, 3, 7, 6], // y = +1
        [0, 1, 3, 2], // z = −1
        [4, 6, 7, 5], // z = +1
    ];
    for [a, b, c, d] in faces {
        for i in [a, b, c, a, c, d] {
            bin.extend_from_slice(&i.to_le_bytes());
        }
    }
    assert_eq!(bin.len(), 96 + 72);
    s.write("cube.bin", &bin);
    s.write(
        "cube.gltf",
        format!(
            r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_ior"],
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "materials": [{{
    "name": "glass",
    "pbrMetallicRoughness": {{"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0}},
    "extensions": {{
      "KHR_materials_transmission": {{"transmissionFactor": 1}},
      "KHR_materials_volume": {{"thicknessFactor": 2, "attenuationDistance": 1,
                                "attenuationColor": [{}, {}, {}]}},
      "KHR_materials_ior": {{"ior": 1.5}}
    }}
  }}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}}],
  "buffers": [{{"uri": "cube.bin", "byteLength": 168}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 96}},
    {{"buffer": 0, "byteOffset": 96, "byteLength": 72}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
      "min": [-1, -1, -1], "max": [1, 1, 1]}},
    {{"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}}
  ]
}}"#,
            c[0], c[1], c[2]
        ),
    );
}

/// A glTF volume that transmits and absorbs but does not scatter is a clear absorbing
/// dielectric under every method: the default (`auto`) and the BSSRDF estimators path-trace
/// it, instead of rendering it black, and say so without a warning. Seen straight down
/// through the cube (2 thick, σa = −ln c per unit) under a uniform sky of 1, every path stays
/// vertical, and a pixel is the slab's reflectance plus its transmittance with Fresnel
/// reflectance R = ((η − 1)/(η + 1))² at both faces and every internal bounce:
/// R + (1 − R)² (t + R t²)/(1 − R² t²), t = c² (pbrt-v4 §4.5 / Beer–Lambert). Each channel's
/// mean over the 64 pixels lies within 4 standard errors of that.
#[test]
fn gltf_absorbing_volumes_are_clear_dielectrics_under_every_method() {
    let s = Scratch::new();
    let c = [0.8, 0.5, 0.2];
    absorbing_cube_gltf(&s, c);
    let scene = edit(
        &view(8, 256, 1.0),
        "seed = 3\n",
        "seed = 3\nmax_depth = 16\n",
    ) + r#"
[[light]]
type = "environment"
radiance = 1.0

[[shape]]
type = "gltf"
name = "cube"
path = "cube.gltf"
"#;
    s.write("glass.toml", &scene);
    let r_fresnel: f64 = (0.5f64 / 2.5).powi(2);
    let expected = c.map(|c| {
        let t = c * c;
        r_fresnel
            + (1.0 - r_fresnel).powi(2) * (t + r_fresnel * t * t) / (1.0 - (r_fresnel * t).powi(2))
    });
    for method in ["auto", "sone", "jensen-out", "pt"] {
        let out = format!("glass-{method}.exr");
        let r = s.run(&["render", "glass.toml", "--method", method, "--out", &out]);
        assert_eq!(r.code, Some(0), "{method}: {}", r.stderr);
        assert!(!r.stderr.contains("warning"), "{method}: {}", r.stderr);
        if method != "pt" {
            assert!(
                r.stderr.contains("does not scatter") && r.stderr.contains("`cube/glass`"),
                "{method}: {}",
                r.stderr
            );
        }
        let film = read_exr(&s.join(&out)).unwrap();
        for (ch, want) in expected.iter().enumerate() {
            let v: Vec<f64> = film.pixels.iter().map(|p| p[ch]).collect();
            let n = v.len() as f64;
            let mean = v.iter().sum::<f64>() / n;
            let se = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
            assert!(
                (mean - want).abs() < 4.0 * se + 1e-6,
                "{method}, channel {ch}: {mean} ± {se}, closed form {want}"
            );
        }
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(s.join(&out.replace(".exr", ".json"))).unwrap())
                .unwrap();
        assert_eq!(json["objects"][0]["rendered_by"], "pt", "{method}: {json}");
        assert_eq!(json["objects"][0]["clear_medium"], true, "{method}: {json}");
    }
}
