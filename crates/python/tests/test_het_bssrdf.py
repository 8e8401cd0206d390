"""Tests of the Python bindings against closed forms written here, independently of the Rust
code: the classical dipole at eta = 1, the Fresnel formula and its normalisation, exact
reciprocity, constant fields, determinism, typed errors, and renders of the example scenes."""

import math
import pathlib

import numpy as np
import pytest

import het_bssrdf as hb

ROOT = pathlib.Path(__file__).resolve().parents[3]
CHECKER_SLAB = ROOT / "examples" / "scenes" / "checker-slab.toml"


def dipole_eta_one(r, sigma_a, sigma_s):
    """The classical dipole (Jensen et al. 2001, Eq. 4-5) at eta = 1 (A = 1): the real source at
    z_r = 1/sigma_t', the virtual one at z_v = z_r (1 + 4/3)."""
    sigma_tp = sigma_a + sigma_s
    alpha_p = sigma_s / sigma_tp
    sigma_tr = math.sqrt(3.0 * sigma_a * sigma_tp)
    z_r = 1.0 / sigma_tp
    z_v = z_r * (1.0 + 4.0 / 3.0)
    d_r = np.sqrt(r * r + z_r * z_r)
    d_v = np.sqrt(r * r + z_v * z_v)
    term = lambda z, d: z * (1.0 + sigma_tr * d) * np.exp(-sigma_tr * d) / d**3
    return alpha_p / (4.0 * math.pi) * (term(z_r, d_r) + term(z_v, d_v))


def fresnel(cos_i, eta):
    """Unpolarised dielectric Fresnel reflectance for light arriving from outside a medium of
    relative index eta at cosine cos_i."""
    sin_t = math.sqrt(max(0.0, 1.0 - cos_i * cos_i)) / eta
    if sin_t >= 1.0:
        return 1.0
    cos_t = math.sqrt(1.0 - sin_t * sin_t)
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs * rs + rp * rp)


def test_names_are_exported():
    assert "sone" in hb.ESTIMATORS and "kernel" in hb.ESTIMATORS
    assert "tabulated" in hb.PROFILE_MODELS
    assert set(hb.SCATTERING) == {"single", "multiple", "all"}


def test_dipole_matches_closed_form_at_eta_one():
    r = np.linspace(0.0, 20.0, 401)
    for sigma_a, sigma_s in [(0.01, 1.0), (0.5, 2.0), (1e-3, 10.0)]:
        got = hb.Profile("dipole", "multiple", 0.0, 1.0).eval(r, sigma_a, sigma_s)
        want = dipole_eta_one(r, sigma_a, sigma_s)
        assert got.shape == r.shape
        np.testing.assert_allclose(got, want, rtol=1e-10)


def test_total_is_the_integral_of_the_profile():
    profile = hb.Profile("pbd", "multiple", 0.0, 1.3)
    # Geometric radii: the profile spans many decades.
    r = np.concatenate([[0.0], np.geomspace(1e-6, 400.0, 20001)])
    values = profile.eval(r, 0.05, 1.0)
    integral = np.trapezoid(2.0 * np.pi * r * values, r)
    assert integral == pytest.approx(profile.total(0.05, 1.0), rel=2e-3)


def test_s_is_profile_times_normalised_fresnel():
    eta = 1.3
    s = hb.Bssrdf("dipole", "multiple", 0.0, eta)
    # c = 1 - 2 C1, C1 the first moment of the Fresnel reflectance of the boundary for light
    # arriving from outside (what the Rust docs write C1(1/eta)), by the midpoint rule.
    n = 200_000
    mu = (np.arange(n) + 0.5) / n
    c = 1.0 - 2.0 * np.mean([fresnel(m, eta) * m for m in mu])
    assert s.normalisation == pytest.approx(c, rel=1e-7)
    x_i = np.array([[0.4, 0.0, 0.0]])
    x_o = np.zeros((1, 3))
    up = np.array([[0.0, 0.0, 1.0]])
    w_i = np.array([[0.6, 0.0, 0.8]])
    w_o = np.array([[0.0, 0.28, 0.96]])
    got = s.eval([0.01, 0.1, 0.5], [1.0, 2.0, 0.7], hb.Crossings(x_i, up, w_i), hb.Crossings(x_o, up, w_o))
    assert got.shape == (1, 3)
    profile = hb.Profile("dipole", "multiple", 0.0, eta)
    for ch, (sa, ss) in enumerate([(0.01, 1.0), (0.1, 2.0), (0.5, 0.7)]):
        r = profile.eval(np.array([0.4]), sa, ss)[0]
        want = r * (1.0 - fresnel(0.8, eta)) * (1.0 - fresnel(0.96, eta)) / (c * math.pi)
        assert got[0, ch] == pytest.approx(want, rel=1e-6)
    # The JMLH01 form without c is darker by the factor c.
    assert c < 0.95


def test_s_is_reciprocal_and_zero_behind_the_surface():
    s = hb.Bssrdf("tabulated", "all", 0.0, 1.4)
    rng = np.random.default_rng(3)
    n = 64
    up = np.tile([0.0, 0.0, 1.0], (n, 1))
    x_i = np.column_stack([rng.uniform(-1, 1, n), rng.uniform(-1, 1, n), np.zeros(n)])
    x_o = np.column_stack([rng.uniform(-1, 1, n), rng.uniform(-1, 1, n), np.zeros(n)])

    def directions():
        v = rng.normal(size=(n, 3))
        v[:, 2] = np.abs(v[:, 2]) + 0.05
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    w_i, w_o = directions(), directions()
    sigma_a = rng.uniform(0.0, 1.0, (n, 3))
    sigma_s = rng.uniform(0.1, 3.0, (n, 3))
    incident, exitant = hb.Crossings(x_i, up, w_i), hb.Crossings(x_o, up, w_o)
    a = s.eval(sigma_a, sigma_s, incident, exitant)
    b = s.eval(sigma_a, sigma_s, incident=exitant, exitant=incident)
    assert np.all(np.isfinite(a)) and np.all(a > 0.0)
    assert np.array_equal(a, b)
    below = w_i.copy()
    below[:, 2] *= -1.0
    zero = s.eval(sigma_a, sigma_s, hb.Crossings(x_i, up, below), exitant)
    assert np.all(zero == 0.0)


def test_estimators_on_constant_and_patterned_fields():
    n = 32
    rng = np.random.default_rng(5)
    x_i = rng.uniform(-3, 3, (n, 2))
    x_o = x_i + rng.uniform(-1, 1, (n, 2))
    constant = hb.Field.constant([0.02, 0.05, 0.1], [1.0])
    a, b = ([0.005], [1.0]), ([0.1], [2.0])
    checks = hb.Field.checks(1.0, a, b)
    for name in hb.ESTIMATORS:
        estimator = hb.Estimator(name)
        sa, ss = estimator.estimate(constant, x_i, x_o, seed=1)
        assert sa.shape == (n, 3) and ss.shape == (n, 3)
        assert np.all(sa == np.array([0.02, 0.05, 0.1])) and np.all(ss == 1.0), name
        sa, ss = estimator.estimate(checks, x_i, x_o, seed=1)
        # Averages of the two media lie between them.
        assert np.all((sa >= 0.005 - 1e-12) & (sa <= 0.1 + 1e-12)), name
        assert np.all((ss >= 1.0 - 1e-12) & (ss <= 2.0 + 1e-12)), name


def test_estimates_are_deterministic_per_pair():
    field = hb.Field.stripes(0.5, ([0.01], [1.0]), ([0.3], [1.0]), angle=0.3)
    rng = np.random.default_rng(9)
    x_i = rng.uniform(-2, 2, (10, 2))
    x_o = x_i + rng.uniform(-1, 1, (10, 2))
    sone = hb.Estimator("sone", g=0.0, eta=1.3)
    whole, _ = sone.estimate(field, x_i, x_o, seed=11)
    again, _ = sone.estimate(field, x_i, x_o, seed=11)
    assert np.array_equal(whole, again)
    # Pair k draws from seed + k: alone, with that seed, it gives the same numbers.
    alone, _ = sone.estimate(field, x_i[4:5], x_o[4:5], seed=15)
    assert np.array_equal(alone[0], whole[4])
    # The field varies between the pairs: the estimates are not all one value.
    assert np.ptp(whole[:, 0]) > 0.0


def test_invalid_input_raises_value_error_naming_it():
    with pytest.raises(ValueError, match="eta"):
        hb.Profile("pbd", "multiple", 0.0, 0.5)
    with pytest.raises(ValueError, match="unknown"):
        hb.Profile("nonsense")
    with pytest.raises(ValueError, match="sigma_a"):
        hb.Profile("pbd").eval(np.array([1.0]), -1.0, 1.0)
    with pytest.raises(ValueError, match="r"):
        hb.Profile("pbd").eval(np.array([-1.0]), 0.1, 1.0)
    with pytest.raises(ValueError, match="sigma_s"):
        hb.Field.constant([0.1], [1e13])
    with pytest.raises(ValueError, match="shape"):
        hb.Estimator("sone").estimate(hb.Field.constant([0.1], [1.0]), np.zeros((2, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError):
        hb.Estimator("nonsense")
    with pytest.raises(ValueError, match="eta"):
        hb.Estimator("sone", eta=0.5)
    with pytest.raises(ValueError, match="rows"):
        hb.Crossings(np.zeros((2, 3)), np.zeros((1, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="rows"):
        hb.Bssrdf().eval([0.1], [1.0], hb.Crossings(*[np.zeros((2, 3))] * 3), hb.Crossings(*[np.zeros((1, 3))] * 3))


def test_render_checker_slab():
    image = hb.render(str(CHECKER_SLAB), "sone", 1, seed=3)
    assert image.shape == (128, 128, 3) and image.dtype == np.float64
    assert np.all(np.isfinite(image)) and image.min() >= 0.0 and image.max() > 0.0
    assert np.array_equal(image, hb.render(str(CHECKER_SLAB), "sone", 1, seed=3))
    reference = hb.render(str(CHECKER_SLAB), "pt", 1, seed=3)
    assert reference.shape == image.shape and reference.max() > 0.0
    with pytest.raises(OSError):
        hb.render(str(ROOT / "no-such-scene.toml"), "pt", 1)
    with pytest.raises(ValueError):
        hb.render(str(CHECKER_SLAB), "nonsense", 1)
