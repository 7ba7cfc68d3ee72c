"""The analytic BRDFs from Python: construction, conventions (checked against the spec's
formulas in numpy, float64), sampling consistency and errors."""

import numpy as np
import pytest

import neural_brdfs as nb


def directions(n, seed, upper=True):
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    if upper:
        d[:, 2] = np.abs(d[:, 2]) + 1e-3
        d /= np.linalg.norm(d, axis=1, keepdims=True)
    return d


@pytest.mark.parametrize("kind", nb.KINDS)
def test_every_kind_builds_with_defaults_and_reports_its_params(kind):
    b = nb.AnalyticBrdf(kind)
    assert b.kind == kind
    assert b.params, kind
    f = b.eval(directions(64, 1), directions(64, 2))
    assert f.shape == (64, 3) and np.all(np.isfinite(f)) and np.all(f >= 0)
    assert b.reciprocal == (kind != "fmbrdf")


def test_lambert_is_albedo_over_pi_and_zero_below_the_horizon():
    b = nb.AnalyticBrdf("lambert", albedo=(0.2, 0.5, 0.9))
    l, v = directions(100, 3), directions(100, 4)
    np.testing.assert_allclose(b.eval(l, v), np.tile([0.2, 0.5, 0.9], (100, 1)) / np.pi, rtol=1e-15)
    below = l * np.array([1, 1, -1])
    assert np.all(b.eval(below, v) == 0)


def test_realistic_phong_matches_the_spec_formula_to_1e_12():
    kd, ks, n_exp = np.array([0.3, 0.2, 0.1]), np.array([0.5, 0.6, 0.7]), 40.0
    b = nb.AnalyticBrdf("rp", kd=kd, ks=ks, exponent=n_exp)
    l, v = directions(500, 5), directions(500, 6)
    r = 2 * l[:, 2:3] * np.array([0, 0, 1.0]) - l
    cos_a = np.maximum(0, np.sum(r * v, axis=1, keepdims=True))
    want = kd / np.pi + ks * (n_exp + 2) / (2 * np.pi) * cos_a**n_exp
    np.testing.assert_allclose(b.eval(l, v), want, rtol=1e-12, atol=1e-15)


def test_torrance_sparrow_matches_the_spec_formula_to_1e_12():
    rough, rho, f0 = 0.4, np.array([0.5, 0.3, 0.2]), np.array([0.04, 0.05, 0.06])
    b = nb.AnalyticBrdf("ts", roughness=rough, diffuse=rho, f0=f0)
    l, v = directions(500, 7), directions(500, 8)
    a = max(rough**2, 1e-3)
    h = (l + v) / np.linalg.norm(l + v, axis=1, keepdims=True)
    nh, nl, nv, vh = h[:, 2:3], l[:, 2:3], v[:, 2:3], np.sum(v * h, axis=1, keepdims=True)
    d = a**2 / (np.pi * (nh**2 * (a**2 - 1) + 1) ** 2)
    g1 = lambda c: 2 * c / (c + np.sqrt(a**2 + (1 - a**2) * c**2))
    f = f0 + (1 - f0) * (1 - vh) ** 5
    want = (1 - f) * rho / np.pi + d * f * g1(nl) * g1(nv) / (4 * nl * nv)
    np.testing.assert_allclose(b.eval(l, v), want, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("kind", ["lambert", "rp", "ts", "disney"])
def test_reciprocal_models_are_symmetric(kind):
    b = nb.AnalyticBrdf(kind, roughness=0.3) if kind in ("ts", "disney") else nb.AnalyticBrdf(kind)
    l, v = directions(300, 9), directions(300, 10)
    np.testing.assert_allclose(b.eval(l, v), b.eval(v, l), rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("kind", nb.KINDS)
def test_sample_weight_is_f_cos_over_pdf_and_pdf_agrees(kind):
    b = nb.AnalyticBrdf(kind)
    v = directions(2000, 11)
    u = np.random.default_rng(12).random((2000, 2))
    l, w, pdf, valid = b.sample(v, u)
    assert valid.sum() > 1000, kind
    l, w, pdf, v = l[valid], w[valid], pdf[valid], v[valid]
    np.testing.assert_allclose(np.linalg.norm(l, axis=1), 1, rtol=1e-9)
    np.testing.assert_allclose(b.pdf(v, l), pdf, rtol=1e-9)
    f = b.eval(l, v)
    np.testing.assert_allclose(w, f * l[:, 2:3] / pdf[:, None], rtol=1e-9, atol=1e-12)


def test_lambert_sampling_estimates_the_albedo():
    b = nb.AnalyticBrdf("lambert", albedo=0.7)
    v = np.tile([0.0, 0.6, 0.8], (4000, 1))
    _, w, _, valid = b.sample(v, np.random.default_rng(0).random((4000, 2)))
    assert valid.all()
    np.testing.assert_allclose(w.mean(axis=0), 0.7, rtol=1e-12)


def test_batch_shapes_broadcast():
    b = nb.AnalyticBrdf("disney")
    l = directions(12, 13).reshape(3, 4, 3)
    v = np.array([0.0, 0.0, 1.0])
    assert b.eval(l, v).shape == (3, 4, 3)
    assert b.pdf(v, l).shape == (3, 4)


def test_bad_parameters_and_inputs_are_clear_errors():
    with pytest.raises(ValueError, match="roughness"):
        nb.AnalyticBrdf("ts", roughness=2.0)
    with pytest.raises(TypeError, match="unknown parameter colour.*albedo"):
        nb.AnalyticBrdf("lambert", colour=0.5)
    with pytest.raises(ValueError, match="unknown analytic BRDF"):
        nb.AnalyticBrdf("blinn")
    with pytest.raises(TypeError, match="base_color must be a number or three"):
        nb.AnalyticBrdf("disney", base_color=(0.1, 0.2))
    b = nb.AnalyticBrdf("lambert")
    with pytest.raises(ValueError, match="row 1 .*not a finite unit vector"):
        b.eval([[0, 0, 1.0], [0, 0, 2.0]], [[0, 0, 1.0], [0, 0, 1.0]])
    with pytest.raises(ValueError, match="not a finite unit vector"):
        b.eval([[0, 0, np.nan]], [[0, 0, 1.0]])
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 3\)"):
        b.eval(np.zeros((4, 2)), np.zeros((4, 2)))


def test_params_are_reported_as_used():
    p = nb.AnalyticBrdf("disney", base_color=0.25, metallic=1, gamma_base_color=True).params
    assert p["base_color"] == (0.25, 0.25, 0.25)
    assert p["metallic"] == 1.0 and p["gamma_base_color"] is True
    assert p["roughness"] == 0.5
