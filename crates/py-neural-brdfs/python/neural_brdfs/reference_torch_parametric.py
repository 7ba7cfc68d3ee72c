"""The parametric kinds of :mod:`neural_brdfs.reference_torch` (RP, TS, Disney, FMBRDF) in
PyTorch: an MLP on the spatial features predicts raw parameters, output maps put them in range,
then an analytic BRDF is evaluated for (l, v). Load them through ``reference_torch.load``.

A transcription of the Rust ground truth (``brdf-neural``: ``parametric.rs``,
``tensor_brdf/*.rs``), as :mod:`neural_brdfs.mitsuba_parametric` is in Dr.Jit, differentiable
with autograd in the MLP's weights, the spatial rows and FMBRDF's two global scalars:

======  ===  ==============================================================================
kind    out  parameters (``ParametricModel::params_of_outputs``)
======  ===  ==============================================================================
rp      7    k = sigmoid (RGB), zeta = sigmoid (RGB), k_d = zeta k, k_s = (1 - zeta) k,
             N = 1 + softplus;  f = k_d / pi + k_s (N + 2) / (2 pi) max(0, r.v)^N
ts      7    r = sigmoid(0.5 z), rho_d, F0 = sigmoid (RGB);  alpha = max(r^2, 1e-3),
             f = (1 - F) rho_d / pi + D G F / (4 n.l n.v) (GGX, Smith, Schlick)
disney  12   base colour (RGB), metallic, subsurface, specular, roughness (sigmoid(0.5 z)),
             specular tint, sheen, sheen tint, clearcoat, clearcoat gloss; all sigmoid
fmbrdf  6    eta = 1.1 + 1.4 sigmoid, rho = sigmoid (RGB), k_s = softplus, kappa = 100 sigmoid;
             per object alpha = 0.001 + (2 pi - 0.001) sigmoid(10 a), beta = 0.5 + 3.5
             sigmoid(10 b) (parameters ``fm_alpha``, ``fm_beta``); f = G (I_s + rho I_b) /
             (n.l + 1e-9), G = 1 / ((1 + Lambda_l)(1 + Lambda_v))
======  ===  ==============================================================================

The per-pair geometry (:func:`pair_geometry`, ``tensor_brdf/geometry.rs``) depends on l, v only:
it is computed in float32 without gradient (in Rust on the CPU, outside autodiff), pairs not
both above the horizon replaced by l = v = n so that every term is finite, and zeroed at the
end through ``mask``. So f and its gradients stay finite at grazing angles, l = v, n.l = 0 and
below the horizon (every division, sqrt and log has the Rust guards: alpha >= 1e-3, Smith's
sqrt >= alpha^2 (1 - c^2) + c^2, tan theta from cos clamped into [1e-6, 1 - 1e-6], Fresnel's
+1e-9 and sin t <= 1 - 1e-6, the tint luminance floor 1e-15, r.v >= 1e-20).

FMBRDF's fixed helper networks (``tensor_brdf/fmbrdf_nets.rs``: Smith Lambda 4-300-100-50-1,
body intensity 11-200-100-100-1) are non-persistent buffers read from ``fmbrdf_weights.bin``
(:func:`default_fmbrdf_weights`, :func:`read_fmbrdf_weights`). The Lambda network runs dense
(``lambda_mode="dense"``, the network as trained) or by segments of the tan axis as Rust's
training step does (``"segments"``, ``lambda_segments.rs``; here on the device, without a
host sync); the two agree to about 1e-5 relative.
"""

from __future__ import annotations

import json
import math
import os

import numpy as np
import torch
from torch import nn
import torch.nn.functional as F

from .fmbrdf_weights import FMBRDF_WEIGHTS_ENV, default_fmbrdf_weights, read_fmbrdf_weights

try:
    from . import reference_numpy as _ref
    from . import reference_torch as _rt
except ImportError:  # standalone copies side by side
    import reference_numpy as _ref
    import reference_torch as _rt

__all__ = ["OUTPUTS", "PairGeometry", "pair_geometry", "ParametricBrdf", "FmbrdfNets",
           "fmbrdf_normalization", "read_export", "read_fmbrdf_weights",
           "default_fmbrdf_weights", "mlp_specs"]

#: Raw outputs of each kind's parameter MLP (``Analytic::outputs``).
OUTPUTS = {"rp": 7, "ts": 7, "disney": 12, "fmbrdf": 6}
F32 = np.float32
PI, TAU, INV_PI = float(_ref.PI_F32), float(_ref.TAU_F32), float(_ref.FRAC_1_PI_F32)
#: ``microfacet::ALPHA_MIN``, ``DISNEY_TINT_LUMINANCE_MIN``, Realistic Phong's largest exponent.
ALPHA_MIN, TINT_LUMINANCE_MIN, MAX_EXPONENT = float(F32(1e-3)), float(F32(1e-15)), 1e6
#: FMBRDF's clamps (``geometry.rs``), gain and ranges (``parametric.rs``), initial alpha, beta
#: and the normalisation rule (24 Gauss-Legendre nodes, tail e^-40, ``quadrature.rs``).
COS_EPS, DEN_EPS = 1e-6, 1e-9
COS_CAP, COS_LO = float(F32(1.0 - COS_EPS)), float(F32(COS_EPS))
THETA_H_MIN = float(F32(math.acos(1.0 - COS_EPS)))
FMBRDF_GLOBAL_GAIN, FMBRDF_INIT = 10.0, (0.3, 2.0)
FMBRDF_ALPHA_RANGE, FMBRDF_BETA_RANGE = (0.001, 2.0 * math.pi), (0.5, 4.0)
FMBRDF_NODES, FMBRDF_TAIL = 24, 40.0
#: The environment variable naming ``fmbrdf_weights.bin`` (as the Mitsuba plugin's).


def mlp_specs(config):
    """The parameter MLP (``parametric_config``): ``spatial_dim`` -> 5 ReLU layers of ``width``
    -> the kind's raw outputs, the input skipping into linear layer ``skip_layer``."""
    return {"mlp": _ref.MlpSpec(config.spatial_dim, config.width, 5, OUTPUTS[config.kind],
                                config.skip_layer)}


# ----------------------------------------------------------------------------------- geometry
class PairGeometry:
    """The direction-only terms of ``tensor_brdf::Geometry``, ``(n, 1)`` tensors (``body``
    ``(n, 6)``): ``mask`` (1 where n.l > 0 and n.v > 0), ``nl``, ``nv``, ``nl2``, ``nv2``,
    ``sin2_h``, ``cos2_h``, ``lh2``, ``schlick_l``, ``schlick_v``, ``schlick_h``,
    ``subsurface_cos``, ``clearcoat_fresnel``, ``clearcoat_visibility``, ``rv``,
    ``rv_positive``; with FMBRDF's also ``fm_nl``, ``fm_nv``, ``nh``, ``theta_h``, ``cos_h``,
    ``cos_r``, ``sin_r``, ``tan_l``, ``tan_v``, ``body``."""

    def __init__(self, **terms):
        self.__dict__.update(terms)

    def __len__(self):
        return self.mask.shape[0]

    def to(self, *args, **kwargs):
        return PairGeometry(**{k: t.to(*args, **kwargs) for k, t in self.__dict__.items()})


def _schlick(u):
    """``schlick_weight``: (1 - u)^5, 1 - u clamped into [0, 1]."""
    m = (1.0 - u).clamp(0.0, 1.0)
    m2 = m * m
    return m2 * m2 * m


def _smith(c, c2, a2):
    """Smith-GGX visibility 1 / (c + sqrt((a^2 + c^2) - a^2 c^2))."""
    return torch.reciprocal(c + torch.sqrt((a2 + c2) - a2 * c2))


def _unit(w):
    """FMBRDF's ``unit()``: nearly unit rows as they are, others normalized; ``(w, ok)``."""
    len2 = w[:, 0] * w[:, 0] + w[:, 1] * w[:, 1] + w[:, 2] * w[:, 2]
    keep = (len2 - 1.0).abs() <= 16.0 * float(np.finfo(F32).eps)
    length = torch.sqrt(len2)
    ok = (length > 0) & torch.isfinite(length)
    scaled = w * torch.reciprocal(torch.where(ok, length, 1.0))[:, None]
    return torch.where(keep[:, None], w, scaled), keep | ok


def _body_features(l, v):
    """``brdf_analytic::fmbrdf_body_features``: [n''_x, n''_y, n''_z, l''_x, l''_z, n''.l'']
    in the frame where -v is +z and l has no y component."""
    ux, uy, uz = -v[:, 0], -v[:, 1], -v[:, 2]
    rho = _rt._hypot(ux, uz)
    ok = rho > 0
    r_ = torch.where(ok, rho, 1.0)
    cy, sy = torch.where(ok, uz / r_, 1.0), torch.where(ok, ux / r_, 0.0)
    n1 = (-sy, -uy * cy, uz)
    d = l - v
    l1 = (cy * d[:, 0] - sy * d[:, 2], -uy * (sy * d[:, 0] + cy * d[:, 2]) + rho * d[:, 1],
          ux * l[:, 0] + uy * l[:, 1] + uz * l[:, 2])
    r = _rt._hypot(l1[0], l1[1])
    ok = r > 0
    rr = torch.where(ok, r, 1.0)
    cp, sp = torch.where(ok, l1[0] / rr, 1.0), torch.where(ok, l1[1] / rr, 0.0)
    n2 = (cp * n1[0] + sp * n1[1], -sp * n1[0] + cp * n1[1], n1[2])
    return torch.stack([n2[0], n2[1], n2[2], r, l1[2], n2[0] * r + n2[2] * l1[2]], dim=1)


def _smith_tan(c):
    """``fmbrdf_smith_tan``: tan theta from cos theta clamped into [1e-6, 1 - 1e-6]."""
    c = c.clamp(COS_LO, COS_CAP)
    return torch.sqrt((1.0 - c) * (1.0 + c)) / c


@torch.no_grad()
def pair_geometry(l, v, fmbrdf=False) -> PairGeometry:
    """The :class:`PairGeometry` of local directions ``l``, ``v`` ``(n, 3)`` (float32, in the
    operation order of ``Terms::of``); invalid pairs computed as l = v = n."""
    l, v = torch.as_tensor(l).to(torch.float32), torch.as_tensor(v).to(torch.float32)
    if l.ndim != 2 or l.shape[1] != 3 or l.shape != v.shape:
        raise ValueError(f"l, v: expected equal shapes (n, 3), got {tuple(l.shape)}, "
                         f"{tuple(v.shape)}")
    valid = (l[:, 2] > 0) & (v[:, 2] > 0)
    up = l.new_tensor([0.0, 0.0, 1.0])
    lv, vv = torch.where(valid[:, None], l, up), torch.where(valid[:, None], v, up)
    a = lv + vv
    txy = a[:, 0] * a[:, 0] + a[:, 1] * a[:, 1]
    len2 = txy + a[:, 2] * a[:, 2]
    lh = (0.5 * torch.sqrt(len2)).clamp(max=1.0)
    sin2_h = torch.where(len2 > 0, txy / torch.where(len2 > 0, len2, 1.0), 0.0)
    nl, nv = lv[:, 2].clamp(max=1.0), vv[:, 2].clamp(max=1.0)
    nl2, nv2 = nl * nl, nv * nv
    schlick_h = _schlick(lh)
    rv = l[:, 2] * v[:, 2] - (l[:, 0] * v[:, 0] + l[:, 1] * v[:, 1])
    rv_positive = torch.where(valid, rv > 0, True)
    cc_a2 = 0.25 * 0.25
    t = dict(mask=valid, nl=nl, nv=nv, nl2=nl2, nv2=nv2, sin2_h=sin2_h, cos2_h=-sin2_h + 1.0,
             lh2=lh * lh, schlick_l=_schlick(nl), schlick_v=_schlick(nv), schlick_h=schlick_h,
             subsurface_cos=torch.reciprocal((nl + nv).clamp(min=1e-12)) - 0.5,
             clearcoat_fresnel=schlick_h * 0.96 + 0.04,
             clearcoat_visibility=_smith(nl, nl2, cc_a2) * _smith(nv, nv2, cc_a2),
             rv=torch.where(valid, rv, 1.0).clamp(1e-20, 1.0), rv_positive=rv_positive)
    if fmbrdf:
        (lu, lok), (vu, vok) = _unit(l), _unit(v)
        use = valid & lok & vok & (lu[:, 2] > 0) & (vu[:, 2] > 0)
        lu, vu = torch.where(use[:, None], lu, up), torch.where(use[:, None], vu, up)
        fnl, fnv = lu[:, 2].clamp(max=1.0), vu[:, 2].clamp(max=1.0)
        a = lu + vu
        txy = _rt._hypot(a[:, 0], a[:, 1])
        length = _rt._hypot(txy, a[:, 2])
        cos_r = (0.5 * length).clamp(0.0, COS_CAP)
        nh = (a[:, 2] / length).clamp(max=1.0)
        t.update(fm_nl=fnl, fm_nv=fnv, nh=nh, theta_h=_rt._atan2(txy, a[:, 2]).clamp(
            min=THETA_H_MIN), cos_h=nh.clamp(max=COS_CAP), cos_r=cos_r,
            sin_r=torch.sqrt((1.0 - cos_r) * (1.0 + cos_r)), tan_l=_smith_tan(fnl),
            tan_v=_smith_tan(fnv))
        body = _body_features(lu, vu)
    out = {k: x.to(torch.float32)[:, None] for k, x in t.items()}
    if fmbrdf:
        out["body"] = body
    return PairGeometry(**out)


# ----------------------------------------------------------------------- parameters and BRDFs
def _ranged(z, lo_hi):
    lo, hi = lo_hi
    return torch.sigmoid(z) * (hi - lo) + lo


def params_of_outputs(kind, z, gamma_base_color=False, fm_alpha=None, fm_beta=None):
    """The BRDF parameters (a dict of ``(n, k)`` tensors) of the raw outputs ``z``."""
    if kind == "rp":
        k, zeta = torch.sigmoid(z[:, 0:3]), torch.sigmoid(z[:, 3:6])
        return {"kd": zeta * k, "ks": (1.0 - zeta) * k, "exponent": _softplus(z[:, 6:7]) + 1.0}
    if kind in ("ts", "disney"):  # the roughness column's sigmoid(0.5 z)
        h = 0 if kind == "ts" else 6
        s = torch.sigmoid(torch.cat([z[:, :h], z[:, h:h + 1] * 0.5, z[:, h + 1:]], dim=1))
        if kind == "ts":
            return {"roughness": s[:, 0:1], "diffuse": s[:, 1:4], "f0": s[:, 4:7]}
        names = ("metallic", "subsurface", "specular", "roughness", "specular_tint", "sheen",
                 "sheen_tint", "clearcoat", "clearcoat_gloss")
        p = {n: s[:, 3 + i:4 + i] for i, n in enumerate(names)}
        return dict(p, base_color=s[:, 0:3], gamma_base_color=bool(gamma_base_color))
    if kind == "fmbrdf":
        g = FMBRDF_GLOBAL_GAIN
        return {"eta": _ranged(z[:, 0:1], (1.1, 2.5)), "rho": torch.sigmoid(z[:, 1:4]),
                "k_s": _softplus(z[:, 4:5]), "kappa": torch.sigmoid(z[:, 5:6]) * 100.0,
                "alpha": _ranged(fm_alpha * g, FMBRDF_ALPHA_RANGE),
                "beta": _ranged(fm_beta * g, FMBRDF_BETA_RANGE)}
    raise ValueError(f"not a parametric kind: {kind!r} (expected one of {tuple(OUTPUTS)})")


def _softplus(x):
    return F.softplus(x, beta=1.0, threshold=_ref.SOFTPLUS_THRESHOLD)


def _alpha(roughness):
    return (roughness * roughness).clamp(min=ALPHA_MIN)


def _spec_dg(g, alpha):
    """GGX D (alpha^2 / (pi (sin^2 + alpha^2 cos^2)^2)) times the two Smith visibilities."""
    a2 = alpha * alpha
    t = g.sin2_h + a2 * g.cos2_h
    return a2 / ((t * t) * PI) * (_smith(g.nl, g.nl2, a2) * _smith(g.nv, g.nv2, a2))


def realistic_phong(p, g):
    """``phong.rs``: f = k_d / pi + k_s (N + 2) / (2 pi) r.v^N [r.v > 0], N in [1, 1e6]."""
    n = p["exponent"].clamp(1.0, MAX_EXPONENT)
    spec = torch.pow(g.rv, n) * g.rv_positive
    return (p["kd"] * INV_PI + p["ks"] * ((n + 2.0) / TAU) * spec) * g.mask


def torrance_sparrow(p, g):
    """``torrance_sparrow.rs``: f = (1 - F) rho_d / pi + D G F, F = F0 + (1 - F0) (1 - l.h)^5
    (G in Smith's visibility form, which includes 1 / (4 n.l n.v))."""
    dg = _spec_dg(g, _alpha(p["roughness"]))
    f0 = p["f0"]
    f = f0 + (1.0 - f0) * g.schlick_h
    return ((1.0 - f) * (p["diffuse"] * INV_PI) + dg * f) * g.mask


def disney(p, g):
    """Disney as ``tensor_brdf/disney.rs`` writes it: f = C (A + B tint_scale) + K (+ B where
    the luminance of C is <= 1e-15), A, B, K per-sample scalars (see there)."""
    cdlin = torch.pow(p["base_color"], 2.2) if p["gamma_base_color"] else p["base_color"]
    cdlum = cdlin[:, 0:1] * 0.3 + cdlin[:, 1:2] * 0.6 + cdlin[:, 2:3] * 0.1
    dark = cdlum <= TINT_LUMINANCE_MIN
    tint_scale = torch.where(dark, 0.0, torch.reciprocal(cdlum.clamp(min=TINT_LUMINANCE_MIN)))
    metallic, rough = p["metallic"], p["roughness"]
    w = 1.0 - metallic
    dielectric_w = (p["specular"] * (0.5 * 0.16)) * w
    fh, fl, fv = g.schlick_h, g.schlick_l, g.schlick_v
    lh2r = g.lh2 * rough
    fd90m1 = (lh2r + lh2r) - 0.5
    diffuse = (fd90m1 * fl + 1.0) * (fd90m1 * fv + 1.0)
    fss90m1 = lh2r - 1.0
    ss = (((fss90m1 * fl + 1.0) * (fss90m1 * fv + 1.0)) * g.subsurface_cos + 0.5) * 1.25
    diffuse = diffuse + (ss - diffuse) * p["subsurface"]
    spec = _spec_dg(g, _alpha(rough))
    spec_tinted = spec * (1.0 - fh)
    cc_a2 = torch.square(p["clearcoat_gloss"] * (0.001 - 0.1) + 0.1)  # in [1e-6, 0.01]
    cc_scale = (p["clearcoat"] * 0.25) * (cc_a2 - 1.0) / (torch.log(cc_a2) * PI)
    clearcoat = cc_scale / (g.sin2_h + cc_a2 * g.cos2_h) * g.clearcoat_fresnel \
        * g.clearcoat_visibility
    sheen = p["sheen"] * w * fh
    st, sht = p["specular_tint"], p["sheen_tint"]
    a = (w * diffuse) * INV_PI + spec_tinted * metallic
    b = spec_tinted * dielectric_w * st + sheen * sht
    k = spec_tinted * dielectric_w * (1.0 - st) + spec * fh + sheen * (1.0 - sht) + clearcoat
    a = (a + b * tint_scale) * g.mask
    k = (k + torch.where(dark, b, 0.0)) * g.mask
    return cdlin * a + k


# -------------------------------------------------------------------------------------- FMBRDF
class FmbrdfNets(nn.Module):
    """FMBRDF's fixed helper networks as non-persistent buffers (not parameters, not in the
    ``state_dict``; gradients flow through them to alpha, beta, eta and kappa):
    ``lambda{k}_{w,b}`` (``shadowing.fc{k}``), ``body{k}_{w,b}`` (``body_reflection.fc_I{k}``,
    the first layer's weight also split into its geometry and parameter columns as Rust does),
    ``gl_u``, ``gl_wu`` (the normalisation's Gauss-Legendre nodes u = (x + 1) / 2 and weights
    w u / 2, :func:`fmbrdf_normalization`)."""

    def __init__(self, weights):
        super().__init__()
        for k in range(1, 5):
            for dst, src in ((f"lambda{k}", f"shadowing.fc{k}"),
                             (f"body{k}", f"body_reflection.fc_I{k}")):
                for s in ("w", "b"):
                    t = weights[f"{src}.{'weight' if s == 'w' else 'bias'}"]
                    self.register_buffer(f"{dst}_{s}", torch.from_numpy(np.array(t, F32)),
                                         persistent=False)
        w1 = np.array(weights["body_reflection.fc_I1.weight"], F32)  # l''_y (column 4) is 0
        x, w = np.polynomial.legendre.leggauss(FMBRDF_NODES)
        for name, a in (("body1_geometry_w", w1[:, [0, 1, 2, 3, 5, 10]]),
                        ("body1_params_w", w1[:, 6:10]), ("gl_u", (0.5 * (x + 1.0))[None, :]),
                        ("gl_wu", (w * 0.5 * (x + 1.0))[None, :])):
            self.register_buffer(name, torch.from_numpy(np.ascontiguousarray(a, F32)),
                                 persistent=False)

    def _lambda_tail(self, z2):
        h = F.relu(z2)
        h = F.relu(F.linear(h, self.lambda3_w, self.lambda3_b))
        return F.relu(F.linear(h, self.lambda4_w, self.lambda4_b))

    def _first(self, alpha, beta):
        """The first layer folded at (alpha, beta): z_1 = a + t c, ``(1, 300)`` each."""
        w = self.lambda1_w
        return alpha * w[:, 0] + beta * w[:, 1] + self.lambda1_b, w[:, 2] + alpha * w[:, 3]

    def smith_lambda(self, t, alpha, beta, mode="dense"):
        """Lambda(tan theta) ``(m, 1)`` at the object's alpha, beta ``(1, 1)``: ``"dense"``
        relu(a + t c) through every layer; ``"segments"``: relu(a + t c) W2 = P_s + t Q_s on
        the segment s of t where the active first-layer units are fixed (``lambda_segments.rs``:
        breakpoints -a_j / c_j sorted by value then unit; P, Q of all width + 1 segments)."""
        a, c = self._first(alpha, beta)
        if mode == "dense":
            return self._lambda_tail(F.linear(F.relu(a + t * c), self.lambda2_w, self.lambda2_b))
        if mode != "segments":
            raise ValueError(f"lambda mode must be 'dense' or 'segments', got {mode!r}")
        a, c = a[0], c[0]
        with torch.no_grad():
            switching = c != 0
            bp = torch.where(switching, -a / torch.where(switching, c, 1.0), math.inf)
            order = torch.sort(bp, stable=True).indices
            units = torch.arange(order.numel(), device=order.device)
            rank = torch.empty_like(order).scatter_(0, order, units)
            seg = torch.arange(order.numel() + 1, device=order.device)[:, None]
            mask = torch.where(c > 0, rank < seg, torch.where(c < 0, rank >= seg, a > 0))
            index = torch.searchsorted(bp[order].contiguous(), t.reshape(-1).contiguous()
                                       .to(bp.dtype))
            mask = mask.to(a.dtype)
        p, q = F.linear(mask * a, self.lambda2_w), F.linear(mask * c, self.lambda2_w)
        return self._lambda_tail(p.index_select(0, index) + t * q.index_select(0, index)
                                 + self.lambda2_b)

    def body(self, geometry, eta, alpha, beta, kappa):
        """I_b: the body network's 11 inputs [n''_x, n''_y, n''_z, l''_x, 0, l''_z, eta, alpha,
        beta, kappa, n''.l''] -> softplus output ``(n, 1)``."""
        z = (F.linear(geometry, self.body1_geometry_w)
             + F.linear(torch.cat([eta, alpha.expand_as(eta), beta.expand_as(eta), kappa], 1),
                        self.body1_params_w, self.body1_b))
        h = F.relu(F.linear(F.relu(z), self.body2_w, self.body2_b))
        h = F.relu(F.linear(h, self.body3_w, self.body3_b))
        return _softplus(F.linear(h, self.body4_w, self.body4_b))


def fmbrdf_normalization(alpha, beta, u, wu):
    """c(alpha, beta) = 1 / (2 pi int_0^theta_max exp(-(theta / alpha)^beta) cos sin dtheta),
    theta = theta_max u^2, theta_max = min(alpha 40^(1 / beta), pi / 2), 24 Gauss-Legendre
    nodes (``fmbrdf_normalization``), differentiable in alpha and beta ``(1, 1)``."""
    theta_max = (alpha * torch.exp(torch.reciprocal(beta) * math.log(FMBRDF_TAIL))).clamp(
        max=math.pi / 2)
    theta = theta_max * u * u
    g = torch.exp(-torch.pow(theta / alpha, beta)) * torch.cos(theta) * torch.sin(theta)
    return torch.reciprocal((g * wu).sum(dim=1, keepdim=True) * theta_max * (2.0 * math.pi))


def fmbrdf(p, nets, g, lambda_mode="dense"):
    """FMBRDF (``tensor_brdf/fmbrdf.rs``): f = G (I_s + rho I_b) / (n.l + 1e-9), I_s = k_s
    c exp(-(theta_h / alpha)^beta) cos(theta_h) F(v.h; eta) / (4 n.v n.h + 1e-9)."""
    alpha, beta, eta, n = p["alpha"], p["beta"], p["eta"], len(g)
    c = fmbrdf_normalization(alpha, beta, nets.gl_u, nets.gl_wu)
    lam = nets.smith_lambda(torch.cat([g.tan_l, g.tan_v], 0), alpha, beta, lambda_mode) + 1.0
    g_smith = torch.reciprocal(lam[:n] * lam[n:])
    dist = torch.exp(-torch.pow(g.theta_h / alpha, beta)) * c * g.cos_h
    a = torch.reciprocal(eta)  # Fresnel (R_s + R_p) / 2 with the official code's guards
    sin_t = (a * g.sin_r).clamp(0.0, COS_CAP)
    cos_t = torch.sqrt((1.0 - sin_t) * (sin_t + 1.0))
    acr, act = a * g.cos_r, a * cos_t
    rs = (acr - cos_t) / ((acr + cos_t) + DEN_EPS)
    rp = (g.cos_r - act) / ((act + g.cos_r) + DEN_EPS)
    fres = (rs * rs + rp * rp) * 0.5
    i_s = p["k_s"] * dist * fres / ((g.fm_nv * g.nh) * 4.0 + DEN_EPS)
    i_b = nets.body(g.body, eta, alpha, beta, p["kappa"])
    return (i_s + p["rho"] * i_b) * (g_smith / (g.fm_nl + DEN_EPS)) * g.mask


_BRDFS = {"rp": realistic_phong, "ts": torrance_sparrow, "disney": disney}


# -------------------------------------------------------------------------------------- model
class ParametricBrdf(_rt.NeuralBrdf):
    """A parametric fit: ``mlp`` (tensors ``mlp.layers.<k>.{weight,bias}``, ``mlp.skip.weight``)
    and, for FMBRDF, the parameters ``fm_alpha``, ``fm_beta`` ``(1, 1)`` (initialised as Rust:
    alpha 0.3, beta 2) and the fixed ``fm_nets`` (``fmbrdf_weights``: a path, the file's bytes
    or a tensor dict; default :func:`default_fmbrdf_weights`). ``forward_parts`` returns ``f``
    and ``params`` (the BRDF parameters); :meth:`direction_features` is the pair geometry."""

    _mlp_specs = staticmethod(mlp_specs)

    def __init__(self, config, spatial, fmbrdf_weights=None, lambda_mode="dense"):
        if config.kind not in OUTPUTS:
            raise ValueError(f"not a parametric kind: {config.kind!r}")
        if config.nol:
            raise ValueError(f"nol applies to the purely neural models, not {config.kind}")
        super().__init__(config, spatial)
        self.mlp = _rt.Mlp(self.specs["mlp"])
        self.lambda_mode = lambda_mode
        if config.kind == "fmbrdf":
            raw = lambda x, lo_hi: math.log((x - lo_hi[0]) / (lo_hi[1] - x)) / FMBRDF_GLOBAL_GAIN
            self.fm_alpha = nn.Parameter(torch.full((1, 1), raw(FMBRDF_INIT[0],
                                                                FMBRDF_ALPHA_RANGE)))
            self.fm_beta = nn.Parameter(torch.full((1, 1), raw(FMBRDF_INIT[1], FMBRDF_BETA_RANGE)))
            w = default_fmbrdf_weights() if fmbrdf_weights is None else fmbrdf_weights
            self.fm_nets = FmbrdfNets(w if isinstance(w, dict) else read_fmbrdf_weights(w))

    def direction_features(self, l, v):
        return pair_geometry(l, v, fmbrdf=self.kind == "fmbrdf")

    def params_of_outputs(self, z):
        fm = self.kind == "fmbrdf"
        return params_of_outputs(self.kind, z, self.config.disney_gamma,
                                 self.fm_alpha if fm else None, self.fm_beta if fm else None)

    def _network(self, spatial, geometry):
        p = self.params_of_outputs(self.mlp(spatial))
        if self.kind == "fmbrdf":
            return {"f": fmbrdf(p, self.fm_nets, geometry, self.lambda_mode), "params": p}
        return {"f": _BRDFS[self.kind](p, geometry), "params": p}


def read_export(folder):
    """``(config, spatial_kind, tensors, description)`` of an export folder of any kind (neural
    kinds: ``reference_numpy.read_export``), checked; errors name the file and the fault."""
    path = os.path.join(os.fspath(folder), "model.json")
    try:
        with open(path, encoding="utf-8") as fh:
            desc = json.load(fh)
        kind = _ref.kind_name((desc.get("model") or {}).get("kind", desc.get("kind",
                                                                             "single_mlp")))
    except (UnicodeDecodeError, json.JSONDecodeError, AttributeError, ValueError) as e:
        raise ValueError(f"{path}: not a readable model description ({e})") from None
    if kind not in OUTPUTS:
        return _ref.read_export(folder)
    if desc.get("format") != "neural-brdfs-weights" or desc.get("version") != 1:
        raise ValueError(f"{path}: expected format 'neural-brdfs-weights' version 1, got "
                         f"{desc.get('format')!r} {desc.get('version')!r}")
    try:
        config = _ref.ModelConfig.from_json(dict(desc.get("model") or {}, kind=kind))
    except (TypeError, ValueError) as e:
        raise ValueError(f"{path}: bad model configuration: {e}") from None
    spatial = desc.get("spatial") or {}
    skind, sdim = spatial.get("kind", "lbo"), int(spatial.get("dim", config.spatial_dim))
    if skind not in ("lbo", "position", "uniform") or sdim != config.spatial_dim:
        raise ValueError(f"{path}: bad spatial section {spatial!r} (kind lbo, position or "
                         f"uniform; dim = model.spatial_dim = {config.spatial_dim})")
    weights = next((os.path.join(folder, f) for f in _ref._WEIGHT_FILES
                    if os.path.exists(os.path.join(folder, f))), None)
    if weights is None:
        raise FileNotFoundError(f"{folder}: none of {_ref._WEIGHT_FILES}")
    tensors, _ = _ref.read_safetensors(weights)
    expected = mlp_specs(config)["mlp"].shapes("mlp")
    if kind == "fmbrdf":
        expected.update(fm_alpha=(1, 1), fm_beta=(1, 1))
    got = {n: tuple(t.shape) for n, t in tensors.items() if not n.startswith("spatial.")}
    if got != expected:
        diff = sorted(set(got.items()) ^ set(expected.items()))[:8]
        raise ValueError(f"{weights}: tensors do not match model kind {kind} of {path} (name, "
                         f"shape; file vs model symmetric difference): {diff}")
    vf, tr = tensors.get("spatial.vertex_features"), tensors.get("spatial.triangles")
    if vf is not None and (vf.ndim != 2 or vf.shape[1] != sdim):
        raise ValueError(f"{weights}: spatial.vertex_features has shape {vf.shape}, expected "
                         f"[V, {sdim}]")
    if tr is not None and (tr.ndim != 2 or tr.shape[1] != 3 or (vf is not None and tr.size and (
            tr.min() < 0 or tr.max() >= vf.shape[0]))):
        raise ValueError(f"{weights}: spatial.triangles of shape {tr.shape} is not [T, 3] or "
                         f"names vertices outside vertex_features")
    bad = [n for n, t in tensors.items() if t.dtype.kind == "f" and not np.isfinite(t).all()]
    if bad:
        raise ValueError(f"{weights}: tensor(s) {bad} hold NaN or infinite values")
    return config, skind, tensors, desc
