//! Every value of a scene file is validated once, when it is loaded, with the bounds every
//! method accepts, and the error names the file, the line and the key: through the built
//! binary, with `--method pt` so that no BSSRDF set-up can catch what the loader missed.

mod common;

use common::{CUBE_OBJ, MINIMAL, Scratch, edit, gradient, with_obj};
use tracer::output::write_exr;

/// A path-traced render of `bad.toml` into `out.exr`.
const RENDER_PT: &[&str] = &["render", "bad.toml", "--method", "pt", "--out", "out.exr"];

#[test]
fn minimal_scene_renders_with_pt() {
    let s = Scratch::new();
    s.write("bad.toml", MINIMAL);
    let r = s.run(RENDER_PT);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
}

#[test]
fn fixed_length_arrays_refuse_extra_elements() {
    let s = Scratch::new();
    for (from, to, line) in [
        (
            "max = [1.0, 1.0, 0.0]",
            "max = [1.0, 1.0, 0.0, 5.0]",
            "bad.toml:24",
        ),
        (
            "centre = [0.0, 0.0, 5.0]",
            "centre = [0.0, 0.0, 5.0, 1.0]",
            "bad.toml:8",
        ),
        (
            "sigma_a = 0.1",
            "sigma_a = { type = \"check\", width = 1.0, values = [0.1, 0.2, 0.3] }",
            "bad.toml:17",
        ),
    ] {
        s.write("bad.toml", edit(MINIMAL, from, to));
        s.assert_rejected(RENDER_PT, 1, &[line, "elements"]);
    }
}

#[test]
fn coefficients_above_the_profiles_bound_are_refused_at_load() {
    let s = Scratch::new();
    s.write("bad.toml", edit(MINIMAL, "sigma_s = 1.0", "sigma_s = 1e13"));
    s.assert_rejected(
        RENDER_PT,
        1,
        &["bad.toml:18", "`material[0].sigma_s`", "1e12"],
    );
    // unit_scale applies before the bound.
    s.write(
        "bad.toml",
        edit(MINIMAL, "sigma_s = 1.0", "sigma_s = 1e9\nunit_scale = 1e4"),
    );
    s.assert_rejected(RENDER_PT, 1, &["bad.toml", "`material[0].sigma_s`", "1e12"]);
}

#[test]
fn eta_has_one_range_for_every_method_checked_at_load() {
    let s = Scratch::new();
    s.write(
        "bad.toml",
        edit(MINIMAL, "sigma_s = 1.0", "sigma_s = 1.0\neta = 5.0"),
    );
    for method in ["pt", "sone"] {
        s.assert_rejected(
            &["render", "bad.toml", "--method", method, "--out", "out.exr"],
            1,
            &["bad.toml:19", "`material[0].eta`", "[1, 3]"],
        );
    }
}

#[test]
fn render_estimator_is_parsed_at_load_whatever_the_method() {
    let s = Scratch::new();
    s.write(
        "bad.toml",
        edit(MINIMAL, "spp = 1", "spp = 1\nestimator = \"sonne\""),
    );
    s.assert_rejected(
        RENDER_PT,
        1,
        &["bad.toml:5", "`render.estimator`", "`sonne`", "sone"],
    );
}

#[test]
fn uv_mapped_fields_need_texture_coordinates() {
    let s = Scratch::new();
    write_exr(&gradient(4, 4), &s.join("t.exr")).unwrap();
    let uv = "sigma_a = { type = \"image\", texture = \"t\", mapping = \"uv\", scale = 0.1 }";
    let texture = "\n[[texture]]\nname = \"t\"\npath = \"t.exr\"\n";
    // An OBJ without `vt` lines.
    s.write("cube.obj", CUBE_OBJ);
    s.write(
        "bad.toml",
        format!(
            "{}{texture}",
            edit(&with_obj("cube.obj"), "sigma_a = 0.1", uv)
        ),
    );
    s.assert_rejected(
        &["render", "bad.toml", "--method", "sone", "--out", "out.exr"],
        1,
        &["bad.toml", "`shape[0]`", "`blob`", "texture coordinates"],
    );
    // A sphere primitive has none either.
    let sphere = edit(
        MINIMAL,
        "type = \"box\"\nmaterial = \"m\"\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 0.0]",
        "type = \"sphere\"\nmaterial = \"m\"\ncentre = [0.0, 0.0, 0.0]\nradius = 1.0",
    );
    s.write(
        "bad.toml",
        format!("{}{texture}", edit(&sphere, "sigma_a = 0.1", uv)),
    );
    s.assert_rejected(
        &["render", "bad.toml", "--method", "sone", "--out", "out.exr"],
        1,
        &["bad.toml", "`shape[0]`", "texture coordinates"],
    );
    // A box has UVs: the same material renders.
    s.write(
        "ok.toml",
        format!("{}{texture}", edit(MINIMAL, "sigma_a = 0.1", uv)),
    );
    let r = s.run(&["render", "ok.toml", "--method", "sone", "--out", "ok.exr"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
}

/// A unit cube as an ASCII PLY (six quads, outward-facing).
const CUBE_PLY: &str = "ply
format ascii 1.0
element vertex 8
property float x
property float y
property float z
element face 6
property list uchar uint vertex_indices
end_header
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
4 0 3 2 1
4 4 5 6 7
4 0 1 5 4
4 3 7 6 2
4 0 4 7 3
4 1 2 6 5
";

#[test]
fn a_ply_mesh_renders_and_a_bad_one_is_named() {
    let s = Scratch::new();
    s.write("cube.ply", CUBE_PLY);
    let scene = with_obj("cube.ply").replace("type = \"obj\"", "type = \"ply\"");
    s.write("ply.toml", &scene);
    for method in ["pt", "sone"] {
        let r = s.run(&["render", "ply.toml", "--method", method, "-o", "x.exr"]);
        assert_eq!(r.code, Some(0), "{method}: {}", r.stderr);
    }
    s.write("bad.ply", CUBE_PLY.replace("4 1 2 6 5", "4 1 2 6 9"));
    s.write("bad.toml", scene.replace("cube.ply", "bad.ply"));
    s.assert_rejected(
        RENDER_PT,
        1,
        &["bad.toml", "`shape[0]`", "bad.ply", "vertex 9"],
    );
}
