//! Statistical tests of every radius sampler: chi-square (fixed seed, 2·10⁵ samples, bins
//! pooled to expected ≥ 5, family-wise significance 1e-4 per test function with the Šidák
//! correction, [`crate::chi_square`]) of `sample_r` against
//! `pdf_r`, whose bin probabilities are integrated independently (Simpson); plus exactness
//! checks of the densities and a negative control showing the test can fail.

use crate::chi_square::ChiSquareTest;
use crate::family::ProfileFamily;
use crate::model::{ProfileModel, Scattering};
use crate::profile::RadialProfile;
use crate::table::ProfileTable;
use crate::test_util::{Rng, chi_square, simpson_log};
use std::f64::consts::PI;

const N: usize = 200_000;

fn assert_chi2(name: &str, test: ChiSquareTest, p: &impl RadialProfile, sigma_t: f64, seed: u64) {
    let r = chi_square(
        test,
        p,
        |r| p.pdf_r(r),
        1e-3 / sigma_t,
        1e3 / sigma_t,
        N,
        seed,
    );
    assert!(r.passes(), "{name}: {r}");
    assert!(r.dof >= 20, "{name}: too few bins ({})", r.dof);
}

fn fam(model: ProfileModel, sc: Scattering, g: f64, eta: f64) -> ProfileFamily {
    ProfileFamily::new(model, sc, g, eta).unwrap()
}

#[test]
fn model_samplers_pass_chi_square() {
    let cases = [
        (
            ProfileModel::Dipole,
            Scattering::Multiple,
            0.0,
            1.3,
            0.01,
            1.0,
        ),
        (
            ProfileModel::Dipole,
            Scattering::Multiple,
            0.5,
            3.0,
            0.3,
            2.0,
        ),
        (
            ProfileModel::BetterDipole,
            Scattering::Multiple,
            0.0,
            1.0,
            0.05,
            1.0,
        ),
        (
            ProfileModel::Pbd,
            Scattering::Multiple,
            0.0,
            1.33,
            0.01,
            1.0,
        ),
        (ProfileModel::Pbd, Scattering::Single, 0.3, 1.5, 0.2, 1.0),
        (ProfileModel::Pbd, Scattering::All, 0.0, 1.0, 0.1, 0.9),
        (ProfileModel::Dipole, Scattering::All, -0.3, 1.2, 0.02, 4.0),
    ];
    let test = ChiSquareTest::family(1e-4, cases.len() as u32);
    for (k, (m, sc, g, eta, sa, ss)) in cases.into_iter().enumerate() {
        let p = fam(m, sc, g, eta).profile(sa, ss).unwrap();
        assert_chi2(
            &format!("{m} {sc} g={g} η={eta}"),
            test,
            &p,
            sa + ss,
            1000 + k as u64,
        );
    }
}

#[test]
fn dipole_densities_are_exactly_the_normalised_profile() {
    for m in [ProfileModel::Dipole, ProfileModel::BetterDipole] {
        let p = fam(m, Scattering::Multiple, 0.0, 1.4)
            .profile(0.02, 1.5)
            .unwrap();
        let t = p.total();
        for r in [0.0, 1e-3, 0.3, 1.0, 7.0, 40.0] {
            let want = 2.0 * PI * r * p.eval(r) / t;
            assert!(
                (p.pdf_r(r) - want).abs() <= 1e-12 * want.max(1e-300),
                "{m} r={r}"
            );
        }
        // radius_for_fraction is the exact quantile: the integral up to it is f·total.
        for f in [0.1, 0.5, 0.999] {
            let rf = p.radius_for_fraction(f);
            let inside = simpson_log(|r| 2.0 * PI * r * p.eval(r), 1e-9, rf, 20_000);
            assert!((inside / t - f).abs() < 1e-6, "{m} f={f}: {}", inside / t);
        }
    }
}

#[test]
fn chi_square_detects_a_wrong_density() {
    // Negative control: samples from α' = 0.9 tested against the density of α' = 0.8.
    let f = fam(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.0);
    let sampler = f.profile(0.1, 0.9).unwrap();
    let other = f.profile(0.2, 0.8).unwrap();
    let r = chi_square(
        ChiSquareTest::SINGLE,
        &sampler,
        |r| other.pdf_r(r),
        1e-3,
        1e3,
        N,
        7,
    );
    assert!(
        !r.passes(),
        "the chi-square test must reject a wrong density ({r})"
    );
}

#[test]
fn table_samplers_pass_chi_square_and_are_consistent() {
    // 3 families × 3 coefficient pairs.
    let test = ChiSquareTest::family(1e-4, 9);
    for (k, (m, sc, g, eta)) in [
        (ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.3),
        (ProfileModel::Pbd, Scattering::All, 0.5, 1.0),
        (ProfileModel::BetterDipole, Scattering::Multiple, -0.2, 2.0),
    ]
    .into_iter()
    .enumerate()
    {
        let family = fam(m, sc, g, eta);
        let table = ProfileTable::new(family);
        // Between albedo rows, on a row (σa = 0: α' = 1) and at an extreme scale.
        for (j, (sa, ss)) in [(0.013, 1.0), (0.0, 2.0), (3e4, 2e5)]
            .into_iter()
            .enumerate()
        {
            let s = table.sampler(sa, ss).unwrap();
            let st = sa + ss;
            assert_chi2(
                &format!("table {m} {sc} ({sa},{ss})"),
                test,
                &s,
                st,
                77 + 10 * k as u64 + j as u64,
            );
            // pdf integrates to 1 and eval is consistent with total.
            let (lo, hi) = (1e-9 / st, 1e9 / st);
            let mass = simpson_log(|r| s.pdf_r(r), lo, hi, 40_000);
            assert!((mass - 1.0).abs() < 1e-4, "{m}: pdf mass {mass}");
            let tot = simpson_log(|r| 2.0 * PI * r * s.eval(r), lo, hi, 40_000);
            assert!((tot / s.total() - 1.0).abs() < 1e-4, "{m}: eval/total");
            // radius_for_fraction inverts the sampler's CDF.
            for f in [0.3, 0.9, 0.999] {
                let rf = s.radius_for_fraction(f);
                let cdf = simpson_log(|r| s.pdf_r(r), lo, rf, 40_000);
                assert!((cdf - f).abs() < 1e-4, "{m} f={f}: {cdf}");
            }
        }
    }
}

#[test]
fn table_totals_track_the_exact_model() {
    let family = fam(ProfileModel::Pbd, Scattering::Multiple, 0.0, 1.33);
    let table = ProfileTable::new(family);
    for (sa, ss) in [
        (0.5, 0.5),
        (0.1, 0.9),
        (0.01, 0.99),
        (1e-3, 1.0),
        (0.0, 1.0),
    ] {
        let exact = family.profile(sa, ss).unwrap().total();
        let tab = table.sampler(sa, ss).unwrap().total();
        assert!(
            (tab - exact).abs() < 1e-3 * exact.max(0.05),
            "({sa},{ss}): {tab} vs {exact}"
        );
    }
    // ρ_eff inversion round trip.
    for alpha in [0.3, 0.9, 0.999] {
        let rho = table.rho_eff(alpha);
        assert!(
            (table.invert_rho_eff(rho) - alpha).abs() < 1e-6,
            "α'={alpha}"
        );
    }
}

#[test]
fn samplers_are_monotone_in_u() {
    let family = fam(ProfileModel::Pbd, Scattering::Multiple, 0.0, 1.0);
    let p = family.profile(0.05, 1.0).unwrap();
    let mut rng = Rng::new(3);
    let mut us: Vec<f64> = (0..2000).map(|_| rng.uniform()).collect();
    us.sort_by(f64::total_cmp);
    // PBD's proposal picks its component by splitting u: monotone within the first part.
    let mut last = 0.0;
    for &u in us.iter().filter(|&&u| u < 0.85) {
        let r = p.sample_r(u).unwrap();
        assert!(r >= last);
        last = r;
    }
}
