//! The `converge` reference cache, through the built binary: kept out of the scene's
//! directory, keyed on everything the render reads (a changed mesh or scene is never served a
//! stale reference, an unchanged one is reused), and moved under `--out` when the cache
//! directory cannot be written.

mod common;

use common::{CUBE_OBJ, Scratch, listing, with_obj};

/// `converge` of `scene` with one cheap method into `out`, caching in `cache`.
fn converge(s: &Scratch, scene: &str, out: &str, cache: &str) -> common::Run {
    s.run(&[
        "converge",
        scene,
        "--methods",
        "pt",
        "--reference-spp",
        "2",
        "--max-spp",
        "1",
        "--cache-dir",
        cache,
        "--out",
        out,
    ])
}

/// The cached references in `dir` of the scratch directory.
fn cached(s: &Scratch, dir: &str) -> Vec<String> {
    listing(&s.join(dir))
        .into_iter()
        .filter(|f| f.starts_with("reference-pt-") && f.ends_with(".exr"))
        .collect()
}

#[test]
fn the_cache_is_keyed_on_everything_the_render_reads() {
    let s = Scratch::new();
    s.write("scenes/cube.obj", CUBE_OBJ);
    s.write("scenes/blob.toml", with_obj("cube.obj"));
    let first = converge(&s, "scenes/blob.toml", "o1", "cache");
    assert_eq!(first.code, Some(0), "{}", first.stderr);
    assert!(first.stderr.contains("rendering the path-traced reference"));
    assert_eq!(cached(&s, "cache").len(), 1);
    assert_eq!(
        listing(&s.join("scenes")),
        ["blob.toml", "cube.obj"],
        "the cache landed beside the scene"
    );

    // Nothing changed: the reference is reused.
    let again = converge(&s, "scenes/blob.toml", "o2", "cache");
    assert_eq!(again.code, Some(0), "{}", again.stderr);
    assert!(
        !again.stderr.contains("rendering the path-traced reference"),
        "{}",
        again.stderr
    );
    assert_eq!(cached(&s, "cache").len(), 1);

    // The mesh changes (same file name, same scene text): a new reference.
    s.write("scenes/cube.obj", CUBE_OBJ.replace("v 1 1 1", "v 1 1 1.5"));
    let mesh = converge(&s, "scenes/blob.toml", "o3", "cache");
    assert_eq!(mesh.code, Some(0), "{}", mesh.stderr);
    assert!(mesh.stderr.contains("rendering the path-traced reference"));
    assert_eq!(cached(&s, "cache").len(), 2);

    // The scene changes (max_depth): a new reference.
    s.write(
        "scenes/blob.toml",
        common::edit(&with_obj("cube.obj"), "spp = 1", "spp = 1\nmax_depth = 3"),
    );
    let depth = converge(&s, "scenes/blob.toml", "o4", "cache");
    assert_eq!(depth.code, Some(0), "{}", depth.stderr);
    assert_eq!(cached(&s, "cache").len(), 3);
}

#[test]
fn an_unwritable_cache_falls_back_to_the_output_directory() {
    let s = Scratch::new();
    s.write("cube.obj", CUBE_OBJ);
    s.write("blob.toml", with_obj("cube.obj"));
    // A regular file where the cache directory should be: it cannot be created.
    s.write("not-a-dir", "x");
    let r = converge(&s, "blob.toml", "out", "not-a-dir/cache");
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(r.stderr.contains("cannot be written"), "{}", r.stderr);
    assert_eq!(cached(&s, "out").len(), 1, "{:?}", listing(s.path()));
}

/// Issue 39, case 3: a glTF model's external buffer edited between two `converge` runs was not
/// in the cache key, and the stale reference was reused.
#[test]
fn the_cache_key_covers_a_gltf_models_buffers() {
    let s = Scratch::new();
    s.write("scenes/tetra.bin", common::tetra_bin());
    s.write(
        "scenes/m.gltf",
        common::gltf(common::NODES, 12, 72, "tetra.bin"),
    );
    s.write("scenes/t.toml", common::with_gltf("m.gltf"));
    let first = converge(&s, "scenes/t.toml", "o1", "cache");
    assert_eq!(first.code, Some(0), "{}", first.stderr);
    assert_eq!(cached(&s, "cache").len(), 1);
    let mut bin = common::tetra_bin();
    bin[44..48].copy_from_slice(&2f32.to_le_bytes());
    s.write("scenes/tetra.bin", bin);
    let second = converge(&s, "scenes/t.toml", "o2", "cache");
    assert_eq!(second.code, Some(0), "{}", second.stderr);
    assert!(
        second
            .stderr
            .contains("rendering the path-traced reference"),
        "the reference of the old buffer was reused:\n{}",
        second.stderr
    );
    assert_eq!(cached(&s, "cache").len(), 2);
}
