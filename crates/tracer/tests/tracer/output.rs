//! Output writers: round trips, the sRGB preview, and atomicity under each failure class.

use std::path::Path;

use bssrdf_core::Rgb;
use tracer::error::OutputError;
use tracer::film::Film;
use tracer::output::{read_exr, write_exr, write_grey_exr, write_json, write_png};

fn film() -> Film {
    let mut f = Film::new(5, 3);
    for y in 0..3 {
        for x in 0..5 {
            f.set(
                x,
                y,
                Rgb::new(x as f64 * 0.37, y as f64 * 1.5e-3, 1e4 + (x * y) as f64),
            );
        }
    }
    f
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn exr_round_trip_and_grey_maps() {
    let dir = tempfile::tempdir().unwrap();
    let f = film();
    let p = dir.path().join("a.exr");
    write_exr(&f, &p).unwrap();
    let back = read_exr(&p).unwrap();
    assert_eq!((back.width, back.height), (5, 3));
    for (a, b) in f.pixels.iter().zip(&back.pixels) {
        for c in 0..3 {
            assert_eq!(b[c], a[c] as f32 as f64, "f32 round trip");
        }
    }
    // A single-channel map reads back as equal channels, row 0 at the top.
    let values: Vec<f64> = (0..15).map(|i| i as f64 * 0.25).collect();
    let g = dir.path().join("g.exr");
    write_grey_exr(5, 3, &values, &g).unwrap();
    let back = read_exr(&g).unwrap();
    assert_eq!(back.get(4, 0), Rgb::splat(1.0));
    assert_eq!(back.get(0, 2), Rgb::splat(2.5));
    assert_eq!(
        entries(dir.path()),
        vec!["a.exr", "g.exr"],
        "no temporary files left"
    );
    assert!(matches!(
        write_grey_exr(5, 3, &values[..14], &g),
        Err(OutputError::Encode { .. })
    ));
}

#[test]
fn png_preview_applies_exposure_and_the_srgb_curve() {
    let dir = tempfile::tempdir().unwrap();
    let mut f = Film::new(3, 1);
    f.set(0, 0, Rgb::new(0.25, 0.5, 1.0));
    f.set(1, 0, Rgb::new(0.001, 2.0, -1.0));
    f.set(2, 0, Rgb::new(f64::NAN, 0.0, 0.18));
    let p = dir.path().join("p.png");
    write_png(&f, &p, 1.0).unwrap();
    let img = image::open(&p).unwrap().to_rgb8();
    // Independent sRGB encoding (IEC 61966-2-1) of x · 2^1.
    let enc = |x: f64| -> u8 {
        let v = x * 2.0;
        let s = if v.is_nan() {
            0.0
        } else if v <= 0.0031308 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        };
        (s.clamp(0.0, 1.0) * 255.0).round() as u8
    };
    for x in 0..3 {
        for c in 0..3 {
            assert_eq!(
                img.get_pixel(x, 0).0[c],
                enc(f.get(x, 0)[c]),
                "pixel {x} channel {c}"
            );
        }
    }
    assert_eq!(img.get_pixel(0, 0).0, [188, 255, 255]);
}

#[test]
fn json_sidecar() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("meta.json");
    let v = serde_json::json!({"spp": 16, "method": "sone", "rays": [1, 2, 3]});
    write_json(&v, &p).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.contains("\n  \"spp\": 16"), "pretty-printed: {text}");
    let back: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(back, v);
}

#[test]
fn failures_name_the_path_and_leave_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let f = film();

    // Missing directory.
    let p = dir.path().join("no/such/dir/out.exr");
    let e = write_exr(&f, &p).unwrap_err();
    assert!(matches!(e, OutputError::MissingDirectory { .. }), "{e}");
    assert!(e.to_string().contains("no/such/dir/out.exr"), "{e}");

    // The path is an existing directory.
    let sub = dir.path().join("sub.png");
    std::fs::create_dir(&sub).unwrap();
    for e in [
        write_png(&f, &sub, 0.0).unwrap_err(),
        write_exr(&f, &sub).unwrap_err(),
        write_json(&serde_json::json!(1), &sub).unwrap_err(),
    ] {
        assert!(matches!(e, OutputError::IsDirectory { .. }), "{e}");
        assert!(e.to_string().contains("sub.png"), "{e}");
    }
    assert!(sub.is_dir() && entries(&sub).is_empty());

    // Encoding failure (film size mismatch) leaves an existing file untouched.
    let keep = dir.path().join("keep.exr");
    write_exr(&f, &keep).unwrap();
    let before = std::fs::read(&keep).unwrap();
    let mut broken = f.clone();
    broken.pixels.pop();
    let e = write_exr(&broken, &keep).unwrap_err();
    assert!(
        matches!(e, OutputError::Encode { .. }) && e.to_string().contains("keep.exr"),
        "{e}"
    );
    assert_eq!(std::fs::read(&keep).unwrap(), before);
    assert_eq!(entries(dir.path()), vec!["keep.exr", "sub.png"]);

    // Reading a missing or corrupt EXR names it.
    let e = read_exr(&dir.path().join("absent.exr")).unwrap_err();
    assert!(e.to_string().contains("absent.exr"), "{e}");
    std::fs::write(dir.path().join("junk.exr"), b"not an exr").unwrap();
    let e = read_exr(&dir.path().join("junk.exr")).unwrap_err();
    assert!(
        matches!(e, OutputError::Decode { .. }) && e.to_string().contains("junk.exr"),
        "{e}"
    );
}

#[cfg(unix)]
#[test]
fn read_only_directory_is_reported_and_left_clean() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let ro = dir.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    // Root (and some CI containers) ignore directory permissions: detect it.
    if std::fs::write(ro.join("probe"), b"x").is_ok() {
        let _ = std::fs::remove_file(ro.join("probe"));
        eprintln!("note: running with permissions that ignore read-only directories: test skipped");
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
        return;
    }
    let p = ro.join("out.png");
    let e = write_png(&film(), &p, 0.0).unwrap_err();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert!(matches!(e, OutputError::Io { .. }), "{e}");
    assert!(e.to_string().contains("ro/out.png"), "{e}");
    assert!(entries(&ro).is_empty());
}
