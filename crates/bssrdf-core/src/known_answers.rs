//! Known-answer tests: every expected number comes from docs/physics.md's independently
//! computed [C] values or from a closed form / brute-force computation written in the test.

use crate::dipole::Dipole;
use crate::family::{FamilyOptions, ProfileFamily};
use crate::fresnel::DiffuseFresnel;
use crate::model::{ProfileModel, Scattering};
use crate::profile::RadialProfile;
use crate::test_util::brute_total;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn family(model: ProfileModel, sc: Scattering, eta: f64) -> ProfileFamily {
    ProfileFamily::new(model, sc, 0.0, eta).unwrap()
}

#[test]
fn dipole_spot_values_match_notes() {
    // docs/physics.md#dipole [computed]: σs' = 1, σa = 0.01; A = 1 (η = 1, exact) and A = 2.60206 (η = 1.3 fit).
    let spots = [
        (0.0, 9.315356e-2, 8.260529e-2),
        (0.5, 6.911931e-2, 5.945554e-2),
        (1.0, 3.786617e-2, 3.031243e-2),
        (2.0, 1.234990e-2, 9.020910e-3),
        (5.0, 1.275820e-3, 1.249951e-3),
        (10.0, 1.153581e-4, 1.521386e-4),
        (20.0, 4.355345e-6, 6.572948e-6),
    ];
    let exact = family(ProfileModel::Dipole, Scattering::Multiple, 1.0);
    let fit = ProfileFamily::with_options(
        ProfileModel::Dipole,
        Scattering::Multiple,
        0.0,
        1.3,
        FamilyOptions::new().with_diffuse_fresnel(DiffuseFresnel::JensenFit),
    )
    .unwrap();
    assert!(
        (fit.a_dipole() - 2.602064).abs() < 2e-6,
        "{}",
        fit.a_dipole()
    );
    let p1 = exact.profile(0.01, 1.0).unwrap();
    let p2 = fit.profile(0.01, 1.0).unwrap();
    for (r, a1, a2) in spots {
        assert!(
            rel(p1.eval(r), a1) < 1e-6,
            "A=1 r={r}: {} vs {a1}",
            p1.eval(r)
        );
        assert!(
            rel(p2.eval(r), a2) < 1e-5,
            "A=2.6 r={r}: {} vs {a2}",
            p2.eval(r)
        );
    }
}

#[test]
fn dipole_total_closed_form_and_numeric() {
    // docs/physics.md#dipole [computed] table of Rd_tot for α' ∈ {0.5, 0.9, 0.99, 0.999}.
    let table = [
        (1.0, 1.0, [0.087808, 0.385584, 0.746714, 0.912451]),
        (1.0, 1.003205, [0.087733, 0.385291, 0.746469, 0.912348]),
        (1.3, 2.600079, [0.074510, 0.299186, 0.644630, 0.863973]),
        (1.3, 2.602064, [0.074507, 0.299129, 0.644525, 0.863916]),
    ];
    for (_eta, a, vals) in table {
        for (alpha, want) in [0.5, 0.9, 0.99, 0.999].into_iter().zip(vals) {
            let got = Dipole::total_closed_form(alpha, a);
            assert!(
                (got - want).abs() < 1.5e-6,
                "A={a} α'={alpha}: {got} vs {want}"
            );
        }
    }
    // The profile's total equals the closed form, and so does a brute-force integral of eval
    // (independent Simpson quadrature in the test), to ≤ 1e-6 relative.
    for eta in [1.0, 1.3, 3.0] {
        let fam = family(ProfileModel::Dipole, Scattering::Multiple, eta);
        for (sa, ss) in [(0.5, 0.5), (0.01, 1.0), (1e-3, 2.0), (0.2, 30.0)] {
            let p = fam.profile(sa, ss).unwrap();
            let alpha = ss / (sa + ss);
            let closed = Dipole::total_closed_form(alpha, fam.a_dipole());
            assert!(rel(p.total(), closed) < 1e-12);
            let st = sa + ss;
            let brute = brute_total(&p, 1e-9 / st, 1e4 / st);
            assert!(
                rel(brute, closed) < 1e-6,
                "eta={eta} σ=({sa},{ss}): {brute} vs {closed}"
            );
        }
    }
}

#[test]
fn pbd_spot_values_match_notes_int_column() {
    // docs/physics.md#beam-diffusion [computed] "exact" columns (adaptive quadrature of the exact integrals), η = 1, g = 0.
    let spots = [
        (1.0, 0.01, 0.1, 2.176604e-1, 4.731028e-1),
        (1.0, 0.01, 0.5, 6.978296e-2, 2.989089e-2),
        (1.0, 0.01, 1.0, 3.252422e-2, 5.134430e-3),
        (1.0, 0.01, 2.0, 1.059152e-2, 4.422408e-4),
        (1.0, 0.01, 5.0, 1.139965e-3, 2.383837e-6),
        (1.0, 0.1, 1.0, 2.257545e-2, 4.323647e-3),
        (0.5, 0.5, 1.0, 3.531317e-3, 2.617396e-3),
    ];
    let ms = family(ProfileModel::Pbd, Scattering::Multiple, 1.0);
    let ss = family(ProfileModel::Pbd, Scattering::Single, 1.0);
    let all = family(ProfileModel::Pbd, Scattering::All, 1.0);
    for (s, a, r, want_ms, want_ss) in spots {
        let got_ms = ms.profile(a, s).unwrap().eval(r);
        let got_ss = ss.profile(a, s).unwrap().eval(r);
        let got_all = all.profile(a, s).unwrap().eval(r);
        assert!(
            rel(got_ms, want_ms) < 1e-5,
            "MS σ=({s},{a}) r={r}: {got_ms} vs {want_ms}"
        );
        assert!(
            rel(got_ss, want_ss) < 1e-5,
            "SS σ=({s},{a}) r={r}: {got_ss} vs {want_ss}"
        );
        assert!(rel(got_all, want_ms + want_ss) < 1e-5);
    }
}

#[test]
fn single_scattering_totals_are_exact() {
    // (ϖ/2)(1 − ln 2) for η = 1, g = 0 (docs/physics.md#beam-diffusion, #half-space), from the closed form and from a
    // brute-force radial integral of eval.
    let fam = family(ProfileModel::Pbd, Scattering::Single, 1.0);
    for w in [0.5, 0.9, 0.99, 0.999, 1.0] {
        let want = 0.5 * w * (1.0 - 2f64.ln());
        let p = fam.profile(1.0 - w, w).unwrap();
        assert!(rel(p.total(), want) < 1e-9, "ϖ={w}: {}", p.total());
        let brute = brute_total(&p, 1e-6, 60.0);
        assert!(rel(brute, want) < 2e-5, "ϖ={w}: brute {brute} vs {want}");
    }
    // HG single scattering at ϖ = 1 (docs/physics.md#half-space [derived, computed]).
    for (g, want) in [
        (-0.5, 0.323800),
        (0.0, 0.153426),
        (0.5, 0.046273),
        (0.9, 0.006057),
    ] {
        let fam = ProfileFamily::new(ProfileModel::Pbd, Scattering::Single, g, 1.0).unwrap();
        let got = fam.profile(0.0, 1.0).unwrap().total();
        assert!((got - want).abs() < 1.5e-6, "g={g}: {got} vs {want}");
    }
    // η > 1: closed form agrees with the brute-force integral of the profile.
    for (g, eta) in [(0.0, 1.3), (0.7, 1.5), (-0.3, 2.0)] {
        let fam = ProfileFamily::new(ProfileModel::Pbd, Scattering::Single, g, eta).unwrap();
        let p = fam.profile(0.1, 0.9).unwrap();
        let brute = brute_total(&p, 1e-6, 60.0);
        assert!(
            rel(brute, p.total()) < 1e-4,
            "g={g} η={eta}: {brute} vs {}",
            p.total()
        );
    }
}

#[test]
fn pbd_ms_totals_relate_to_notes() {
    // docs/physics.md#beam-diffusion [computed]: PBD-MS totals with pbrt's 100-midpoint depth rule. Ours integrates the
    // depth integral accurately; the rule's error is concentrated at r·σt < 0.1, which holds
    // little energy, so the totals still agree to the 5 digits given (±1e-5).
    let fam = family(ProfileModel::Pbd, Scattering::Multiple, 1.0);
    for (w, want) in [
        (0.5, 0.05124),
        (0.9, 0.33613),
        (0.99, 0.68920),
        (0.999, 0.85238),
    ] {
        let t = fam.profile(1.0 - w, w).unwrap().total();
        assert!((t - want).abs() < 1e-5, "ϖ={w}: {t} vs pbrt100 {want}");
    }
}

#[test]
fn better_dipole_total_matches_hery_formula_and_numeric() {
    for eta in [1.0, 1.33, 3.0] {
        let fam = family(ProfileModel::BetterDipole, Scattering::Multiple, eta);
        let m = fam.moments();
        let (two_c1, three_c2) = (2.0 * m.c1, 3.0 * m.c2);
        for (sa, ss) in [(0.5, 0.5), (0.01, 1.0), (0.0, 1.0), (1e-4, 3.0)] {
            let p = fam.profile(sa, ss).unwrap();
            // Hery's closed form in optical units (written independently here).
            let ap: f64 = ss / (sa + ss);
            let cphi = 0.25 * (1.0 - two_c1);
            let ce = 0.5 * (1.0 - three_c2);
            let four_a = (1.0 + three_c2) / cphi;
            let mu_tr_d = ((1.0 - ap) * (2.0 - ap) / 3.0).sqrt();
            let e = (-four_a * mu_tr_d).exp();
            let second = if mu_tr_d > 0.0 {
                cphi / mu_tr_d * (1.0 - e)
            } else {
                cphi * four_a
            };
            let want = 0.5
                * ap
                * ap
                * (-(3.0 * (1.0 - ap) / (2.0 - ap)).sqrt()).exp()
                * (ce * (1.0 + e) + second);
            assert!(
                rel(p.total(), want) < 1e-10,
                "η={eta} ({sa},{ss}): {} vs {want}",
                p.total()
            );
            if sa > 0.0 {
                let st = sa + ss;
                let brute = brute_total(&p, 1e-9 / st, 1e4 / st);
                assert!(
                    rel(brute, want) < 1e-6,
                    "η={eta} ({sa},{ss}): {brute} vs {want}"
                );
            }
        }
    }
}

#[test]
fn better_dipole_is_pbd_integrand_at_one_depth() {
    // dE12 as pinned down (see module docs and docs/physics.md#better-dipole): the PBD depth
    // integrand without κ, at the single depth z_r = 1/σt', with Grosjean's D_G and the A_PBD
    // boundary. Typed here from docs/physics.md#beam-diffusion (η = 1: c_φ = 1/4, c_E = 1/2,
    // A = 1) and compared to 1e-12: a wrong depth, D, boundary or prefactor fails. (The former
    // test only asked the ratio to PBD to lie in 0.7–1.3, which such errors could pass.)
    let bd = family(ProfileModel::BetterDipole, Scattering::Multiple, 1.0);
    for (sa, ss) in [(0.01, 1.0), (0.3, 0.7), (0.0, 2.0)] {
        let p = bd.profile(sa, ss).unwrap();
        let stp = sa + ss;
        let alpha = ss / stp;
        let d_g = (2.0 * sa + ss) / (3.0 * stp * stp);
        for r in [0.0, 0.1, 1.0, 2.0, 5.0, 10.0] {
            let want = alpha * alpha * pbd_source_exitance(r, 1.0 / stp, d_g, sa);
            assert!(
                rel(p.eval(r), want) < 1e-12,
                "({sa},{ss}) r={r}: {} vs {want}",
                p.eval(r)
            );
        }
    }
}

#[test]
fn pbd_far_field_decays_at_grosjean_sigma_tr() {
    // Diffusion theory: far from the beam every dipole term decays like e^{−σtr r}/r^k with
    // Grosjean's σtr = √(σa/D_G), D_G = (2σa + σs')/(3σt'²). With σa = σs = 0.5 it differs
    // from the classical √(3σaσt') by √1.5, so the test discriminates the two. We compare
    // the log-slope of r²·MS(r) between r = 20 and 40 mean free paths (the leading power
    // r⁻² of a dipole's flux far field removed), which approaches −σtr with an O(1/r)
    // correction: we allow 3 %.
    let fam = family(ProfileModel::Pbd, Scattering::Multiple, 1.0);
    let (sa, ss) = (0.5, 0.5);
    let p = fam.profile(sa, ss).unwrap();
    let d_g = (2.0 * sa + ss) / (3.0 * (sa + ss) * (sa + ss));
    let sigma_tr = (sa / d_g).sqrt();
    let classical = (3.0 * sa * (sa + ss)).sqrt();
    let (r1, r2) = (20.0, 40.0);
    let slope = -((r2 * r2 * p.eval(r2)).ln() - (r1 * r1 * p.eval(r1)).ln()) / (r2 - r1);
    assert!(
        rel(slope, sigma_tr) < 0.03,
        "slope {slope} vs σtr {sigma_tr}"
    );
    assert!(
        rel(slope, classical) > 0.1,
        "slope {slope} should not match classical {classical}"
    );
}

/// Independent brute-force PBD-MS at optical radius `x` (η = 1, g = 0, σt' = 1): composite
/// Simpson in `ln z` with 40 000 intervals over z ∈ [1e-9, 60], formulas typed from docs/physics.md#beam-diffusion.
fn pbd_ms_brute(x: f64, alpha: f64) -> f64 {
    let (sa, ssp) = (1.0 - alpha, alpha);
    let st = sa + ssp;
    let d_g = (2.0 * sa + ssp) / (3.0 * st * st);
    let f = |z: f64| {
        let dr = (x * x + z * z).sqrt();
        let kappa = 1.0 - (-2.0 * st * (dr + z)).exp();
        let rho = ssp / st;
        rho * rho * st * (-st * z).exp() * kappa * pbd_source_exitance(x, z, d_g, sa)
    };
    crate::test_util::simpson_log(f, 1e-9, 60.0, 40_000)
}

/// c_φ φ_D + c_E E_n of docs/physics.md#beam-diffusion for one source at depth `z`, at radius
/// `r`, with Grosjean's `d_g`, absorption `sa` and η = 1 (c_φ = 1/4, c_E = 1/2, A = 1).
fn pbd_source_exitance(r: f64, z: f64, d_g: f64, sa: f64) -> f64 {
    use std::f64::consts::PI;
    let s = (sa / d_g).sqrt();
    let (cphi, ce, a) = (0.25, 0.5, 1.0);
    let zv = -z - 4.0 * a * d_g;
    let dr = (r * r + z * z).sqrt();
    let dv = (r * r + zv * zv).sqrt();
    let phi = ((-s * dr).exp() / dr - (-s * dv).exp() / dv) / (4.0 * PI * d_g);
    let en = (z * (1.0 + s * dr) * (-s * dr).exp() / dr.powi(3)
        - zv * (1.0 + s * dv) * (-s * dv).exp() / dv.powi(3))
        / (4.0 * PI);
    cphi * phi + ce * en
}

#[test]
fn pbd_ms_small_radius_matches_brute_force() {
    let fam = family(ProfileModel::Pbd, Scattering::Multiple, 1.0);
    for alpha in [0.5, 0.99, 1.0] {
        let p = fam.profile(1.0 - alpha, alpha).unwrap();
        for x in [0.001, 0.01, 0.05, 0.3, 3.0] {
            let want = pbd_ms_brute(x, alpha);
            let tol = if x >= 0.01 { 1e-5 } else { 1e-4 };
            assert!(
                rel(p.eval(x), want) < tol,
                "α'={alpha} x={x}: {} vs {want}",
                p.eval(x)
            );
        }
    }
}

#[test]
fn single_scattering_matches_brute_force_at_small_and_large_radii() {
    // Independent brute force of docs/physics.md#beam-diffusion's SS integral (σt = 1), Simpson in ln(τ − τ_c).
    fn brute(x: f64, omega: f64, g: f64, eta: f64) -> f64 {
        let tc = x * (eta * eta - 1.0f64).sqrt();
        let f = |y: f64| {
            let t = tc + y;
            let d = (x * x + t * t).sqrt();
            let mu = t / d;
            let fr = crate::fresnel::dielectric(mu, 1.0 / eta);
            omega * (-(t + d)).exp() / (d * d) * crate::hg::phase(-mu, g) * (1.0 - fr) * mu
        };
        crate::test_util::simpson_log(f, 1e-12, 80.0, 60_000)
    }
    for (g, eta) in [(0.0, 1.0), (0.6, 1.0), (-0.4, 1.5), (0.3, 2.5)] {
        let fam = ProfileFamily::new(ProfileModel::Pbd, Scattering::Single, g, eta).unwrap();
        let p = fam.profile(0.2, 0.8).unwrap();
        for x in [0.001, 0.01, 0.1, 1.0, 4.0] {
            let want = brute(x, 0.8, g, eta);
            let tol = if x >= 0.01 { 1e-5 } else { 1e-4 };
            assert!(
                rel(p.eval(x), want) < tol,
                "g={g} η={eta} x={x}: {} vs {want}",
                p.eval(x)
            );
        }
    }
}

#[test]
fn profiles_obey_the_scaling_law() {
    // docs/physics.md#conventions: R(r; kσa, kσs) = k² R(kr; σa, σs), and totals are scale-invariant.
    for m in [
        ProfileModel::Dipole,
        ProfileModel::BetterDipole,
        ProfileModel::Pbd,
    ] {
        let fam = ProfileFamily::new(m, Scattering::All, 0.4, 1.4).unwrap();
        let base = fam.profile(0.03, 1.2).unwrap();
        for k in [1e-4, 0.3, 7.0, 1e5] {
            let scaled = fam.profile(0.03 * k, 1.2 * k).unwrap();
            for r in [0.05, 0.8, 6.0] {
                let (a, b) = (scaled.eval(r / k), k * k * base.eval(r));
                assert!(rel(a, b) < 1e-10, "{m} k={k} r={r}: {a} vs {b}");
                let (pa, pb) = (scaled.pdf_r(r / k), k * base.pdf_r(r));
                assert!(rel(pa, pb) < 1e-10, "{m} pdf k={k} r={r}");
            }
        }
    }
}
