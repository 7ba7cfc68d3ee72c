"""Importance sampling for :mod:`neural_brdfs.mitsuba`: the analytic lobe fitted to a neural BRDF.

numpy only (no Mitsuba), so the fit can be inspected and tested on its own.

The sampling density, in the local shading frame (normal +z, ``v`` towards the viewer), is the
one-sample MIS (balance heuristic) mixture of a Phong lobe around the mirror direction
``r = (-v_x, -v_y, v_z)`` and the cosine-weighted hemisphere::

    pdf(l | v) = w (n + 1) / (2 pi) max(l . r, 0)^n  +  (1 - w) max(l_z, 0) / pi,   l_z > 0

(0 for ``l_z <= 0``: lobe samples below the horizon are rejected, so ``pdf`` is exactly the
density of the accepted samples). Both parts are symmetric about the normal, so the density does
not depend on the tangent frame. ``n`` and ``w`` are fitted once per material by
:func:`fit_lobe`: the pair of a grid (``n`` in 1, 2, 4, ..., 4096; ``w`` in 0, 0.1, ..., 0.9) that
minimises the summed relative second moment ``E_q[(g/q)^2] / (E_q[g/q])^2`` of the one-sample
estimator of ``int g``, ``g = luminance(f_r(l, v)) l_z``, over random surface points and view
directions (polar angles up to 87 degrees), estimated with one shared set of directions drawn
from the equal mixture of every candidate lobe and the cosine density. That is the variance a
renderer's BSDF sampling pays, so the fit needs no model of the BRDF's shape; ``w <= 0.9``
keeps the cosine density under the whole hemisphere. A lobe that lowers the cost by less than
``MIN_GAIN`` (5 %) is dropped (``w = 0``: cosine only): such gains are within the fit's noise and
the mismatch between this cost and a render's (visibility, lighting), and measured as no gain.
"""

from __future__ import annotations

import numpy as np

__all__ = ["EXPONENTS", "WEIGHTS", "lobe_pdf", "sample_lobe", "fit_lobe", "LUMINANCE"]

#: Candidate Phong exponents and lobe weights of :func:`fit_lobe`.
EXPONENTS = tuple(float(2 ** k) for k in range(13))
WEIGHTS = tuple(round(0.1 * k, 1) for k in range(0, 10))
#: The least relative gain in the fit's cost for a lobe over cosine sampling alone.
MIN_GAIN = 0.05
#: Linear sRGB (Rec. 709) luminance weights.
LUMINANCE = np.array([0.212671, 0.715160, 0.072169])


def _mirror(v):
    return np.stack([-v[..., 0], -v[..., 1], v[..., 2]], axis=-1)


def phong_pdf(n, r, l):
    """``(n + 1) / (2 pi) max(l . r, 0)^n`` (solid angle), broadcast over ``n``."""
    c = np.maximum((l * r).sum(-1), 0.0)
    return (n + 1.0) / (2.0 * np.pi) * c ** n


def lobe_pdf(n, w, v, l):
    """The mixture density of the module docstring (0 where ``v_z <= 0`` or ``l_z <= 0``)."""
    v, l = np.asarray(v, np.float64), np.asarray(l, np.float64)
    p = w * phong_pdf(n, _mirror(v), l) + (1.0 - w) * np.maximum(l[..., 2], 0.0) / np.pi
    return np.where((l[..., 2] > 0) & (v[..., 2] > 0), p, 0.0)


def _frame(r):
    """Duff et al.'s orthonormal basis around unit ``r`` ``(..., 3)``: ``(s, t)``."""
    sign = np.copysign(1.0, r[..., 2])
    a = -1.0 / (sign + r[..., 2])
    b = r[..., 0] * r[..., 1] * a
    s = np.stack([1 + sign * r[..., 0] ** 2 * a, sign * b, -sign * r[..., 0]], axis=-1)
    t = np.stack([b, sign + r[..., 1] ** 2 * a, -r[..., 1]], axis=-1)
    return s, t


def sample_phong(n, r, u):
    """Directions around ``r`` with density :func:`phong_pdf` from uniforms ``u`` ``(..., 2)``."""
    c = u[..., 0] ** (1.0 / (n + 1.0))
    s = np.sqrt(np.maximum(0.0, 1.0 - c * c))
    phi = 2.0 * np.pi * u[..., 1]
    e1, e2 = _frame(r)
    return ((s * np.cos(phi))[..., None] * e1 + (s * np.sin(phi))[..., None] * e2
            + c[..., None] * r)


def sample_cosine(u):
    r, phi = np.sqrt(u[..., 0]), 2.0 * np.pi * u[..., 1]
    return np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(0, 1 - r * r))], -1)


def sample_lobe(n, w, v, u1, u2):
    """Draws ``l`` for each ``v`` from :func:`lobe_pdf` (``u1`` picks the strategy, ``u2`` the
    direction); rows with ``l_z <= 0`` are rejected samples (their density is not in the pdf)."""
    lobe = sample_phong(n, _mirror(v), u2)
    return np.where((u1 < w)[..., None], lobe, sample_cosine(u2))


def _stratified_views(rng, count, max_theta_deg=87.0):
    """``count`` view directions with polar angles stratified in [0, max_theta]."""
    theta = np.radians(max_theta_deg) * (np.arange(count) + rng.random(count)) / count
    phi = 2 * np.pi * rng.random(count)
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], 1)


def fit_lobe(model, points=48, views=8, samples=384, seed=0):
    """Fits ``(exponent, weight)`` to ``model`` (a :class:`~neural_brdfs.reference_numpy
    .NeuralBrdf`) as the module docstring describes. Returns ``(n, w, info)``, ``info`` a dict
    with the chosen cost, the cosine-only cost (``w = 0``) and the grid's costs."""
    rng = np.random.default_rng(seed)
    tri = model.triangles
    if model.spatial_kind == "uniform" or tri is None:
        spatial = model.spatial_features(np.zeros(points, np.int64), np.zeros((points, 2)))
    else:
        t = rng.integers(0, tri.shape[0], points)
        b = rng.random((points, 2))
        flip = b.sum(1) > 1
        b[flip] = 1 - b[flip]
        spatial = model.spatial_features(t, b)
    nv, ns = views, samples
    v = np.stack([_stratified_views(rng, nv) for _ in range(points)])          # (P, V, 3)
    v = np.repeat(v[:, :, None, :], ns, axis=2)                                  # (P, V, S, 3)
    # the proposal: the equal mixture of the cosine density and every candidate lobe
    ex = np.array(EXPONENTS)
    comp = rng.integers(0, len(ex) + 1, v.shape[:3])
    u = rng.random(v.shape[:3] + (2,))
    nn = ex[np.minimum(comp, len(ex) - 1)]
    l = np.where((comp == len(ex))[..., None], sample_cosine(u), sample_phong(nn, _mirror(v), u))
    l = l / np.linalg.norm(l, axis=-1, keepdims=True)
    cos_l = np.maximum(l[..., 2], 0.0)
    r = _mirror(v)
    per_lobe = np.stack([phong_pdf(e, r, l) for e in ex], -1)                   # (P, V, S, E)
    p_cos = cos_l / np.pi
    prop = (per_lobe.sum(-1) + p_cos) / (len(ex) + 1)
    ok = (l[..., 2] > 1e-6) & (prop > 0)
    rows = np.repeat(spatial[:, None, :], nv * ns, axis=1).reshape(-1, spatial.shape[1])
    lf, vf = l.reshape(-1, 3), v.reshape(-1, 3)
    f = np.zeros((lf.shape[0], 3))
    sel = ok.reshape(-1)
    for k in range(0, int(sel.sum()), 65536):  # bounded memory
        idx = np.nonzero(sel)[0][k:k + 65536]
        f[idx] = model.forward(rows[idx], lf[idx].astype(np.float32), vf[idx].astype(np.float32))
    g = np.where(ok, np.clip(f, 0, None).reshape(l.shape[:3] + (3,)) @ LUMINANCE * cos_l, 0.0)
    safe_prop = np.where(ok, prop, 1.0)
    integral = (g / safe_prop).mean(-1)                                          # (P, V)
    good = integral > 1e-12
    g2 = np.where(ok, g * g / safe_prop, 0.0)

    def cost(q):  # summed relative second moment of g / q over the (point, view) pairs
        m = (g2 / np.where(q > 0, q, np.inf)).mean(-1)
        return float((m[good] / integral[good] ** 2).sum())

    grid = {}
    for i, e in enumerate(ex):
        for w in WEIGHTS:
            grid[(e, w)] = cost(w * per_lobe[..., i] + (1 - w) * p_cos)
    (n, w), best = min(grid.items(), key=lambda kv: kv[1])
    cos_cost = cost(p_cos)
    if best > (1.0 - MIN_GAIN) * cos_cost:  # a gain within the fit's noise: cosine only
        n, w, best = 1.0, 0.0, cos_cost
    pairs = max(int(good.sum()), 1)
    info = {"cost": best / pairs, "cosine_cost": cos_cost / pairs, "pairs": pairs, "grid": grid}
    return float(n), float(w), info
