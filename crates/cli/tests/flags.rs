//! Command-line conventions of pbrt-v4 and Mitsuba 3 users, through the built binary: `-o`,
//! `--threads`, the possible values of `--method`, `--profile` and `--scattering` in `--help`
//! and in shell completion.

mod common;

use common::{MINIMAL, Scratch, run_in};

const METHODS: &[&str] = &[
    "pt",
    "auto",
    "jensen-in",
    "jensen-out",
    "endpoints",
    "segment",
    "sone",
    "kernel",
];
const PROFILES: &[&str] = &["dipole", "pbd", "better-dipole", "tabulated"];
const SCATTERING: &[&str] = &["multiple", "single", "all"];

#[test]
fn render_help_lists_every_method_profile_and_scattering() {
    let s = Scratch::new();
    let r = run_in(s.path(), &["render", "--help"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    for values in [METHODS, PROFILES, SCATTERING] {
        let listed = format!("[possible values: {}]", values.join(", "));
        assert!(
            r.stdout.contains(&listed),
            "`{listed}` missing from:\n{}",
            r.stdout
        );
    }
}

#[test]
fn completion_offers_the_method_names() {
    let s = Scratch::new();
    let r = run_in(s.path(), &["completions", "bash"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    for v in METHODS.iter().chain(PROFILES).chain(SCATTERING) {
        assert!(
            r.stdout.contains(v),
            "`{v}` missing from the bash completion"
        );
    }
    s.assert_rejected(&["completions", "cmd.exe"], 2, &["cmd.exe"]);
}

#[test]
fn short_out_and_threads() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    let one = s.run(&[
        "--threads",
        "1",
        "render",
        "ok.toml",
        "--method",
        "pt",
        "-o",
        "a.exr",
    ]);
    assert_eq!(one.code, Some(0), "{}", one.stderr);
    let two = s.run(&[
        "render",
        "ok.toml",
        "--method",
        "pt",
        "-o",
        "b.exr",
        "--threads",
        "2",
    ]);
    assert_eq!(two.code, Some(0), "{}", two.stderr);
    let a = tracer::output::read_exr(&s.join("a.exr")).unwrap();
    let b = tracer::output::read_exr(&s.join("b.exr")).unwrap();
    assert_eq!(a.pixels, b.pixels, "1 and 2 threads differ");
    // The sidecar names its writer and its layout's version.
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(s.join("a.json")).unwrap()).unwrap();
    assert_eq!(json["tool"]["name"], "het-bssrdf", "{json}");
    assert_eq!(json["tool"]["version"], env!("CARGO_PKG_VERSION"), "{json}");
    assert_eq!(json["schema_version"], 1, "{json}");
    // The EXR header records the render, as pbrt-v4 does.
    let meta = exr::meta::MetaData::read_from_file(s.join("a.exr"), false).unwrap();
    let attrs = &meta.headers[0].own_attributes.other;
    use exr::meta::attribute::AttributeValue as V;
    let Some(V::Text(meta)) = attrs.get(&exr::meta::attribute::Text::from("hetBssrdf")) else {
        panic!("no `hetBssrdf` metadata in the EXR header: {attrs:?}");
    };
    let meta = meta.to_string();
    for pair in [
        "samplesPerPixel=1",
        "seed=0",
        "method=pt",
        "profile=none",
        "generator=het-bssrdf",
    ] {
        assert!(meta.contains(pair), "`{pair}` missing from `{meta}`");
    }
    // The render time is in the sidecar only, so that the EXR's bytes are reproducible.
    assert!(!meta.contains("renderTime"));
    s.assert_rejected(
        &["render", "ok.toml", "--threads", "0", "-o", "c.exr"],
        2,
        &["--threads"],
    );
}

/// `render --trace light` light-traces a BSSRDF render into the same files as a camera-traced
/// one (the sidecar names the method `sone-light-traced`), and refuses what it cannot render
/// with a message naming the reason: the path tracer, a time budget, a diffuse surface.
#[test]
fn render_trace_light_writes_an_image_and_refuses_what_it_cannot_trace() {
    let s = Scratch::new();
    s.write("scene.toml", MINIMAL);
    let r = s.run(&[
        "render",
        "scene.toml",
        "--method",
        "sone",
        "--trace",
        "light",
        "--spp",
        "64",
        "-o",
        "light.exr",
    ]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(
        r.stderr.contains("sone-light-traced: 4096 light paths"),
        "{}",
        r.stderr
    );
    let film = tracer::output::read_exr(&s.join("light.exr")).unwrap();
    assert!(film.mean()[0] > 0.0);
    let json = std::fs::read_to_string(s.join("light.json")).unwrap();
    assert!(json.contains("sone-light-traced"), "{json}");
    for (extra, says) in [
        (&["--method", "pt"][..], "BSSRDF methods only"),
        (&["--time", "1"][..], "--trace light takes a sample count"),
    ] {
        let mut args = vec!["render", "scene.toml", "--trace", "light", "-o", "x.exr"];
        args.extend_from_slice(extra);
        let r = s.run(&args);
        assert_ne!(r.code, Some(0));
        assert!(r.stderr.contains(says), "{extra:?}: {}", r.stderr);
    }
    let diffuse = MINIMAL.replace(
        "type = \"translucent\"\nsigma_a = 0.1\nsigma_s = 1.0",
        "type = \"diffuse\"\nalbedo = 0.5",
    );
    assert_ne!(diffuse, MINIMAL);
    s.write("diffuse.toml", diffuse);
    let r = s.run(&["render", "diffuse.toml", "--trace", "light", "-o", "d.exr"]);
    assert_ne!(r.code, Some(0));
    assert!(r.stderr.contains("is diffuse"), "{}", r.stderr);
}
