//! Image textures from files: sRGB decoding, linear data, EXR, filtering through a planar
//! field.

use std::sync::Arc;

use bssrdf_core::Rgb;
use glam::DVec3;
use tracer::field::{Axis, Field, Filter, ImageMapping, PlanarProjection, Texture, Wrap};
use tracer::film::Film;

/// IEC 61966-2-1 decoding, written out independently of the tracer.
fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[test]
fn png_colour_is_decoded_from_srgb_and_data_is_not() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("c.png");
    image::RgbImage::from_fn(2, 1, |x, _| {
        image::Rgb(if x == 0 { [128, 0, 255] } else { [10, 200, 64] })
    })
    .save(&p)
    .unwrap();
    let colour = Texture::load(&p, false).unwrap();
    let data = Texture::load(&p, true).unwrap();
    for (x, bytes) in [(0u32, [128u8, 0, 255]), (1, [10, 200, 64])] {
        for c in 0..3 {
            let b = bytes[c] as f64 / 255.0;
            assert!((colour.texel(x, 0)[c] as f64 - srgb_to_linear(b)).abs() < 1e-6);
            assert!((data.texel(x, 0)[c] as f64 - b).abs() < 1e-6);
        }
    }
    // sRGB 128 is about 0.2158 linear.
    assert!((colour.texel(0, 0)[0] - 0.2158605).abs() < 1e-6);
    assert!(!colour.is_grey());
    // A grey PNG gives equal channels.
    let g = dir.path().join("g.png");
    image::GrayImage::from_fn(3, 3, |x, y| image::Luma([(x * 40 + y) as u8]))
        .save(&g)
        .unwrap();
    let t = Texture::load(&g, true).unwrap();
    assert!(t.is_grey());
    assert!((t.texel(2, 1)[1] as f64 - 81.0 / 255.0).abs() < 1e-6);
}

#[test]
fn exr_is_linear_and_exact() {
    let dir = tempfile::tempdir().unwrap();
    let mut f = Film::new(2, 2);
    f.set(1, 0, Rgb::new(0.125, 7.5, 1e-3));
    let p = dir.path().join("t.exr");
    tracer::output::write_exr(&f, &p).unwrap();
    // The `linear` flag does not matter for EXR.
    for linear in [false, true] {
        let t = Texture::load(&p, linear).unwrap();
        assert_eq!(t.texel(1, 0), [0.125, 7.5, 1e-3f64 as f32]);
        assert_eq!(t.texel(0, 1), [0.0; 3]);
    }
    // A corrupt file is named.
    std::fs::write(dir.path().join("bad.exr"), b"nope").unwrap();
    let e = Texture::load(&dir.path().join("bad.exr"), true).unwrap_err();
    assert!(e.to_string().contains("bad.exr"), "{e}");
}

#[test]
fn planar_bilinear_field_matches_an_independent_interpolation() {
    // 3x2 texture; planar projection along y (s = z, t = x), image 6 wide (s) and 4 high (t),
    // centred on (0, 0, 1).
    let texels: Vec<[f32; 3]> = (0..6).map(|i| [i as f32, 2.0 * i as f32, 0.5]).collect();
    let tex = Arc::new(Texture::from_texels("mem", 3, 2, texels.clone()).unwrap());
    let field = Field::image(
        tex,
        ImageMapping::Planar {
            projection: PlanarProjection::new(Axis::Y, DVec3::new(0.0, 0.0, 1.0)),
            size: [6.0, 4.0],
        },
        Wrap::Clamp,
        Filter::Bilinear,
        Rgb::new(1.0, 0.5, 2.0),
    )
    .unwrap();
    let texel = |i: i64, j: i64| -> [f64; 3] {
        let (i, j) = (i.clamp(0, 2) as usize, j.clamp(0, 1) as usize);
        texels[j * 3 + i].map(|v| v as f64)
    };
    for (x, y, z) in [
        (0.3, 5.0, 1.7),
        (-1.9, -2.0, -1.5),
        (1.0, 0.0, 1.0),
        (0.0, 9.0, 3.9),
    ] {
        // Axis y: (s, t) = (z − 1, x − 0). Image: u = s/6 + 1/2, v_down = 1/2 − t/4.
        let (s, t) = (z - 1.0, x);
        let (px, py): (f64, f64) = ((s / 6.0 + 0.5) * 3.0 - 0.5, (0.5 - t / 4.0) * 2.0 - 0.5);
        let (i0, j0) = (px.floor() as i64, py.floor() as i64);
        let (fx, fy) = (px - px.floor(), py - py.floor());
        let mut expect = [0.0; 3];
        for c in 0..3 {
            expect[c] = (1.0 - fx) * (1.0 - fy) * texel(i0, j0)[c]
                + fx * (1.0 - fy) * texel(i0 + 1, j0)[c]
                + (1.0 - fx) * fy * texel(i0, j0 + 1)[c]
                + fx * fy * texel(i0 + 1, j0 + 1)[c];
        }
        let got = field.at_point(DVec3::new(x, y, z));
        let scale = [1.0, 0.5, 2.0];
        for c in 0..3 {
            assert!(
                (got[c] - scale[c] * expect[c]).abs() < 1e-12,
                "({x}, {y}, {z}) ch {c}: {} vs {}",
                got[c],
                scale[c] * expect[c]
            );
        }
    }
}
