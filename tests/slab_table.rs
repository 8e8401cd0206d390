//! The slab table (`bssrdf_core::tabulated::slab`) against exact transport: its data file,
//! the unscattered light through both Fresnel boundaries (closed form at every plane), single
//! scattering at η = 1 (a one-dimensional integral computed here, independently of the
//! simulation), the energy balance near α = 1, the thick limit against the half-space table
//! (a separate simulation), and the profile built on it.

use bssrdf_core::fresnel::dielectric;
use bssrdf_core::tabulated::grid::{N_ALBEDO, N_BINS, albedo_of_row, centre};
use bssrdf_core::tabulated::half_space::table;
use bssrdf_core::tabulated::slab::{
    SLAB_ETAS, SLAB_ROWS, SLAB_THICKNESSES, SlabFace, SlabTerm, slab_albedo_of_row, slab_table,
};
use bssrdf_core::tabulated::slab_file::{SlabData, SlabPlane, simulate_slab_plane};

use crate::common::radial::radial_integral;

const DATA: &[u8] = include_bytes!("../crates/bssrdf-core/data/slab-profile-v1.bin");

/// The raw table (no pooling): the totals are the same either way, bins are compared raw.
fn raw() -> SlabData {
    SlabData::from_bytes(DATA).unwrap()
}

#[test]
fn the_data_file_round_trips_and_records_its_provenance() {
    let t = raw();
    assert_eq!(t.to_bytes(), DATA, "the format round-trips bit for bit");
    assert_eq!(t.planes.len(), SLAB_THICKNESSES.len() * SLAB_ETAS.len());
    assert!(t.photons >= 1_000_000, "only {} photons", t.photons);
    assert!(DATA.len() <= 1_200_000, "{} bytes", DATA.len());
    for p in &t.planes {
        assert_eq!(p.capped, 0, "no slab path reaches the event cap");
    }
    assert!(SlabData::from_bytes(&DATA[..DATA.len() - 1]).is_err());
    assert!(SlabData::from_bytes(b"HBSSRDFS").is_err());
    let mut bad = DATA.to_vec();
    bad[0] = b'X';
    assert!(SlabData::from_bytes(&bad).is_err());
}

#[test]
fn a_plane_is_the_same_whatever_the_thread_count() {
    // Two chunks and a bit: the chunks' order of summation is fixed.
    let n = 2 * 16_384 + 100;
    let one = simulate_slab_plane(0.5, 1.3, 7, 3, n, 1);
    let three = simulate_slab_plane(0.5, 1.3, 7, 3, n, 3);
    assert_eq!(one, three);
}

#[test]
fn unscattered_light_matches_the_closed_form_through_both_boundaries() {
    // A photon entering along the normal crosses d unscattered (e^{-d}); each face transmits
    // 1 − F and reflects F (F the normal-incidence Fresnel reflectance from inside), so
    // T0 = (1 − F) e^{-d} / (1 − F² e^{-2d}) and R0 = F (1 − F) e^{-2d} / (1 − F² e^{-2d}).
    // This is the σs = 0 slab, whose transmission is e^{-d} at η = 1 and reflection 0.
    let t = raw();
    // A face that no photon reached has a standard error of 0: allow the expected count of
    // a few photons (Poisson).
    let floor = 3.0 / t.photons as f64;
    for p in &t.planes {
        let f = dielectric(1.0, 1.0 / p.eta);
        let (e1, e2) = ((-p.thickness).exp(), (-2.0 * p.thickness).exp());
        let den = 1.0 - f * f * e2;
        let want = [f * (1.0 - f) * e2 / den, (1.0 - f) * e1 / den];
        for (face, want) in want.into_iter().enumerate() {
            let (got, se) = (p.ballistic[face], p.ballistic_se[face]);
            assert!(
                (got - want).abs() <= 4.0 * se + floor,
                "d {} η {} face {face}: {got} ± {se}, exact {want}",
                p.thickness,
                p.eta,
            );
        }
    }
}

/// Midpoint rule on (0, 1) with `n` points.
fn midpoint(n: usize, f: impl Fn(f64) -> f64) -> f64 {
    (0..n).map(|k| f((k as f64 + 0.5) / n as f64)).sum::<f64>() / n as f64
}

#[test]
fn index_matched_single_scattering_matches_the_exact_integrals() {
    // η = 1, a collision at depth z (density e^{-z}), an isotropic direction with cosine μ
    // (density 1/2 on each hemisphere) and escape without another collision:
    //   R1 = (α/2) ∫₀¹ μ/(1 + μ) (1 − e^{−d(1 + 1/μ)}) dμ,
    //   T1 = (α/2) ∫₀¹ μ (e^{−d} − e^{−d/μ}) / (1 − μ) dμ.
    let mut checked = 0;
    for p in raw().planes.iter().filter(|p| p.eta == 1.0) {
        let d = p.thickness;
        let r1 = midpoint(200_000, |m| {
            m / (1.0 + m) * (1.0 - (-d * (1.0 + 1.0 / m)).exp())
        });
        let t1 = midpoint(200_000, |m| m * ((-d).exp() - (-d / m).exp()) / (1.0 - m));
        for row in 0..SLAB_ROWS {
            let a = slab_albedo_of_row(row);
            for (face, exact) in [(0, r1), (1, t1)] {
                let k = face * SLAB_ROWS + row;
                let (got, se) = (p.single[k], p.single_se[k]);
                let want = 0.5 * a * exact;
                assert!(
                    (got - want).abs() <= 4.0 * se + 1e-6,
                    "d {d} α {a} face {face}: {got} ± {se}, exact {want}"
                );
                checked += 1;
            }
        }
    }
    assert_eq!(checked, SLAB_THICKNESSES.len() * SLAB_ROWS * 2);
}

#[test]
fn near_alpha_one_every_photon_leaves_through_one_face() {
    // At the largest albedo α₀ the exits of all orders sum to E[α₀^n] ∈ [1 − (1 − α₀)E[n], 1]
    // (α^n ≥ 1 − n(1 − α)): a face counted twice or an exit lost would break it.
    let a0 = slab_albedo_of_row(0);
    for p in &raw().planes {
        let parts = [
            (p.ballistic[0], p.ballistic_se[0]),
            (p.ballistic[1], p.ballistic_se[1]),
            (p.single[0], p.single_se[0]),
            (p.single[SLAB_ROWS], p.single_se[SLAB_ROWS]),
            (p.total[0], p.total_se[0]),
            (p.total[SLAB_ROWS], p.total_se[SLAB_ROWS]),
        ];
        let sum: f64 = parts.iter().map(|x| x.0).sum();
        let se: f64 = parts.iter().map(|x| x.1).sum(); // correlated: add linearly
        let low = 1.0 - (1.0 - a0) * p.mean_events;
        assert!(
            sum <= 1.0 + 4.0 * se && sum >= low - 4.0 * se,
            "d {} η {}: R + T = {sum} ± {se}, expected in [{low}, 1]",
            p.thickness,
            p.eta
        );
    }
}

#[test]
fn the_thickest_slab_reflects_as_the_half_space_where_little_gets_through() {
    // Slab row 10 and half-space row 26 are the same albedo (0.971, σtr ≈ 0.29 per mfp); at 16
    // mean free paths the light that would have come back from beyond the far face is of order
    // e^{-2σtr d} ≈ 1e-4 of it,
    // so the multiple-scattering reflection of the slab table must equal that of the
    // half-space table (a separate simulation) within their errors, in total and per bin.
    let (sr, hr) = (10, 26);
    assert!((slab_albedo_of_row(sr) - albedo_of_row(hr)).abs() < 1e-12);
    let hs = table();
    let d_last = SLAB_THICKNESSES.len() - 1;
    for (e, &eta) in SLAB_ETAS.iter().enumerate() {
        let slab = raw();
        let sp = slab.plane(d_last, e);
        let hp = hs.planes.iter().find(|p| p.eta == eta).unwrap();
        let (a, sa) = (sp.total[sr], sp.total_se[sr]);
        let (b, sb) = (hp.total[N_ALBEDO + hr], hp.total_se[N_ALBEDO + hr]);
        let se = (sa * sa + sb * sb).sqrt();
        assert!(
            (a - b).abs() <= 4.0 * se,
            "η {eta}: slab {a} ± {sa}, half-space {b} ± {sb}"
        );
        // The transmission is small: of order e^{-σtr d} ≈ 1 % of the reflection.
        let t = sp.total[SLAB_ROWS + sr];
        assert!(t > 0.0 && t < 0.03 * a, "η {eta}: T {t}, R {a}");
        // Bins out to 3 mfp, where both are well resolved.
        for j in (1..N_BINS).filter(|&j| centre(j) < 3.0) {
            let x = sp.density[SlabPlane::index(0, sr, j)] as f64;
            let sx = sp.density_se[SlabPlane::index(0, sr, j)] as f64;
            let i = (N_ALBEDO + hr) * N_BINS + j;
            let (y, sy) = (hp.density[i] as f64, hp.density_se[i] as f64);
            let se = (sx * sx + sy * sy).sqrt();
            if se > 0.05 * y {
                continue; // too noisy to compare
            }
            assert!(
                (x - y).abs() <= 5.0 * se,
                "η {eta} bin {j}: {x} ± {sx}, {y} ± {sy}"
            );
        }
    }
}

#[test]
fn the_profile_is_the_table_at_its_planes_and_integrates_to_its_totals() {
    let t = slab_table();
    for (di, &d) in SLAB_THICKNESSES.iter().enumerate() {
        for (ei, &eta) in SLAB_ETAS.iter().enumerate() {
            let p = t.plane(di, ei);
            for row in [0, 5, 10] {
                let term = SlabTerm::new(1.0, slab_albedo_of_row(row), eta, d);
                for (f, face) in [SlabFace::Reflection, SlabFace::Transmission]
                    .into_iter()
                    .enumerate()
                {
                    let want = p.total[f * SLAB_ROWS + row];
                    let got = term.total(face);
                    assert!(
                        (got - want).abs() <= 1e-9 * want.max(1e-300),
                        "{d} {eta} {row}"
                    );
                    // The profile integrates to its total (which also counts exits beyond
                    // the last bin, which a slab never reaches).
                    let integral = radial_integral(|r| term.eval(face, r), 1.0);
                    assert!(
                        (integral - want).abs() <= 1e-3 * want + 1e-9,
                        "{d} {eta} {row} {f}: ∫ {integral} vs {want}"
                    );
                }
            }
        }
    }
}

/// Between the planes and rows the profile still integrates to its totals: the reflection
/// within 0.1 %, the transmission within 0.2 % (it is interpolated in radius per thickness
/// plane and row, then mixed; between η planes log–log interpolation of the mixed bins loses
/// up to 0.12 % of the transmission of slabs thicker than about 5 mean free paths).
#[test]
fn the_profile_integrates_to_its_totals_between_the_planes() {
    let mut worst = [0.0f64; 2];
    for d in [0.1, 0.6, 1.5, 3.0, 7.0, 12.0, 20.0] {
        for eta in [1.0, 1.22, 1.47] {
            for alpha in [0.2, 0.5, 0.77, 0.95, 0.999] {
                let term = SlabTerm::new(2.0, alpha, eta, d / 2.0);
                for (f, face) in [SlabFace::Reflection, SlabFace::Transmission]
                    .into_iter()
                    .enumerate()
                {
                    // Transmissions below 10⁻³ of the entering light (thick slabs of low
                    // albedo) are left out: their bins are sparse counts, and between η
                    // planes clamping their mixture at 0 adds up to 0.7 % of almost nothing
                    // (measured at 1–3·10⁻⁴; exact at the planes).
                    let total = term.total(face);
                    if total < 1e-3 {
                        continue;
                    }
                    let q = radial_integral(|r| term.eval(face, r), 2.0) / total;
                    worst[f] = worst[f].max((q - 1.0).abs());
                    assert!(
                        (q - 1.0).abs() < [1e-3, 2e-3][f],
                        "d {d} η {eta} α {alpha} {face:?}: ∫ = {q:.5} × total"
                    );
                }
            }
        }
    }
    eprintln!(
        "slab ∫ / total: reflection within {:.1e}, transmission within {:.1e}",
        worst[0], worst[1]
    );
}

#[test]
fn thickness_interpolation_is_continuous_and_reaches_the_half_space() {
    let (a, eta) = (0.99, 1.3);
    let t = |d: f64, face| SlabTerm::new(1.0, a, eta, d).total(face);
    for face in [SlabFace::Reflection, SlabFace::Transmission] {
        // Continuous across every plane and the ends of the blend.
        for &d in SLAB_THICKNESSES.iter().chain(&[32.0]) {
            let (lo, hi) = (t(d * (1.0 - 1e-9), face), t(d * (1.0 + 1e-9), face));
            let scale = t(d, SlabFace::Reflection);
            assert!((lo - hi).abs() <= 1e-6 * scale, "{d}: {lo} {hi}");
        }
        assert_eq!(t(0.0, face), 0.0);
    }
    // From 32 mfp on: the half-space table's multiple scattering, no transmission.
    let hs = bssrdf_core::tabulated::TabulatedTerm::new(1.0, a, eta, false, true);
    use bssrdf_core::RadialProfile;
    assert_eq!(t(32.0, SlabFace::Reflection), hs.total());
    assert_eq!(t(40.0, SlabFace::Transmission), 0.0);
    // Thinner slabs reflect less and (above the thinnest) transmit more than thicker ones
    // at α = 0.99 in this range.
    assert!(t(0.5, SlabFace::Reflection) < t(2.0, SlabFace::Reflection));
    assert!(t(2.0, SlabFace::Reflection) < t(8.0, SlabFace::Reflection));
    assert!(t(8.0, SlabFace::Transmission) < t(2.0, SlabFace::Transmission));
}
