//! The tabulated half-space profile against exact transport: its data file, its totals at
//! η = 1 (Chandrasekhar), its single scattering at η = 1.3 (the exact single-scattering
//! integral of `bssrdf-core`, computed independently of the simulation), and the profile built
//! on it.

use bssrdf_core::tabulated::file::TableData;
use bssrdf_core::tabulated::grid::{ETAS, N_ALBEDO, S_MIN, albedo_of_row};
use bssrdf_core::tabulated::half_space::table;
use bssrdf_core::{ProfileFamily, ProfileModel, RadialProfile, Scattering};

use crate::common::chandrasekhar::{half_space_albedo, single_scattering_albedo};
use crate::common::radial::radial_integral;

const DATA: &[u8] = include_bytes!("../crates/bssrdf-core/data/halfspace-profile-v1.bin");

#[test]
fn the_data_file_round_trips_and_records_its_provenance() {
    let t = TableData::from_bytes(DATA).unwrap();
    assert_eq!(t.to_bytes(), DATA, "the format round-trips bit for bit");
    assert_eq!(t.planes.len(), ETAS.len());
    assert!(
        t.photons >= 1_000_000,
        "only {} photons per plane",
        t.photons
    );
    for p in &t.planes {
        assert!(
            (p.capped as f64) < 0.02 * t.photons as f64,
            "{} capped",
            p.capped
        );
    }
    // Corrupt files are errors, not panics.
    assert!(TableData::from_bytes(&DATA[..DATA.len() - 1]).is_err());
    assert!(TableData::from_bytes(b"HBSSRDFT").is_err());
    let mut bad = DATA.to_vec();
    bad[0] = b'X';
    assert!(TableData::from_bytes(&bad).is_err());
}

#[test]
fn index_matched_totals_match_chandrasekhar() {
    // A(α) = 1 − H(1)√(1 − α) and R_ss = (α/2)(1 − ln 2), at 4 standard errors of the table.
    // Paths cut at the event cap lose at most e^{-2.5} of ~1 % of the paths at the largest
    // albedo row: a bias allowance of 1e-3 there (none is needed below α = 0.9999).
    let plane = &table().planes[0];
    assert_eq!(plane.eta, 1.0);
    let mut checked = 0;
    for row in 0..N_ALBEDO {
        let alpha = albedo_of_row(row);
        if !(0.3..=0.9999).contains(&alpha) {
            continue;
        }
        let (ss, ms) = (plane.total[row], plane.total[N_ALBEDO + row]);
        let (se_ss, se_ms) = (plane.total_se[row], plane.total_se[N_ALBEDO + row]);
        let want = half_space_albedo(alpha);
        let se = (se_ss * se_ss + se_ms * se_ms).sqrt();
        assert!(
            (ss + ms - want).abs() < 4.0 * se + 2e-4,
            "α {alpha}: total {} ± {se}, exact {want}",
            ss + ms
        );
        let want_ss = single_scattering_albedo(alpha);
        assert!(
            (ss - want_ss).abs() < 4.0 * se_ss,
            "α {alpha}: single {ss} ± {se_ss}, exact {want_ss}"
        );
        assert!(se < 2e-3, "table too noisy: {se}");
        checked += 1;
    }
    assert!(checked >= 15, "{checked} rows checked");
}

#[test]
fn refractive_single_scattering_matches_the_exact_integral() {
    // At η = 1.3 the single-scattering total, with Fresnel at the exit, is an exact integral
    // (bssrdf-core's single-scattering term); the table's comes from the photon simulation.
    let plane_index = ETAS.iter().position(|&e| e == 1.3).unwrap();
    let plane = &table().planes[plane_index];
    for row in [5usize, 15, 25, 33] {
        let alpha = albedo_of_row(row);
        let family = ProfileFamily::new(ProfileModel::Pbd, Scattering::Single, 0.0, 1.3).unwrap();
        let exact = family.profile(1.0 - alpha, alpha).unwrap().total();
        let (got, se) = (plane.total[row], plane.total_se[row]);
        assert!(
            (got - exact).abs() < 4.0 * se + 2e-3 * exact,
            "α {alpha}: table {got} ± {se}, exact {exact}"
        );
    }
}

/// Between the albedo rows (issue 38): the profile's total, multiple scattering alone and all
/// orders, at η = 1 against Chandrasekhar's (the H-function of `tests/common`, independent of
/// the table): 20 albedos from 0.2 to 0.999, geometric in 1 − α and none on a row, within
/// 0.5 %. Interpolated linearly in log √(1 − α), as the rows were before, the multiple
/// scattering was 2.6 % high at α = 0.5, 10 % at 0.3 and 20 % at 0.2.
#[test]
fn totals_between_rows_match_chandrasekhar() {
    let family = |sc| ProfileFamily::new(ProfileModel::Tabulated, sc, 0.0, 1.0).unwrap();
    let (all, multiple) = (family(Scattering::All), family(Scattering::Multiple));
    let n = 20;
    let mut worst: f64 = 0.0;
    for k in 0..n {
        // 1 − α from 0.8 to 0.00106, geometric: α from 0.2 to 0.99894, every one at least 4 %
        // of a row spacing from the nearest row (rows are uniform in log √(1 − α)).
        let alpha = 1.0 - 0.8 * (0.00106f64 / 0.8).powf(k as f64 / (n - 1) as f64);
        let position =
            ((1.0 - alpha).sqrt() / S_MIN).ln() / (1.0 / S_MIN).ln() * (N_ALBEDO - 1) as f64;
        let off_row = (position - position.round()).abs();
        assert!(off_row > 0.04, "α {alpha} is on a row ({position})");
        let exact_all = half_space_albedo(alpha);
        let exact_ms = exact_all - single_scattering_albedo(alpha);
        // Any σt: the totals depend on the albedo alone.
        let (sa, ss) = (3.0 * (1.0 - alpha), 3.0 * alpha);
        for (what, got, want) in [
            ("all", all.profile(sa, ss).unwrap().total(), exact_all),
            (
                "multiple",
                multiple.profile(sa, ss).unwrap().total(),
                exact_ms,
            ),
        ] {
            let e = got / want - 1.0;
            worst = worst.max(e.abs());
            assert!(
                e.abs() < 5e-3,
                "α {alpha:.5}, {what}: total {got:.6}, Chandrasekhar {want:.6} ({:+.2} %)",
                100.0 * e
            );
        }
    }
    eprintln!(
        "totals between rows at η = 1: largest error {:.3} %",
        100.0 * worst
    );
}

/// The profile integrates to its total within 0.1 % (issue 38; log–log interpolation between
/// bin centres had put ∫ 2πr R(r) dr at 0.9965 of the total everywhere): every order, η on and
/// between the planes, albedos on and between the rows (0.05 to 0.99999), g = 0 and 0.5. And
/// `sample_r` and `pdf_r` describe the same density.
#[test]
fn the_profile_integrates_to_its_total_and_samples_its_own_density() {
    let mut worst: f64 = 0.0;
    for sc in [Scattering::Multiple, Scattering::All, Scattering::Single] {
        for eta in [1.0, 1.12, 1.3, 1.47, 1.6] {
            for g in [0.0, 0.5] {
                let family = ProfileFamily::new(ProfileModel::Tabulated, sc, g, eta).unwrap();
                for alpha in [0.05, 0.2, 0.5, 0.77, 0.9, 0.99, 0.9995, 0.99999] {
                    let st = 2.0;
                    let (sa, ss) = (st * (1.0 - alpha), st * alpha);
                    let p = family.profile(sa, ss).unwrap();
                    // The optical unit of the radial shape: σt' = σa + (1 − g)σs.
                    let integral = radial_integral(|r| p.eval(r), sa + (1.0 - g) * ss);
                    let q = integral / p.total();
                    worst = worst.max((q - 1.0).abs());
                    assert!(
                        (q - 1.0).abs() < 1e-3,
                        "{sc}, η {eta}, g {g}, α {alpha}: ∫ = {q:.5} × total"
                    );
                }
            }
        }
    }
    eprintln!("∫ 2πr R dr / total: largest deviation {worst:.1e}");
    for (eta, sc) in [
        (1.0, Scattering::Multiple),
        (1.3, Scattering::All),
        (1.22, Scattering::Single),
    ] {
        let family = ProfileFamily::new(ProfileModel::Tabulated, sc, 0.0, eta).unwrap();
        for (sa, ss) in [(0.01, 1.0), (0.001, 2.0), (0.3, 1.0)] {
            let p = family.profile(sa, ss).unwrap();
            // sample_r and pdf_r agree: E[1/pdf(r)] over samples in the first half of the CDF
            // is ∫ over that range = its radius, and radius_for_fraction inverts the CDF.
            let r_half = p.radius_for_fraction(0.5);
            let mut below = 0;
            let n = 20_000;
            for k in 0..n {
                let u = (k as f64 + 0.5) / n as f64;
                let r = p.sample_r(u).unwrap();
                assert!(p.pdf_r(r) > 0.0, "pdf 0 at its own sample {r}");
                below += usize::from(r <= r_half);
            }
            assert!(
                (below as f64 / n as f64 - 0.5).abs() < 2e-3,
                "η {eta} {sc}: {below} of {n} below the median"
            );
        }
    }
    // Outside the table's η range the family is a typed error.
    assert!(ProfileFamily::new(ProfileModel::Tabulated, Scattering::All, 0.0, 1.7).is_err());
}

/// The anisotropic half-space's plane albedo (`bssrdf_core::half_space_albedo`, adding–
/// doubling), which sets the tabulated profile's totals at g ≠ 0, against two independent
/// computations at g = 0, where they must agree: Chandrasekhar's H-function at η = 1 (every
/// albedo of the test above), and the photon table's totals at the other η planes (every
/// third plane, every albedo row from 0.3 to 0.9999, within 4 standard errors of the table
/// plus 2·10⁻⁴, the allowance of `index_matched_totals_match_chandrasekhar`).
#[test]
fn doubling_agrees_with_chandrasekhar_and_the_photon_table() {
    use bssrdf_core::half_space_albedo::plane_albedo;
    for k in 0..20 {
        let alpha = 1.0 - 0.8 * (0.001f64 / 0.8).powf(k as f64 / 19.0);
        let (got, want) = (plane_albedo(alpha, 0.0, 1.0), half_space_albedo(alpha));
        assert!((got - want).abs() < 1e-5, "α {alpha}: {got} vs {want}");
    }
    let mut worst: f64 = 0.0;
    for plane in table().planes.iter().step_by(3).skip(1) {
        for row in 0..N_ALBEDO {
            let alpha = albedo_of_row(row);
            if !(0.3..=0.9999).contains(&alpha) {
                continue;
            }
            let want = plane.total[row] + plane.total[N_ALBEDO + row];
            let se = plane.total_se[row].hypot(plane.total_se[N_ALBEDO + row]);
            let got = plane_albedo(alpha, 0.0, plane.eta);
            worst = worst.max((got - want).abs() / se);
            assert!(
                (got - want).abs() < 4.0 * se + 2e-4,
                "η {}, α {alpha}: doubling {got}, table {want} ± {se}",
                plane.eta
            );
        }
    }
    eprintln!("doubling against the photon table: largest |z| {worst:.2}");
}

/// What "multiple" means at g ≠ 0 (issue 38): the orders the path tracer counts, two or more
/// scattering events in the real Henyey–Greenstein medium. The profile's single scattering is
/// the exact single-scattering term of the real medium (`SingleScattering`, the same as the
/// other models'), its multiple scattering the anisotropic plane albedo minus that term, and
/// all orders their sum, for the half-space and for a thick slab alike.
#[test]
fn anisotropic_orders_add_up_to_the_anisotropic_albedo() {
    use bssrdf_core::SlabFace;
    use bssrdf_core::half_space_albedo::plane_albedo;
    for (g, eta) in [(0.3, 1.0), (0.6, 1.3), (-0.3, 1.45)] {
        let family = |m, sc| ProfileFamily::new(m, sc, g, eta).unwrap();
        for omega in [0.5, 0.9, 0.99] {
            let (sa, ss) = (1.0 - omega, omega);
            let total = |sc| {
                family(ProfileModel::Tabulated, sc)
                    .profile(sa, ss)
                    .unwrap()
                    .total()
            };
            let (single, multiple, all) = (
                total(Scattering::Single),
                total(Scattering::Multiple),
                total(Scattering::All),
            );
            let exact_single = family(ProfileModel::Pbd, Scattering::Single)
                .profile(sa, ss)
                .unwrap()
                .total();
            assert_eq!(single, exact_single, "g {g} ϖ {omega}");
            assert!((single + multiple - all).abs() < 1e-12, "g {g} ϖ {omega}");
            // Between rows the totals are interpolated (cubic in log √(1 − ϖ)).
            let want = plane_albedo(omega, g, eta);
            assert!(
                (all - want).abs() < 1e-3 * want,
                "g {g} η {eta} ϖ {omega}: {all} vs {want}"
            );
            let slab = family(ProfileModel::Tabulated, Scattering::All)
                .slab(sa, ss, 1e6)
                .unwrap()
                .unwrap();
            let r = slab.total(SlabFace::Reflection);
            assert!((r - all).abs() < 1e-12 * all, "slab {r} vs {all}");
        }
    }
}

#[test]
fn eta_interpolation_is_exact_at_the_planes_and_continuous_between() {
    let total = |eta: f64| {
        let f = ProfileFamily::new(ProfileModel::Tabulated, Scattering::All, 0.0, eta).unwrap();
        f.profile(0.002, 1.0).unwrap().total()
    };
    // At a plane and an albedo row the profile's total is the stored one.
    let row = 12;
    let alpha = albedo_of_row(row);
    for (k, &eta) in ETAS.iter().enumerate() {
        let f = ProfileFamily::new(ProfileModel::Tabulated, Scattering::All, 0.0, eta).unwrap();
        let got = f.profile(1.0 - alpha, alpha).unwrap().total();
        let plane = &table().planes[k];
        let want = plane.total[row] + plane.total[N_ALBEDO + row];
        assert!((got - want).abs() < 1e-9 * want, "η {eta}: {got} vs {want}");
        // Approaching a plane from both sides gives its value (continuity across stencils).
        for d in [1e-9, -1e-9] {
            let e = (eta + d).clamp(1.0, 1.6);
            assert!((total(e) - total(eta)).abs() < 1e-6, "η {eta}{d:+e}");
        }
    }
    // Between planes the totals stay between smooth bounds (no overshoot beyond 1 %).
    let (lo, hi) = (total(1.0).min(total(1.6)), total(1.0).max(total(1.6)));
    for k in 0..=60 {
        let e = 1.0 + 0.01 * k as f64;
        let t = total(e);
        assert!(t > 0.99 * lo && t < 1.01 * hi, "η {e}: {t}");
    }
}

/// Interpolation in η is within the table's noise. Each plane is predicted from its
/// neighbours at *twice* the table's spacing (leave-one-out: cubic through the planes at
/// offsets −3, −1, +1, +3 in the interior, quadratic through −1, +1, +3 or −3, −1, +1 next to
/// the ends, the stencils the profile uses) and compared with the stored plane, total
/// reflectance per albedo row, at 4 standard errors of the difference (the planes are
/// simulated with independent streams). A cubic's error grows as the fourth power of the
/// spacing and a quadratic's as the third, so passing at twice the spacing bounds the error at
/// the real spacing by 1/16 (1/8 next to the ends) of these tolerances: well below the noise.
#[test]
fn eta_interpolation_is_within_the_noise() {
    let planes = &table().planes;
    let n = planes.len();
    assert!(n >= 9, "too few η planes ({n}) for the check");
    let total = |k: usize, row: usize| {
        let p = &planes[k];
        let t = p.total[row] + p.total[N_ALBEDO + row];
        let se = p.total_se[row].hypot(p.total_se[N_ALBEDO + row]);
        (t, se)
    };
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for (k, plane) in planes.iter().enumerate().take(n - 1).skip(1) {
        // (offset, weight) of the stencil predicting offset 0.
        let stencil: &[(isize, f64)] = if k >= 3 && k + 3 < n {
            &[
                (-3, -1.0 / 16.0),
                (-1, 9.0 / 16.0),
                (1, 9.0 / 16.0),
                (3, -1.0 / 16.0),
            ]
        } else if k < 3 {
            &[(-1, 3.0 / 8.0), (1, 3.0 / 4.0), (3, -1.0 / 8.0)]
        } else {
            &[(-3, -1.0 / 8.0), (-1, 3.0 / 4.0), (1, 3.0 / 8.0)]
        };
        for row in 0..N_ALBEDO {
            let (want, se_want) = total(k, row);
            let (mut got, mut var) = (0.0, se_want * se_want);
            for &(off, w) in stencil {
                let (t, se) = total((k as isize + off) as usize, row);
                got += w * t;
                var += (w * se).powi(2);
            }
            let z = (got - want) / var.sqrt().max(1e-12);
            worst = worst.max(z.abs());
            checked += 1;
            assert!(
                z.abs() < 4.0,
                "η {} α {}: predicted {got} from twice the spacing, stored {want} (z = {z:.2})",
                plane.eta,
                albedo_of_row(row)
            );
        }
    }
    assert!(checked > 300, "{checked}");
    eprintln!("η leave-one-out at twice the spacing: worst |z| = {worst:.2} over {checked}");
}

/// The angular coupling's data (`bssrdf_core::tabulated::angular_file`) at η = 1 against
/// Chandrasekhar's diffuse reflection law for isotropic scattering, I(μ, μ0) = ϖ μ0 H(μ) H(μ0)
/// / (4π (μ + μ0)) per unit normal irradiance (Cha50, computed independently in
/// `tests/common/chandrasekhar.rs`): the power falling from cosine bin j that leaves into bin k
/// is P_jk = N ∫_j d(μ0²) ∫_k d(μ²) ϖ H(μ) H(μ0) / (4 (μ + μ0)), and ϖ / (4 (μ + μ0)) for
/// single scattering alone. Every bin pair of every row with 0.3 ≤ α ≤ 0.999, at 5 standard
/// errors of the data.
#[test]
fn angular_coupling_data_matches_chandrasekhar_at_eta_one() {
    use bssrdf_core::tabulated::angular::angular_data;
    use bssrdf_core::tabulated::angular_file::{N_MU, index};

    let plane = &angular_data().planes[0];
    assert_eq!(plane.eta, 1.0);
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    for row in 0..N_ALBEDO {
        let alpha = albedo_of_row(row);
        if !(0.3..=0.999).contains(&alpha) {
            continue;
        }
        let exact = ExactPairs::new(alpha);
        for j in 0..N_MU {
            for k in 0..N_MU {
                let (all, single) = exact.at(j, k);
                let (ss, ms) = (index(0, row, j, k), index(1, row, j, k));
                let got_ss = f64::from(plane.p[ss]);
                let se_ss = f64::from(plane.p_se[ss]);
                let got = got_ss + f64::from(plane.p[ms]);
                let se = (se_ss.powi(2) + f64::from(plane.p_se[ms]).powi(2)).sqrt();
                for (what, g, e, s) in [("all", got, all, se), ("single", got_ss, single, se_ss)] {
                    let z = (g - e).abs() / (s + 1e-9);
                    worst = worst.max(z);
                    assert!(
                        z < 5.0,
                        "α {alpha:.5}, bins ({j}, {k}), {what}: {g:.6} ± {s:.2e}, exact {e:.6}"
                    );
                }
                checked += 1;
            }
        }
    }
    assert!(
        checked >= 20 * N_MU * N_MU,
        "only {checked} bin pairs checked"
    );
    eprintln!("angular coupling at η = 1: {checked} bin pairs, largest |z| {worst:.2}");
}

/// Chandrasekhar's bin-pair fractions at η = 1 for one albedo (see
/// `angular_coupling_data_matches_chandrasekhar_at_eta_one`): per pair (j, k) of the coupling's
/// cosine bins, all orders and single scattering.
struct ExactPairs {
    /// `[j·N + k]`: (all orders, single scattering).
    p: Vec<(f64, f64)>,
}

impl ExactPairs {
    fn new(alpha: f64) -> Self {
        use bssrdf_core::tabulated::angular_file::N_MU;

        use crate::common::chandrasekhar::{gauss_legendre, h_function};

        // Gauss–Legendre in μ over each bin (d(μ²) = 2μ dμ keeps the integrand smooth).
        let (x, w) = gauss_legendre(12);
        let nodes = |j: usize| -> Vec<(f64, f64)> {
            let (a, b) = (
                (j as f64 / N_MU as f64).sqrt(),
                ((j + 1) as f64 / N_MU as f64).sqrt(),
            );
            x.iter()
                .zip(&w)
                .map(|(&t, &wt)| {
                    let mu = a + (b - a) * t;
                    (mu, wt * (b - a) * 2.0 * mu)
                })
                .collect()
        };
        let h = h_function(alpha);
        let mut p = Vec::with_capacity(N_MU * N_MU);
        for j in 0..N_MU {
            for k in 0..N_MU {
                let (mut all, mut single) = (0.0, 0.0);
                for &(mu0, w0) in &nodes(j) {
                    for &(mu, wk) in &nodes(k) {
                        let s = alpha / (4.0 * (mu + mu0)) * w0 * wk * N_MU as f64;
                        single += s;
                        all += s * h(mu) * h(mu0);
                    }
                }
                p.push((all, single));
            }
        }
        Self { p }
    }

    /// (all orders, single scattering) of bins (`j`, `k`).
    fn at(&self, j: usize, k: usize) -> (f64, f64) {
        self.p[j * bssrdf_core::tabulated::angular_file::N_MU + k]
    }
}

/// The coupling as the renderer reads it (`AngularCoupling::factor`: symmetrised, normalised,
/// interpolated) against Chandrasekhar at η = 1, where the separable lobes are uniform
/// (c = 1, no Fresnel): at the bins' centres, T(j, k) / T(N−1, N−1) must equal the exact
/// P_jk / P_(N−1)(N−1), the normalisation cancelling; for all orders and for multiple
/// scattering alone (all − single), at every albedo row from 0.3 to 0.999, within 5 standard
/// errors of the data. The exact ratios span more than 25 % at α = 0.9, so a coupling of ones
/// fails. The ratios are blind to the coupling's level, which
/// `angular_coupling_gives_the_exact_response_to_a_uniform_sky` checks.
#[test]
fn angular_coupling_as_read_matches_chandrasekhar_at_eta_one() {
    use bssrdf_core::tabulated::AngularCoupling;
    use bssrdf_core::tabulated::angular::angular_data;
    use bssrdf_core::tabulated::angular_file::{N_MU, index};

    let plane = &angular_data().planes[0];
    let top = N_MU - 1;
    let centre = |j: usize| ((j as f64 + 0.5) / N_MU as f64).sqrt();
    let mut worst: f64 = 0.0;
    let mut spread: f64 = 0.0;
    for (scattering, kinds) in [
        (bssrdf_core::Scattering::All, &[0, 1][..]),
        (bssrdf_core::Scattering::Multiple, &[1][..]),
    ] {
        let coupling = AngularCoupling::new(1.0, scattering);
        let single = scattering.includes_single();
        for row in 0..N_ALBEDO {
            let alpha = albedo_of_row(row);
            if !(0.3..=0.999).contains(&alpha) {
                continue;
            }
            let exact = ExactPairs::new(alpha);
            let exact_at = |j, k| {
                let (all, ss) = exact.at(j, k);
                if single { all } else { all - ss }
            };
            // The data's value and variance of a symmetrised pair.
            let data = |j: usize, k: usize| -> (f64, f64) {
                let cell = |a, b| -> (f64, f64) {
                    kinds.iter().fold((0.0, 0.0), |(v, var), &kind| {
                        let i = index(kind, row, a, b);
                        let se = f64::from(plane.p_se[i]);
                        (v + f64::from(plane.p[i]), var + se * se)
                    })
                };
                let ((v1, s1), (v2, s2)) = (cell(j, k), cell(k, j));
                (0.5 * (v1 + v2), 0.25 * (s1 + s2))
            };
            let t_top = coupling.factor(alpha, centre(top), centre(top));
            let (d_top, var_top) = data(top, top);
            for j in 0..N_MU {
                for k in j..N_MU {
                    let got = coupling.factor(alpha, centre(j), centre(k)) / t_top;
                    let want = exact_at(j, k) / exact_at(top, top);
                    let (d, var) = data(j, k);
                    let rel_se = (var / (d * d) + var_top / (d_top * d_top)).sqrt();
                    let z = (got / want - 1.0).abs() / rel_se;
                    worst = worst.max(z);
                    spread = spread.max((want - 1.0).abs());
                    assert!(
                        z < 5.0,
                        "α {alpha:.5}, single {single}, bins ({j}, {k}): T ratio {got:.4}, \
                         exact {want:.4} (z {z:.2})"
                    );
                }
            }
        }
    }
    assert!(
        spread > 0.25,
        "the exact ratios barely vary ({spread}): the test is weak"
    );
    eprintln!("angular coupling as read at η = 1: largest |z| {worst:.2}");
}

/// The coupling's absolute level (issue 38: the test above compares ratios of T, in which a
/// wrong normalisation cancels). Under a uniform sky of radiance 1, the renderer's half-space
/// sends toward the external cosine μ_o the radiance
/// R_tot (1 − F(μ_o)) ∫₀¹ (1 − F(μ)) T(μ, μ_o) d(μ²) / c (the separable lobes times T,
/// integrated over the incidence; R_tot the profile's total, c = 1 − 2 C₁(1/η)), and the
/// exact half-space sends (1 − F(μ_o)) A(μ_t), A(μ_t) its albedo per unit power entering
/// along the refracted cosine μ_t (reciprocity). A is computed independently of the photon
/// data, by adding–doubling (`plane_albedo_entering`, which matches Chandrasekhar's oblique
/// albedos; docs/physics.md#half-space); for multiple scattering alone minus the exact
/// single scattering (α/2)∫(1 − F(μ)) μ/(μ + μ_t) dμ. At η 1, 1.3 and 1.6, all orders and
/// multiple scattering, every other albedo row from 0.3 to 0.999 and every bin centre of μ_o:
/// within 1.5 %, and 4 % in the most grazing exit bin at η = 1, where bilinear interpolation
/// of bin means cannot follow H(μ)'s steep rise (measured: 3.4 %; elsewhere at most 1.05 %).
#[test]
fn angular_coupling_gives_the_exact_response_to_a_uniform_sky() {
    use bssrdf_core::fresnel::{dielectric, fresnel_moment};
    use bssrdf_core::half_space_albedo::plane_albedo_entering;
    use bssrdf_core::tabulated::AngularCoupling;
    use bssrdf_core::tabulated::angular_file::N_MU;

    let mut worst: f64 = 0.0;
    for eta in [1.0, 1.3, 1.6] {
        let c = 1.0 - 2.0 * fresnel_moment(1, 1.0 / eta);
        for (single, sc) in [(true, Scattering::All), (false, Scattering::Multiple)] {
            let coupling = AngularCoupling::new(eta, sc);
            let family = ProfileFamily::new(ProfileModel::Tabulated, sc, 0.0, eta).unwrap();
            for row in (0..N_ALBEDO).step_by(2) {
                let alpha = albedo_of_row(row);
                if !(0.3..=0.999).contains(&alpha) {
                    continue;
                }
                let r_tot = family.profile(1.0 - alpha, alpha).unwrap().total();
                for k in 0..N_MU {
                    let mu_o = ((k as f64 + 0.5) / N_MU as f64).sqrt();
                    let mu_t = (1.0 - (1.0 - mu_o * mu_o) / (eta * eta)).sqrt();
                    // ∫ d(μ²) by 4,096 midpoints in μ².
                    let n = 4096;
                    let got = r_tot / c
                        * (0..n)
                            .map(|m| {
                                let mu = ((m as f64 + 0.5) / n as f64).sqrt();
                                (1.0 - dielectric(mu, eta)) * coupling.factor(alpha, mu, mu_o)
                            })
                            .sum::<f64>()
                        / n as f64;
                    let mut want = plane_albedo_entering(alpha, eta, mu_t);
                    if !single {
                        let m = 20_000;
                        want -= 0.5
                            * alpha
                            * (0..m)
                                .map(|i| {
                                    let mu = (i as f64 + 0.5) / m as f64;
                                    (1.0 - dielectric(mu, 1.0 / eta)) * mu / (mu + mu_t)
                                })
                                .sum::<f64>()
                            / m as f64;
                    }
                    let e = got / want - 1.0;
                    let tol = if eta == 1.0 && k == 0 { 0.04 } else { 0.015 };
                    if !(eta == 1.0 && k == 0) {
                        worst = worst.max(e.abs());
                    }
                    assert!(
                        e.abs() < tol,
                        "η {eta}, single {single}, α {alpha:.5}, μ_o {mu_o:.3}: renderer \
                         {got:.5}, exact {want:.5} ({:+.2} %)",
                        100.0 * e
                    );
                }
            }
        }
    }
    eprintln!(
        "angular coupling, absolute response to a uniform sky: largest error {:.2} % \
         (grazing bin at η = 1 apart)",
        100.0 * worst
    );
}

/// Reciprocity in the angular coupling's raw data at η ≠ 1 (refraction and Fresnel both
/// ways): the power from bin j into bin k equals that from k into j, within 5 standard
/// errors, before the coupling symmetrises it.
#[test]
fn angular_coupling_data_is_reciprocal_with_refraction() {
    use bssrdf_core::tabulated::angular::angular_data;
    use bssrdf_core::tabulated::angular_file::{N_MU, index};

    let mut worst: f64 = 0.0;
    for plane in &angular_data().planes[1..] {
        // Rows below α = 0.9999: above it paths cut at the event cap bias the data.
        for row in (0..N_ALBEDO)
            .filter(|&r| albedo_of_row(r) <= 0.9999)
            .step_by(3)
        {
            for kind in 0..2 {
                for j in 0..N_MU {
                    for k in j + 1..N_MU {
                        let (a, b) = (index(kind, row, j, k), index(kind, row, k, j));
                        let d = f64::from(plane.p[a]) - f64::from(plane.p[b]);
                        let se = (f64::from(plane.p_se[a]).powi(2)
                            + f64::from(plane.p_se[b]).powi(2))
                        .sqrt();
                        let z = d.abs() / (se + 1e-9);
                        worst = worst.max(z);
                        assert!(
                            z < 5.0,
                            "η {}, row {row}, kind {kind}, ({j}, {k}): z {z:.2}",
                            plane.eta
                        );
                    }
                }
            }
        }
    }
    eprintln!("angular coupling reciprocity: largest |z| {worst:.2}");
}
