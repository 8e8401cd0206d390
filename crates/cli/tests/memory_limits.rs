//! Memory guards that see the real allocations and the real limits (issue 39, case 6): a
//! texture is budgeted at its decoded size, the process's `ulimit -v` counts, and an OBJ file
//! is streamed, so a binary file is refused without being read whole.

mod common;

use common::{MINIMAL, Scratch, black_grey_png, edit, run_limited, run_within, with_obj};

/// The PNG maker of these tests writes valid files (decoded here by the texture loader).
#[test]
fn the_test_png_is_a_valid_black_image() {
    let s = Scratch::new();
    s.write("small.png", black_grey_png(67, 5));
    let t = tracer::field::Texture::load(&s.join("small.png"), true).unwrap();
    assert_eq!((t.width, t.height), (67, 5));
    assert_eq!((t.min(), t.max()), ([0.0; 3], [0.0; 3]));
}

/// A 20000² greyscale PNG (a few MB; the was 389 kB) passed the decoder's 512 MiB
/// check (400 MB decoded) and then aborted allocating its 4.8 GB of texels. It is refused
/// from its header, before any pixel is decoded, with the decoded size.
#[test]
fn a_huge_greyscale_png_is_refused_at_its_decoded_size() {
    let s = Scratch::new();
    s.write("big.png", black_grey_png(20000, 20000));
    s.write("tex.toml", common::with_texture("big.png"));
    let r = run_within(
        s.path(),
        &["render", "tex.toml", "--method", "pt", "-o", "o.exr"],
        60,
    );
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    for needle in [
        "big.png",
        "20000x20000",
        "4.8 GB",
        "memory limit of 512 MiB",
        "HET_BSSRDF_TEXTURE_LIMIT_MB",
    ] {
        assert!(
            r.stderr.contains(needle),
            "`{needle}` missing: {}",
            r.stderr
        );
    }
    assert!(!s.join("o.exr").exists());
}

/// A 12000² render under `ulimit -v` passed the check (which read only MemAvailable),
/// rendered, and aborted while writing. The address-space limit is now part of the check:
/// refused at once, naming the limit. The same render with a small image still runs under it.
#[test]
fn a_render_over_the_address_space_limit_is_refused_before_the_work() {
    let s = Scratch::new();
    let big = edit(
        &edit(MINIMAL, "width = 8\n", "width = 12000\n"),
        "height = 8\n",
        "height = 12000\n",
    );
    s.write("big.toml", big);
    s.write("small.toml", MINIMAL);
    let limit = "ulimit -v 4000000"; // 4 GB of address space; the render needs about 15 GB
    let r = run_limited(
        s.path(),
        limit,
        &["render", "big.toml", "--method", "pt", "-o", "big.exr"],
        30,
    );
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    for needle in ["big.toml", "render.width", "12000x12000", "RLIMIT_AS"] {
        assert!(
            r.stderr.contains(needle),
            "`{needle}` missing: {}",
            r.stderr
        );
    }
    assert!(!s.join("big.exr").exists());
    let r = run_limited(
        s.path(),
        limit,
        &["render", "small.toml", "--method", "pt", "-o", "small.exr"],
        60,
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
}

/// A 2 GB `.obj` of NUL bytes was read whole into memory before "no triangles" (and its lines
/// read whole again to find the error's line). It is refused after one buffer: under a 1 GB
/// address-space limit, with the line and the reason.
#[test]
fn a_2gb_obj_of_nul_bytes_is_refused_without_being_read_whole() {
    let s = Scratch::new();
    let f = std::fs::File::create(s.join("zeros.obj")).unwrap();
    f.set_len(2 << 30).unwrap(); // sparse: no disk space used
    drop(f);
    s.write("z.toml", with_obj("zeros.obj"));
    let r = run_limited(
        s.path(),
        "ulimit -v 1000000",
        &["render", "z.toml", "--method", "pt", "-o", "z.exr"],
        60,
    );
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    for needle in ["zeros.obj:1:", "NUL byte"] {
        assert!(
            r.stderr.contains(needle),
            "`{needle}` missing: {}",
            r.stderr
        );
    }
}
