//! Renders split across processes (issue 15): `render --tile I/N` in N separate processes and
//! `merge` give the whole render's EXR and PNG byte for byte; merges of shards that are not
//! one render's are refused, naming the files; a time-budgeted merge holds, in each shard's
//! rows, the whole render at that shard's sample count.

mod common;

use common::{MINIMAL, Scratch, edit};
use serde_json::Value;

/// [`MINIMAL`] at 10 × 7 pixels (7 rows: not a multiple of 3), 2 spp, with the camera
/// narrowed so that the box fills every row (every shard has lit pixels to get right).
fn scene() -> String {
    let s = edit(
        MINIMAL,
        "width = 8\nheight = 8\nspp = 1",
        "width = 10\nheight = 7\nspp = 2",
    );
    edit(
        &s,
        "width = 10.0\nheight = 10.0",
        "width = 2.5\nheight = 2.5",
    )
}

fn json(s: &Scratch, rel: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(s.join(rel)).unwrap()).unwrap()
}

fn bytes(s: &Scratch, rel: &str) -> Vec<u8> {
    std::fs::read(s.join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// Runs `args` in `s`, which must succeed.
#[track_caller]
fn ok(s: &Scratch, args: &[&str]) {
    let r = s.run(args);
    assert_eq!(
        r.code,
        Some(0),
        "het-bssrdf {}:\n{}",
        args.join(" "),
        r.stderr
    );
}

/// Renders the 3 shards of `method` as 3 concurrent processes (extra `args` appended), to
/// `{prefix}-{i}.exr`.
fn render_shards(s: &Scratch, method: &str, prefix: &str, args: &[&str]) {
    std::thread::scope(|scope| {
        for i in 0..3 {
            scope.spawn(move || {
                let tile = format!("{i}/3");
                let out = format!("{prefix}-{i}.exr");
                let mut a = vec!["render", "s.toml", "--method", method, "--tile", &tile];
                a.extend_from_slice(&["-o", &out]);
                a.extend_from_slice(args);
                ok(s, &a);
            });
        }
    });
}

#[test]
fn merged_shards_are_the_whole_render_byte_for_byte() {
    let s = Scratch::new();
    s.write("s.toml", scene());
    for method in ["pt", "sone"] {
        ok(
            &s,
            &[
                "render",
                "s.toml",
                "--method",
                method,
                "-o",
                &format!("full-{method}.exr"),
            ],
        );
        render_shards(&s, method, method, &[]);
        // Every shard holds its rows only, and has light in them.
        let full = tracer::output::read_exr(&s.join(&format!("full-{method}.exr"))).unwrap();
        for i in 0..3u32 {
            let part = tracer::output::read_exr(&s.join(&format!("{method}-{i}.exr"))).unwrap();
            let mut lit = false;
            for y in 0..7u32 {
                for x in 0..10u32 {
                    let (a, b) = (part.get(x, y), full.get(x, y));
                    if y % 3 == i {
                        assert_eq!(a, b, "{method}: pixel ({x}, {y}) of shard {i}");
                        lit |= a[0] > 0.0;
                    } else {
                        assert_eq!(a[0] + a[1] + a[2], 0.0, "{method}: row {y} in shard {i}");
                    }
                }
            }
            assert!(
                lit,
                "{method}: shard {i} has no lit pixel; the test scene is too dark"
            );
        }
        // Merged in another order than rendered.
        let merged = format!("merged-{method}.exr");
        let (s0, s1, s2) = (
            format!("{method}-0.exr"),
            format!("{method}-1.exr"),
            format!("{method}-2.exr"),
        );
        ok(&s, &["merge", &s2, &s0, &s1, "-o", &merged]);
        assert!(
            bytes(&s, &merged) == bytes(&s, &format!("full-{method}.exr")),
            "{method}: the merged EXR differs from the whole render's"
        );
        assert!(
            bytes(&s, &format!("merged-{method}.png")) == bytes(&s, &format!("full-{method}.png")),
            "{method}: the merged PNG differs from the whole render's"
        );
        // The sidecar sums the shards' work, which is the whole render's.
        let (m, f) = (
            json(&s, &format!("merged-{method}.json")),
            json(&s, &format!("full-{method}.json")),
        );
        for key in [
            "counters",
            "rays_traced",
            "mean_rgb",
            "spp",
            "seed",
            "method",
        ] {
            assert_eq!(m[key], f[key], "{method}: sidecar `{key}`");
        }
        assert_eq!(m["counters"]["paths"], 10 * 7 * 2);
        let merged = &m["merged"];
        assert_eq!(merged["count"], 3);
        let shards = merged["shards"].as_array().unwrap();
        let secs: Vec<f64> = shards
            .iter()
            .map(|p| p["wall_seconds"].as_f64().unwrap())
            .collect();
        let sum = merged["wall_seconds_sum"].as_f64().unwrap();
        let max = merged["wall_seconds_max"].as_f64().unwrap();
        assert!((sum - secs.iter().sum::<f64>()).abs() <= 1e-12 * sum.max(1.0));
        assert_eq!(max, secs.iter().copied().fold(0.0, f64::max));
        assert_eq!(m["wall_seconds"].as_f64(), Some(max));
    }
}

#[test]
fn merges_of_shards_of_different_renders_are_refused_naming_the_files() {
    let s = Scratch::new();
    s.write("s.toml", scene());
    render_shards(&s, "pt", "pt", &[]);
    // Shard 1 of another seed, of 2 shards, of an edited scene; a whole render.
    ok(
        &s,
        &[
            "render",
            "s.toml",
            "--method",
            "pt",
            "--tile",
            "1/3",
            "--seed",
            "99",
            "-o",
            "seed-1.exr",
        ],
    );
    ok(
        &s,
        &[
            "render",
            "s.toml",
            "--method",
            "pt",
            "--tile",
            "1/2",
            "-o",
            "two-1.exr",
        ],
    );
    ok(
        &s,
        &[
            "render",
            "s.toml",
            "--method",
            "pt",
            "--spp",
            "3",
            "--tile",
            "1/3",
            "-o",
            "spp-1.exr",
        ],
    );
    ok(
        &s,
        &[
            "render",
            "s.toml",
            "--method",
            "sone",
            "--tile",
            "1/3",
            "-o",
            "sone-1.exr",
        ],
    );
    s.write(
        "edited.toml",
        edit(&scene(), "sigma_a = 0.1", "sigma_a = 0.2"),
    );
    ok(
        &s,
        &[
            "render",
            "edited.toml",
            "--method",
            "pt",
            "--tile",
            "1/3",
            "-o",
            "edited-1.exr",
        ],
    );
    ok(
        &s,
        &["render", "s.toml", "--method", "pt", "-o", "whole.exr"],
    );
    for ext in ["exr", "png", "json"] {
        std::fs::copy(
            s.join(&format!("pt-1.{ext}")),
            s.join(&format!("dup-1.{ext}")),
        )
        .unwrap();
    }
    let merge = |inputs: &[&str], needles: &[&str]| {
        let mut args = vec!["merge"];
        args.extend_from_slice(inputs);
        args.extend_from_slice(&["-o", "m.exr"]);
        s.assert_rejected(&args, 1, needles);
    };
    merge(
        &["pt-0.exr", "seed-1.exr", "pt-2.exr"],
        &["seed-1.exr", "pt-0.exr", "seed 99 vs 0"],
    );
    merge(
        &["pt-0.exr", "two-1.exr", "pt-2.exr"],
        &["two-1.exr", "shard count N 2 vs 3"],
    );
    merge(
        &["pt-0.exr", "spp-1.exr", "pt-2.exr"],
        &["spp-1.exr", "samples per pixel 3 vs 2"],
    );
    merge(
        &["pt-0.exr", "sone-1.exr", "pt-2.exr"],
        &["sone-1.exr", "method"],
    );
    merge(
        &["pt-0.exr", "edited-1.exr", "pt-2.exr"],
        &["edited-1.exr", "scene (hash"],
    );
    merge(
        &["pt-0.exr", "pt-1.exr"],
        &["shard 2/3 missing", "pt-0.exr", "pt-1.exr"],
    );
    merge(
        &["pt-0.exr", "pt-1.exr", "dup-1.exr", "pt-2.exr"],
        &["pt-1.exr", "dup-1.exr", "both shard 1/3"],
    );
    merge(
        &["pt-0.exr", "whole.exr"],
        &["whole.exr", "not a shard", "--tile"],
    );
    merge(&["pt-0.exr", "absent.exr"], &["absent.json"]);
    // A shard whose sidecar belongs to another shard.
    std::fs::copy(s.join("pt-2.json"), s.join("dup-1.json")).unwrap();
    merge(
        &["pt-0.exr", "dup-1.exr", "pt-2.exr"],
        &["dup-1.exr", "does not match its sidecar"],
    );
    // Bad --tile values are usage errors naming the value.
    for bad in ["3/3", "1/0", "x/3", "2"] {
        s.assert_rejected(
            &["render", "s.toml", "--tile", bad, "-o", "t.exr"],
            2,
            &["--tile", bad],
        );
    }
}

#[test]
fn a_time_budgeted_merge_holds_each_shards_sample_count() {
    let s = Scratch::new();
    s.write("s.toml", scene());
    render_shards(&s, "pt", "t", &["--time", "0.05"]);
    ok(
        &s,
        &["merge", "t-0.exr", "t-1.exr", "t-2.exr", "-o", "t.exr"],
    );
    let m = json(&s, "t.json");
    assert_eq!(m["time_budget_seconds"], 0.05);
    let merged = tracer::output::read_exr(&s.join("t.exr")).unwrap();
    let shards = m["merged"]["shards"].as_array().unwrap();
    let spps: Vec<u64> = shards.iter().map(|p| p["spp"].as_u64().unwrap()).collect();
    assert_eq!(m["spp"].as_u64(), spps.iter().copied().min());
    // Each shard's rows are those of a whole render at the shard's sample count.
    for (i, spp) in spps.iter().enumerate() {
        assert_eq!(shards[i]["index"], i);
        let out = format!("fixed-{spp}.exr");
        if !s.join(&out).exists() {
            ok(
                &s,
                &[
                    "render",
                    "s.toml",
                    "--method",
                    "pt",
                    "--spp",
                    &spp.to_string(),
                    "-o",
                    &out,
                ],
            );
        }
        let fixed = tracer::output::read_exr(&s.join(&out)).unwrap();
        for y in (i as u32..7).step_by(3) {
            for x in 0..10 {
                assert_eq!(
                    merged.get(x, y),
                    fixed.get(x, y),
                    "({x}, {y}) of shard {i}, {spp} spp"
                );
            }
        }
    }
    let header = tracer::output::read_exr_metadata(&s.join("t.exr")).unwrap();
    let per_shard = header
        .iter()
        .find(|(k, _)| k == "samplesPerPixelPerShard")
        .unwrap();
    let listed: Vec<String> = spps.iter().map(u64::to_string).collect();
    assert_eq!(per_shard.1, listed.join(","));
}

/// Renders the 3 shards `s-{0,1,2}.exr` of the reproduction (`--method sone --spp 4
/// --seed 3`), then `x.exr`: shard 1 again with `extra` flags (replacing those of the same
/// name).
fn shards_and_a_stranger(s: &Scratch, extra: &[&str]) {
    let flags = ["--method", "sone", "--spp", "4", "--seed", "3"];
    std::thread::scope(|scope| {
        for i in 0..3 {
            scope.spawn(move || {
                let (tile, out) = (format!("{i}/3"), format!("s-{i}.exr"));
                let mut a = vec!["render", "s.toml", "--tile", &tile, "-o", &out];
                a.extend_from_slice(&flags);
                ok(s, &a);
            });
        }
    });
    let mut a = vec!["render", "s.toml", "--tile", "1/3", "-o", "x.exr"];
    for pair in flags.chunks(2) {
        if !extra.contains(&pair[0]) {
            a.extend_from_slice(pair);
        }
    }
    a.extend_from_slice(extra);
    ok(s, &a);
}

/// Issue 39, case 1: a shard EXR of another render beside a good sidecar (here: another spp,
/// seed, method or exposure) was merged, and the merged header claimed the sidecar's values.
/// Each EXR's own header is now checked against its sidecar.
#[test]
fn a_shard_exr_from_another_render_beside_a_good_sidecar_is_refused() {
    let s = Scratch::new();
    s.write("s.toml", scene());
    let good = bytes(&s, "s.toml");
    for (extra, needles) in [
        (
            &["--spp", "8"][..],
            &["samplesPerPixel is 8", "spp is 4"][..],
        ),
        (&["--seed", "4"], &["seed is 4", "seed is 3"]),
        (&["--method", "kernel"], &["method is kernel"]),
        (
            &["--exposure", "2"],
            &["exposure is 2", "preview_exposure is 0"],
        ),
    ] {
        shards_and_a_stranger(&s, extra);
        std::fs::copy(s.join("x.exr"), s.join("s-1.exr")).unwrap();
        let mut n = vec!["s-1.exr", "does not match its sidecar", "s-1.json"];
        n.extend_from_slice(needles);
        s.assert_rejected(
            &["merge", "s-0.exr", "s-1.exr", "s-2.exr", "-o", "m.exr"],
            1,
            &n,
        );
        assert_eq!(bytes(&s, "s.toml"), good);
    }
}

/// Issue 39, case 2: shards rendered with different `--exposure` were merged (the merged PNG
/// took the first shard's); the merge's own `--exposure` makes the choice explicit.
#[test]
fn shards_with_different_exposures_need_an_explicit_one() {
    let s = Scratch::new();
    s.write("s.toml", scene());
    shards_and_a_stranger(&s, &["--exposure", "2"]);
    for ext in ["exr", "png", "json"] {
        std::fs::copy(s.join(&format!("x.{ext}")), s.join(&format!("s-1.{ext}"))).unwrap();
    }
    s.assert_rejected(
        &["merge", "s-0.exr", "s-1.exr", "s-2.exr", "-o", "m.exr"],
        1,
        &[
            "s-1.exr",
            "s-0.exr",
            "preview exposure",
            "2.0 vs 0.0",
            "--exposure",
        ],
    );
    ok(
        &s,
        &[
            "merge",
            "s-0.exr",
            "s-1.exr",
            "s-2.exr",
            "-o",
            "m.exr",
            "--exposure",
            "1",
        ],
    );
    assert_eq!(json(&s, "m.json")["preview_exposure"], 1.0);
}

/// Issue 39, case 2: one flipped bit in a shard's pixel blocks decoded to about 4,000 pixels
/// × 65,536 and the merge succeeded. Every flip of a bit that still decodes to other pixels
/// is now refused by the pixel checksum (and one that does not decode, by the decoder).
#[test]
fn a_flipped_bit_in_a_shards_pixels_is_refused() {
    let s = Scratch::new();
    s.write("s.toml", scene());
    shards_and_a_stranger(&s, &[]);
    let original = bytes(&s, "s-1.exr");
    let pixels = tracer::output::read_exr(&s.join("s-1.exr")).unwrap().pixels;
    // Flips that still decode, to different pixels: the case the decoder cannot see.
    let mut silent = 0;
    for at in (original.len() / 2..original.len()).rev().step_by(7) {
        let mut flipped = original.clone();
        flipped[at] ^= 0x10;
        std::fs::write(s.join("s-1.exr"), &flipped).unwrap();
        let decodes_to_other_pixels =
            tracer::output::read_exr(&s.join("s-1.exr")).is_ok_and(|f| f.pixels != pixels);
        let r = s.run(&["merge", "s-0.exr", "s-1.exr", "s-2.exr", "-o", "m.exr"]);
        assert_eq!(
            r.code,
            Some(1),
            "bit flip at byte {at} merged:\n{}",
            r.stderr
        );
        assert!(!s.join("m.exr").exists());
        if decodes_to_other_pixels {
            assert!(r.stderr.contains("checksum"), "byte {at}: {}", r.stderr);
            silent += 1;
            if silent == 5 {
                break;
            }
        }
    }
    assert!(
        silent > 0,
        "no bit flip decoded to other pixels: the test tests nothing"
    );
    std::fs::write(s.join("s-1.exr"), &original).unwrap();
    ok(
        &s,
        &["merge", "s-0.exr", "s-1.exr", "s-2.exr", "-o", "m.exr"],
    );
}

/// Issue 39, case 3: a glTF model's external buffer edited between two tiles was not in the
/// scene hash, so the shards merged into a wrong image (relative L2 0.52 against the right
/// one). The buffer is now hashed with the scene.
#[test]
fn a_gltf_buffer_edited_between_tiles_is_refused() {
    let s = Scratch::new();
    s.write("tetra.bin", common::tetra_bin());
    s.write("m.gltf", common::gltf(common::NODES, 12, 72, "tetra.bin"));
    s.write("t.toml", common::with_gltf("m.gltf"));
    let tile = |i: &str| {
        ok(
            &s,
            &[
                "render",
                "t.toml",
                "--method",
                "pt",
                "--tile",
                &format!("{i}/2"),
                "-o",
                &format!("t-{i}.exr"),
            ],
        )
    };
    tile("0");
    // The same file name and length, another vertex: the tetrahedron's apex moves.
    let mut bin = common::tetra_bin();
    bin[44..48].copy_from_slice(&2f32.to_le_bytes());
    s.write("tetra.bin", bin);
    tile("1");
    s.assert_rejected(
        &["merge", "t-0.exr", "t-1.exr", "-o", "t.exr"],
        1,
        &["t-1.exr", "t-0.exr", "scene (hash of its files)"],
    );
}
