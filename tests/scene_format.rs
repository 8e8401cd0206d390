//! `docs/scene-format.md` documents every key the scene loader accepts, and its examples load.
//!
//! The accepted keys are not listed here: they are read from the loader itself. A scene with an
//! unknown key in a section makes the loader's serde structures list the section's keys
//! ("unknown field `zzz`, expected one of `width`, …"); an unknown `type` lists the types; a
//! key a field kind does not take lists that kind's keys. Each key must then appear as a table
//! row (`` | `key` | ``) under the document's heading for its section and type. A key added
//! to the loader without documentation fails this test, naming the key.
//!
//! The document's first TOML block is a complete scene; every other block is a fragment,
//! loaded as that scene plus the fragment (the fragment's `[render]` or `[camera]` replacing
//! the scene's), with paths relative to `examples/scenes`.

use std::path::Path;

use het_bssrdf::tracer::scene::Scene;

const DOC: &str = include_str!("../docs/scene-format.md");

fn scenes_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes")
}

/// The TOML blocks of the document, in order.
fn toml_blocks() -> Vec<&'static str> {
    DOC.split("```toml\n")
        .skip(1)
        .map(|b| b.split("```").next().expect("a closed block"))
        .collect()
}

/// The base scene (the first block) with `fragment` added; a `[render]` or `[camera]` in the
/// fragment replaces the base's.
fn with_fragment(fragment: &str) -> String {
    let base = toml_blocks()[0];
    let replaced: Vec<&str> = ["[render]", "[camera]"]
        .into_iter()
        .filter(|h| fragment.lines().any(|l| l.trim() == *h))
        .collect();
    let mut out = String::new();
    let mut keep = true;
    for line in base.lines() {
        if line.starts_with('[') {
            keep = !replaced.contains(&line.trim());
        }
        if keep {
            out.push_str(line);
            out.push('\n');
        }
    }
    out + "\n" + fragment
}

fn load(text: &str) -> Result<Scene, String> {
    Scene::from_toml_str(text, &scenes_dir(), "scene-format.md").map_err(|e| format!("{e:#}"))
}

#[test]
fn the_documents_examples_load() {
    let blocks = toml_blocks();
    assert!(blocks.len() > 10, "only {} TOML blocks", blocks.len());
    load(blocks[0]).unwrap_or_else(|e| panic!("the complete scene does not load: {e}"));
    for (i, b) in blocks.iter().enumerate().skip(1) {
        load(&with_fragment(b)).unwrap_or_else(|e| panic!("block {i} does not load: {e}\n{b}"));
    }
}

/// The backticked names after "expected" in a loader error (serde's "expected one of `a`,
/// `b`", or the loader's "expected \"a\" | \"b\"").
fn expected_names(error: &str) -> Vec<String> {
    let tail = error
        .split("expected")
        .nth(1)
        .unwrap_or_else(|| panic!("no list of names in: {error}"));
    let quote = if tail.contains('`') { '`' } else { '"' };
    tail.split(quote)
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// The loader's error for `text`, which must not load.
fn error_of(text: &str) -> String {
    match load(text) {
        Ok(_) => panic!("loaded, but has an unknown key or type:\n{text}"),
        Err(e) => e,
    }
}

/// The keys the loader accepts in the table that `template` writes with `{}` replaced by
/// `zzz_unknown = 1` (an unknown key), added to the base scene.
fn keys(template: &str) -> Vec<String> {
    let e = error_of(&with_fragment(&template.replace("{}", "zzz_unknown = 1")));
    assert!(e.contains("zzz_unknown"), "{e}");
    expected_names(&e)
}

/// The types the loader accepts where `template` writes `type = "{}"`.
fn types(template: &str) -> Vec<String> {
    expected_names(&error_of(&with_fragment(
        &template.replace("{}", "zzz_unknown"),
    )))
}

/// The document's text under the heading that contains `heading` (up to the next heading of
/// the same or a higher level).
fn section(heading: &str) -> String {
    let level = |l: &str| l.chars().take_while(|&c| c == '#').count();
    let lines: Vec<&str> = DOC.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.starts_with('#') && l.contains(heading))
        .unwrap_or_else(|| panic!("no heading with {heading:?} in docs/scene-format.md"));
    let own = level(lines[at]);
    lines[at + 1..]
        .iter()
        .take_while(|l| !(l.starts_with('#') && level(l) <= own))
        .copied()
        .collect::<Vec<_>>()
        .join("\n")
}

/// Each of `keys` has a table row in one of `sections`.
fn documented(what: &str, keys: &[String], sections: &[&str]) {
    assert!(!keys.is_empty(), "{what}: no keys found");
    for k in keys {
        let row = format!("| `{k}` |");
        assert!(
            sections.iter().any(|s| s.contains(&row)),
            "{what}: the key `{k}` that the loader accepts is not documented in \
             docs/scene-format.md"
        );
    }
}

fn type_heading(t: &str) -> String {
    format!("`type = \"{t}\"`")
}

#[test]
fn every_key_the_loader_accepts_is_documented() {
    documented(
        "[render]",
        &keys("[render]\nwidth = 8\nheight = 8\nspp = 1\n{}\n"),
        &[&section("`[render]`")],
    );
    let camera = |t: &str, body: &str| format!("[camera]\ntype = \"{t}\"\n{body}{{}}\n");
    let cameras = types("[camera]\ntype = \"{}\"\n");
    assert!(cameras.len() >= 2, "{cameras:?}");
    for t in &cameras {
        let body = match t.as_str() {
            "perspective" => {
                "eye = [0.0, -5.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\nfov_y = 40.0\n"
            }
            "orthographic" => {
                "centre = [0.0, 0.0, 5.0]\ndirection = [0.0, 0.0, -1.0]\nup = [0.0, 1.0, 0.0]\nwidth = 2.0\nheight = 2.0\n"
            }
            other => panic!(
                "a camera type this test does not know: {other}; add it here and to the document"
            ),
        };
        documented(
            &format!("camera {t}"),
            &keys(&camera(t, body)),
            &[&section(&type_heading(t))],
        );
    }
    documented(
        "[[texture]]",
        &keys("[[texture]]\nname = \"t\"\npath = \"marble-veins.png\"\n{}\n"),
        &[&section("`[[texture]]`")],
    );
    let materials = types("[[material]]\nname = \"m\"\ntype = \"{}\"\n");
    assert!(materials.len() >= 2, "{materials:?}");
    for t in &materials {
        let body = match t.as_str() {
            "translucent" => "sigma_a = 1.0\nsigma_s = 1.0\n",
            "diffuse" => "albedo = 0.5\n",
            other => panic!("a material type this test does not know: {other}"),
        };
        documented(
            &format!("material {t}"),
            &keys(&format!(
                "[[material]]\nname = \"m\"\ntype = \"{t}\"\n{body}{{}}\n"
            )),
            &[&section(&type_heading(t))],
        );
    }
    // Fields: one table type for every kind; each kind's own keys from the loader's refusal
    // of a key it does not take.
    let field = |table: &str| {
        format!(
            "[[material]]\nname = \"m\"\ntype = \"translucent\"\nsigma_a = {table}\nsigma_s = 1.0\n"
        )
    };
    let all_field_keys = keys(&field("{ type = \"constant\", value = 1.0, {} }"));
    let kinds = types(&field("{ type = \"{}\" }"));
    assert!(kinds.len() >= 4, "{kinds:?}");
    let mut per_kind = Vec::new();
    for kind in &kinds {
        let foreign = if kind == "constant" { "width" } else { "value" };
        let e = error_of(&with_fragment(&field(&format!(
            "{{ type = \"{kind}\", {foreign} = 1.0 }}"
        ))));
        let list = e
            .split("its keys: ")
            .nth(1)
            .and_then(|s| s.split(')').next())
            .unwrap_or_else(|| panic!("{kind}: no key list in {e}"));
        let mut kind_keys: Vec<String> = list.split(", ").map(str::to_string).collect();
        kind_keys.push("type".into());
        documented(
            &format!("field {kind}"),
            &kind_keys,
            &[&section(&type_heading(kind))],
        );
        per_kind.extend(kind_keys);
    }
    for k in &all_field_keys {
        assert!(per_kind.contains(k), "field key `{k}` belongs to no kind");
    }
    let lights = types("[[light]]\ntype = \"{}\"\n");
    assert!(lights.len() >= 5, "{lights:?}");
    for t in &lights {
        documented(
            &format!("light {t}"),
            &keys(&format!("[[light]]\ntype = \"{t}\"\n{{}}\n")),
            &[&section(&type_heading(t))],
        );
    }
    let shapes = types("[[shape]]\nmaterial = \"wax\"\ntype = \"{}\"\n");
    assert!(shapes.len() >= 6, "{shapes:?}");
    let common = section("`[[shape]]`");
    let common = &common[..common.find("\n### ").unwrap_or(common.len())];
    for t in &shapes {
        let own = match t.as_str() {
            "obj" | "gltf" | "ply" => section("meshes from files"),
            _ => section(&type_heading(t)),
        };
        documented(
            &format!("shape {t}"),
            &keys(&format!(
                "[[shape]]\nmaterial = \"wax\"\ntype = \"{t}\"\n{{}}\n"
            )),
            &[&own, common],
        );
    }
    let transform = section("`transform`");
    documented(
        "shape transform",
        &keys(
            "[[shape]]\ntype = \"sphere\"\nmaterial = \"wax\"\ncentre = [0.0, 0.0, 5.0]\nradius = 1.0\ntransform = { {} }\n",
        ),
        &[&transform],
    );
    documented(
        "shape transform rotate",
        &keys(
            "[[shape]]\ntype = \"sphere\"\nmaterial = \"wax\"\ncentre = [0.0, 0.0, 5.0]\nradius = 1.0\ntransform = { rotate = { {} } }\n",
        ),
        &[&transform],
    );
}
