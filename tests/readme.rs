//! The README and the documents it points at: the library example in `docs/library.md` is the
//! `het-estimate` crate documentation's, which `cargo test` compiles and runs as a doctest (the
//! two copies must not drift apart); the README's scene template and painted-texture fragment
//! load; every relative link of the README and of `docs/*.md` names a file that exists.

use std::path::Path;

use het_bssrdf::tracer::scene::Scene;

const README: &str = include_str!("../README.md");

/// The first ```` ```rust ```` block after `heading` in `text`.
fn rust_block<'a>(text: &'a str, heading: &str) -> &'a str {
    let from = text.find(heading).map_or(0, |i| i);
    let start = text[from..].find("```rust").expect("a rust block") + from + "```rust".len();
    let end = text[start..].find("```").expect("a closed block") + start;
    &text[start..end]
}

#[test]
fn library_example_is_the_compiled_doctest() {
    let doc = include_str!("../docs/library.md");
    let krate = include_str!("../crates/het-estimate/README.md");
    let a = rust_block(doc, "# Using the libraries in your renderer");
    let b = rust_block(krate, "");
    assert!(a.contains("impl SurfaceQuery for") && a.contains("fn main()"));
    assert_eq!(
        a, b,
        "docs/library.md's example differs from het-estimate's README"
    );
}

/// The README's TOML blocks, in order.
fn toml_blocks() -> Vec<&'static str> {
    README
        .split("```toml\n")
        .skip(1)
        .map(|b| b.split("```").next().expect("a closed block"))
        .collect()
}

/// The README's "your own model" scene, with the repository's UV-mapped block standing for
/// the reader's mesh, loads as written; so does it with the painted-texture fragment added and
/// the statue made of it (a texture of the repository standing for the reader's).
#[test]
fn readme_scene_template_and_painted_texture_load() {
    let blocks = toml_blocks();
    assert_eq!(
        blocks.len(),
        2,
        "the README's TOML blocks changed: update this test"
    );
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes");
    let scene = blocks[0].replace("\"statue.obj\"", "\"../models/marble-block.obj\"");
    assert_ne!(scene, blocks[0], "the template no longer reads statue.obj");
    let s = Scene::from_toml_str(&scene, &dir, "README template").unwrap();
    assert!(s.objects().iter().any(|o| o.name == "statue"));
    let painted = scene.replace("material = \"wax\"\npath", "material = \"painted\"\npath")
        + blocks[1]
            .replace("\"statue-colour.png\"", "\"painted-colour.png\"")
            .as_str();
    let s = Scene::from_toml_str(&painted, &dir, "README painted").unwrap();
    let statue = s.objects().iter().find(|o| o.name == "statue").unwrap();
    assert!(
        statue
            .material
            .translucent()
            .is_some_and(|t| t.name == "painted"),
        "the statue is not made of the painted material"
    );
}

/// The relative link targets (`](target)`, without `#anchor`) of `text`.
fn links(text: &str) -> Vec<&str> {
    text.split("](")
        .skip(1)
        .filter_map(|s| s.split(')').next())
        .map(|t| t.split('#').next().unwrap_or(""))
        .filter(|t| !t.is_empty() && !t.contains("://"))
        .collect()
}

#[test]
fn links_of_the_readme_and_docs_name_existing_files() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = vec![root.join("README.md")];
    for e in std::fs::read_dir(root.join("docs")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "md") {
            files.push(p);
        }
    }
    let mut checked = 0;
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        let dir = file.parent().unwrap();
        for target in links(&text) {
            assert!(
                dir.join(target).exists(),
                "{}: the link `{target}` names no file",
                file.display()
            );
            checked += 1;
        }
    }
    assert!(checked > 30, "only {checked} links");
}

#[test]
fn the_readme_is_a_guide_of_at_most_300_lines() {
    let lines = README.lines().count();
    assert!(lines <= 300, "README.md has {lines} lines");
    for needle in [
        "cargo test --workspace",
        "## Render your first scene",
        "docs/scene-format.md",
        "docs/results.md",
        "sh scripts/fetch-bunny.sh",
    ] {
        assert!(README.contains(needle), "README.md lacks `{needle}`");
    }
}
