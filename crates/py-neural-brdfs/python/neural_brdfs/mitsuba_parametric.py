"""The parametric kinds of :mod:`neural_brdfs.mitsuba` in Dr.Jit: an MLP on the spatial features
predicts the raw parameters of an analytic BRDF, output nonlinearities map them into its range,
and the analytic BRDF (the tensor twin of ``brdf-analytic``) is evaluated for the pair (l, v).

A transcription of the Rust ground truth, operation for operation in float32:

* the parameter MLP (``parametric.rs``, ``parametric_config``): ``spatial_dim`` -> 5 hidden
  ReLU layers of ``width`` -> the kind's raw outputs, the input skipping into linear layer
  ``skip_layer``; tensors ``mlp.layers.<k>.{weight,bias}`` and ``mlp.skip.weight``;
* the output nonlinearities (``ParametricModel::params_of_outputs``):

  ======  ===  ==============================================================================
  kind    out  parameters
  ======  ===  ==============================================================================
  rp      7    k = sigmoid (RGB), zeta = sigmoid (RGB), k_d = zeta k, k_s = (1 - zeta) k,
               N = 1 + softplus
  ts      7    roughness = sigmoid(0.5 z), rho_d = sigmoid (RGB), F0 = sigmoid (RGB)
  disney  12   base colour (RGB), metallic, subsurface, specular, roughness (sigmoid(0.5 z)),
               specular tint, sheen, sheen tint, clearcoat, clearcoat gloss; all sigmoid
  fmbrdf  6    eta = 1.1 + 1.4 sigmoid, rho = sigmoid (RGB), k_s = softplus, kappa = 100
               sigmoid; per object alpha = 0.001 + (2 pi - 0.001) sigmoid(10 a), beta = 0.5 +
               3.5 sigmoid(10 b) from the tensors ``fm_alpha``, ``fm_beta``
  ======  ===  ==============================================================================

* the per-pair geometry (``tensor_brdf/geometry.rs``, ``brdf_analytic::microfacet::
  PairGeometry``) and the tensor BRDFs (``tensor_brdf/{phong,torrance_sparrow,disney,
  fmbrdf}.rs``).

FMBRDF also needs its two fixed helper networks (``tensor_brdf/fmbrdf_nets.rs``: the Smith
Lambda network 4-300-100-50-1, the body-reflection intensity branch 11-200-100-100-1), whose
weights ship in the native ``brdf-analytic`` crate (``assets/fmbrdf/fmbrdf_weights.bin``, MIT,
read by :func:`read_fmbrdf_weights`), not in ``model.safetensors``. The Lambda network runs
dense here, with alpha and beta folded into its first layer; the Rust model evaluates it by
segments of the tan axis, equal to the dense network to about 1e-5 relative.
"""

from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np

from . import reference_numpy as ref
from .fmbrdf_weights import FMBRDF_WEIGHTS_ENV, default_fmbrdf_weights, read_fmbrdf_weights

__all__ = ["SUPPORTED", "OUTPUTS", "mlp_specs", "params_of_outputs", "brdf", "forward",
           "LobeFitModel"]

#: The parametric kinds this module renders (FMBRDF given its helper networks' weights).
SUPPORTED = ("rp", "ts", "disney", "fmbrdf")
#: Raw outputs of each kind's parameter MLP (``Analytic::outputs``).
OUTPUTS = {"rp": 7, "ts": 7, "disney": 12, "fmbrdf": 6}

PI, TAU, INV_PI = float(ref.PI_F32), float(ref.TAU_F32), float(ref.FRAC_1_PI_F32)
#: ``brdf_analytic::microfacet::ALPHA_MIN`` and ``DISNEY_TINT_LUMINANCE_MIN`` as float32.
ALPHA_MIN = float(np.float32(1e-3))
TINT_LUMINANCE_MIN = float(np.float32(1e-15))
#: Realistic Phong's largest exponent.
MAX_EXPONENT = 1e6


def mlp_specs(config):
    """The parameter MLP of a parametric kind by tensor prefix (``parametric_config``)."""
    return {"mlp": ref.MlpSpec(config.spatial_dim, config.width, 5, OUTPUTS[config.kind],
                               config.skip_layer)}


def extra_tensors(config):
    """The kind's tensors besides its networks: FMBRDF's two raw global scalars."""
    return {"fm_alpha": (1, 1), "fm_beta": (1, 1)} if config.kind == "fmbrdf" else {}


def _sigmoid(x):
    from .mitsuba import _sigmoid as s
    return s(x)


def _softplus(x):
    from .mitsuba import _softplus as s
    return s(x)


# ------------------------------------------------------------------------ parameters
def params_of_outputs(kind, z, gamma_base_color=False):
    """The BRDF parameters (a dict of Floats, RGB ones as lists of three) of the raw outputs
    ``z`` (a list of Floats), as ``ParametricModel::params_of_outputs``."""
    if kind == "rp":
        k = [_sigmoid(c) for c in z[0:3]]
        zeta = [_sigmoid(c) for c in z[3:6]]
        return {"kd": [a * b for a, b in zip(zeta, k)],
                "ks": [(-a + 1.0) * b for a, b in zip(zeta, k)],
                "exponent": _softplus(z[6]) + 1.0}
    if kind == "ts":
        s = [_sigmoid(z[0] * 0.5)] + [_sigmoid(c) for c in z[1:]]
        return {"roughness": s[0], "diffuse": s[1:4], "f0": s[4:7]}
    if kind == "disney":
        s = [_sigmoid(c * 0.5) if i == 6 else _sigmoid(c) for i, c in enumerate(z)]
        names = ("metallic", "subsurface", "specular", "roughness", "specular_tint", "sheen",
                 "sheen_tint", "clearcoat", "clearcoat_gloss")
        p = {"base_color": s[0:3], "gamma_base_color": bool(gamma_base_color)}
        p.update(zip(names, s[3:12]))
        return p
    raise ValueError(f"parametric kind {kind!r} is not supported (supported: {SUPPORTED})")


# -------------------------------------------------------------------------- geometry
def _schlick_weight(u):
    m = 1.0 - u
    m = dr.select(m < 0.0, 0.0, dr.select(m > 1.0, 1.0, m))
    m2 = m * m
    return m2 * m2 * m


def _min1(x):  # select, not dr.minimum: keeps LLVM off 'fminimum'
    return dr.select(x > 1.0, 1.0, x)


def _smith_a2(c, c2, a2):
    """Smith-GGX visibility 1 / (c + sqrt((a^2 + c^2) - a^2 c^2))."""
    return dr.rcp(c + dr.sqrt((a2 + c2) - a2 * c2))


class Geometry:
    """``tensor_brdf::Geometry`` of the pairs (l, v): the direction-only terms, in the
    operation order of ``geometry.rs``. ``mask`` marks pairs with both directions above the
    horizon; the terms of other pairs are meaningless (the BRDFs zero them)."""

    def __init__(self, l, v):
        self.mask = (l.z > 0) & (v.z > 0)
        ax, ay, az = l.x + v.x, l.y + v.y, l.z + v.z
        txy = ax * ax + ay * ay
        len2 = txy + az * az
        length = dr.sqrt(len2)
        lh = _min1(0.5 * length)
        self.sin2_h = dr.select(len2 > 0, txy / dr.select(len2 > 0, len2, 1.0), 0.0)
        self.nl, self.nv = _min1(l.z), _min1(v.z)
        self.nl2, self.nv2 = self.nl * self.nl, self.nv * self.nv
        self.cos2_h = -self.sin2_h + 1.0
        self.lh2 = lh * lh
        self.schlick_l, self.schlick_v = _schlick_weight(self.nl), _schlick_weight(self.nv)
        self.schlick_h = _schlick_weight(lh)
        s = self.nl + self.nv
        self.subsurface_cos = dr.rcp(dr.select(s > 1e-12, s, 1e-12)) - 0.5
        self.clearcoat_fresnel = self.schlick_h * 0.96 + 0.04
        cc_a2 = 0.25 * 0.25
        self.clearcoat_visibility = (_smith_a2(self.nl, self.nl2, cc_a2)
                                     * _smith_a2(self.nv, self.nv2, cc_a2))
        rv = l.z * v.z - (l.x * v.x + l.y * v.y)
        self.rv_positive = rv > 0
        self.rv = dr.select(rv < 1e-20, 1e-20, _min1(rv))


def _alpha(roughness):
    a = roughness * roughness
    return dr.select(a < ALPHA_MIN, ALPHA_MIN, a)


def _ggx_d(g, alpha):
    a2 = alpha * alpha
    t = g.sin2_h + a2 * g.cos2_h
    return a2 / ((t * t) * PI)


def _spec_dg(g, alpha):
    """GGX D times the two Smith visibilities (Torrance-Sparrow's and Disney's lobe)."""
    a2 = alpha * alpha
    return _ggx_d(g, alpha) * (_smith_a2(g.nl, g.nl2, a2) * _smith_a2(g.nv, g.nv2, a2))


# ------------------------------------------------------------------------------ BRDFs
def realistic_phong(p, g):
    n = p["exponent"]
    n = dr.select(n < 1.0, 1.0, dr.select(n > MAX_EXPONENT, MAX_EXPONENT, n))
    spec = dr.select(g.rv_positive, dr.power(g.rv, n), 0.0)
    scale = (n + 2.0) / TAU
    return [kd * INV_PI + (ks * scale) * spec for kd, ks in zip(p["kd"], p["ks"])]


def torrance_sparrow(p, g):
    dg = _spec_dg(g, _alpha(p["roughness"]))
    w = g.schlick_h
    out = []
    for rho, f0 in zip(p["diffuse"], p["f0"]):
        f = f0 + (-f0 + 1.0) * w
        out.append((-f + 1.0) * (rho * INV_PI) + dg * f)
    return out


def disney(p, g):
    c = p["base_color"]
    cdlin = [dr.power(x, 2.2) for x in c] if p["gamma_base_color"] else list(c)
    cdlum = cdlin[0] * 0.3 + cdlin[1] * 0.6 + cdlin[2] * 0.1
    dark = cdlum <= TINT_LUMINANCE_MIN
    tint_scale = dr.select(dark, 0.0, dr.rcp(dr.select(dark, TINT_LUMINANCE_MIN, cdlum)))
    tint_white = dr.select(dark, 1.0, 0.0)
    metallic, rough = p["metallic"], p["roughness"]
    w = -metallic + 1.0
    dielectric_w = (p["specular"] * (0.5 * 0.16)) * w
    fh = g.schlick_h
    fl, fv = g.schlick_l, g.schlick_v
    lh2r = g.lh2 * rough
    fd90m1 = (lh2r + lh2r) - 0.5
    diffuse = (fd90m1 * fl + 1.0) * (fd90m1 * fv + 1.0)
    fss90m1 = lh2r - 1.0
    fss = (fss90m1 * fl + 1.0) * (fss90m1 * fv + 1.0)
    ss = (fss * g.subsurface_cos + 0.5) * 1.25
    diffuse = diffuse + (ss - diffuse) * p["subsurface"]
    spec = _spec_dg(g, _alpha(rough))
    spec_tinted = spec * (-fh + 1.0)
    cc_alpha = p["clearcoat_gloss"] * (0.001 - 0.1) + 0.1
    cc_a2 = cc_alpha * cc_alpha
    cc_scale = ((p["clearcoat"] * 0.25) * (cc_a2 - 1.0)) / (dr.log(cc_a2) * PI)
    d_r = cc_scale / (g.sin2_h + cc_a2 * g.cos2_h)
    clearcoat = (d_r * g.clearcoat_fresnel) * g.clearcoat_visibility
    sheen = (p["sheen"] * w) * fh
    st, sht = p["specular_tint"], p["sheen_tint"]
    a = (w * diffuse) * INV_PI + spec_tinted * metallic
    b = (spec_tinted * dielectric_w) * st + sheen * sht
    k = ((((spec_tinted * dielectric_w) * (-st + 1.0) + spec * fh) + sheen * (-sht + 1.0))
         + clearcoat)
    a = a + b * tint_scale
    k = k + b * tint_white
    return [ci * a + k for ci in cdlin]


_BRDFS = {"rp": realistic_phong, "ts": torrance_sparrow, "disney": disney}


def brdf(kind, p, l, v):
    """f_r (``mi.Color3f``) of the parameters ``p`` for local ``l``, ``v``; zero unless both
    are above the horizon."""
    g = Geometry(l, v)
    f = _BRDFS[kind](p, g)
    return mi.Color3f(*[dr.select(g.mask, c, 0.0) for c in f])


def forward(config, z, l, v, fm=None):
    """The parametric model after its MLP: raw outputs ``z`` -> f_r (``mi.Color3f``); ``fm``
    (FMBRDF only): ``(FmbrdfNets, alpha, beta, c)``."""
    if config.kind == "fmbrdf":
        return fmbrdf(fmbrdf_params_of_outputs(z), *fm, l, v)
    return brdf(config.kind, params_of_outputs(config.kind, z, config.disney_gamma), l, v)


# ---------------------------------------------------------------------------- FMBRDF
#: FMBRDF's clamps and guards (``tensor_brdf/geometry.rs``), the global gain and ranges
#: (``parametric.rs``) and the normalisation rule (``brdf_analytic::fmbrdf::quadrature``).
COS_EPS, DEN_EPS = 1e-6, 1e-9
FMBRDF_GLOBAL_GAIN = 10.0
FMBRDF_ALPHA_RANGE, FMBRDF_BETA_RANGE = (0.001, 2.0 * np.pi), (0.5, 4.0)
FMBRDF_NODES, FMBRDF_TAIL = 24, 40.0
#: The environment variable naming ``fmbrdf_weights.bin`` (the plugin's ``fmbrdf_weights``).
def _f32(x):
    return np.float32(x)


def fmbrdf_globals(fm_alpha, fm_beta):
    """FMBRDF's per-object alpha, beta and normalisation c(alpha, beta), float32 as
    ``ParametricModel::params_of_outputs`` and ``fmbrdf_normalization`` compute them."""
    def ranged(raw, lo_hi):
        lo, hi = lo_hi
        z = _f32(_f32(np.asarray(raw, np.float32).reshape(())) * _f32(FMBRDF_GLOBAL_GAIN))
        sg = _f32(1.0 / (1.0 + np.exp(-np.float64(z))))
        return _f32(_f32(sg * _f32(hi - lo)) + _f32(lo))
    alpha, beta = ranged(fm_alpha, FMBRDF_ALPHA_RANGE), ranged(fm_beta, FMBRDF_BETA_RANGE)
    x, w = np.polynomial.legendre.leggauss(FMBRDF_NODES)
    u = (0.5 * (x + 1.0)).astype(np.float32)
    wu = (w * 0.5 * (x + 1.0)).astype(np.float32)
    tmax = _f32(alpha * np.exp(_f32(_f32(1.0) / beta) * _f32(np.log(FMBRDF_TAIL)),
                               dtype=np.float32))
    tmax = min(tmax, _f32(np.pi / 2))
    theta = (tmax * u * u).astype(np.float32)
    g = (np.exp(-np.power(theta / alpha, beta)) * np.cos(theta) * np.sin(theta)).astype(
        np.float32)
    total = _f32(_f32(np.sum(g * wu, dtype=np.float32)) * tmax)
    c = _f32(_f32(1.0) / _f32(total * _f32(2.0 * np.pi)))
    return float(alpha), float(beta), float(c)


class _DenseNet:
    """A fixed ReLU network as packed Dr.Jit matrices (``relu`` flags per layer)."""

    def __init__(self, layers, relu, half=False):
        self.relu, self.half = relu, half
        tensor = dr.float16_array_t(mi.TensorXf) if half else mi.TensorXf
        packed = dr.nn.pack(*[tensor(np.ascontiguousarray(w, np.float32)) for w, _ in layers],
                            *[tensor(np.ascontiguousarray(b, np.float32)) for _, b in layers],
                            layout="inference")
        self.views, self.bias_views = packed[:len(layers)], packed[len(layers):]

    def __call__(self, x):
        if self.half:
            x = [dr.float16_array_t(mi.Float)(c) for c in x]
        h = x
        for k, r in enumerate(self.relu):
            h = dr.nn.matvec(self.views[k], dr.nn.CoopVec(*h), self.bias_views[k])
            if r:
                h = dr.maximum(h, 0.0)
        return [mi.Float(c) for c in h]


class FmbrdfNets:
    """FMBRDF's Smith Lambda network at the object's (alpha, beta) and its body network.

    The Lambda network's first layer sees (alpha, beta, t, t alpha) with alpha, beta fixed per
    object, so it is folded into one column: z_1 = (alpha W_0 + beta W_1 + b) + t (W_2 +
    alpha W_3), as ``FmbrdfNets::lambda`` folds it (there a segment search replaces the second
    product; its values equal the dense network's to about 1e-5)."""

    def __init__(self, weights, alpha, beta, half=False):
        w = {k: np.asarray(v, np.float32) for k, v in weights.items()}
        w1, b1 = w["shadowing.fc1.weight"], w["shadowing.fc1.bias"]
        a, b = _f32(alpha), _f32(beta)
        bias = ((a * w1[:, 0] + b * w1[:, 1]).astype(np.float32) + b1).astype(np.float32)
        col = (w1[:, 2] + a * w1[:, 3]).astype(np.float32)[:, None]
        layers = [(col, bias)] + [(w[f"shadowing.fc{k}.weight"], w[f"shadowing.fc{k}.bias"])
                                  for k in (2, 3, 4)]
        self.lambda_net = _DenseNet(layers, [True] * 4, half)
        self.body_net = _DenseNet([(w[f"body_reflection.fc_I{k}.weight"],
                                    w[f"body_reflection.fc_I{k}.bias"]) for k in (1, 2, 3, 4)],
                                  [True, True, True, False], half)

    def smith_lambda(self, tan):
        return self.lambda_net([tan])[0]

    def body(self, features):
        return _softplus(self.body_net(features)[0])


def _smith_tan(c):
    lo, hi = float(_f32(COS_EPS)), float(_f32(1.0 - COS_EPS))
    c = dr.select(c < lo, lo, dr.select(c > hi, hi, c))
    return dr.sqrt((1.0 - c) * (1.0 + c)) / c


def _hypot_f(x, y):
    return dr.sqrt(x * x + y * y)


def _body_features(l, v):
    """``brdf_analytic::fmbrdf_body_features``: [n''_x, n''_y, n''_z, l''_x, l''_z, n''.l'']."""
    ux, uy, uz = -v.x, -v.y, -v.z
    rho = _hypot_f(ux, uz)
    ok = rho > 0
    r_ = dr.select(ok, rho, 1.0)
    cy, sy = dr.select(ok, uz / r_, 1.0), dr.select(ok, ux / r_, 0.0)
    n1 = (-sy, -uy * cy, uz)
    d = (l.x - v.x, l.y - v.y, l.z - v.z)
    l1 = (cy * d[0] - sy * d[2], -uy * (sy * d[0] + cy * d[2]) + rho * d[1],
          ux * l.x + uy * l.y + uz * l.z)
    r = _hypot_f(l1[0], l1[1])
    ok = r > 0
    rr = dr.select(ok, r, 1.0)
    cp, sp = dr.select(ok, l1[0] / rr, 1.0), dr.select(ok, l1[1] / rr, 0.0)
    n2 = (cp * n1[0] + sp * n1[1], -sp * n1[0] + cp * n1[1], n1[2])
    return [n2[0], n2[1], n2[2], r, l1[2], n2[0] * r + n2[2] * l1[2]]


def fmbrdf_params_of_outputs(z):
    """The per-point FMBRDF parameters of the raw outputs (eta, rho, k_s, kappa)."""
    return {"eta": _sigmoid(z[0]) * (2.5 - 1.1) + 1.1, "rho": [_sigmoid(c) for c in z[1:4]],
            "k_s": _softplus(z[4]), "kappa": _sigmoid(z[5]) * 100.0}


def fmbrdf(p, nets, alpha, beta, c, l, v):
    """FMBRDF (``tensor_brdf/fmbrdf.rs``) for per-point ``p`` and the object's alpha, beta,
    c (Python floats), f_r as ``mi.Color3f`` (zero unless l, v are above the horizon)."""
    # opaque: the object's constants are kernel inputs, not literals (one kernel per model)
    alpha, beta, c = (dr.opaque(mi.Float, x) for x in (alpha, beta, c))
    mask = (l.z > 0) & (v.z > 0)
    nl, nv = _min1(l.z), _min1(v.z)
    ax, ay, az = l.x + v.x, l.y + v.y, l.z + v.z
    txy = _hypot_f(ax, ay)
    length = _hypot_f(txy, az)
    nh = _min1(az / length)
    th_min = float(_f32(np.arccos(1.0 - COS_EPS)))
    theta_h = dr.atan2(txy, az)
    theta_h = dr.select(theta_h < th_min, th_min, theta_h)
    cap = float(_f32(1.0 - COS_EPS))
    cos_h = dr.select(nh > cap, cap, nh)
    cos_r = 0.5 * length
    cos_r = dr.select(cos_r < 0.0, 0.0, dr.select(cos_r > cap, cap, cos_r))
    sin_r = dr.sqrt((1.0 - cos_r) * (1.0 + cos_r))
    lam_l = nets.smith_lambda(_smith_tan(nl)) + 1.0
    lam_v = nets.smith_lambda(_smith_tan(nv)) + 1.0
    g_smith = dr.rcp(lam_l * lam_v)
    dist = (dr.exp(-dr.power(theta_h / alpha, beta)) * c) * cos_h
    a = dr.rcp(p["eta"])
    sin_t = a * sin_r
    sin_t = dr.select(sin_t < 0.0, 0.0, dr.select(sin_t > cap, cap, sin_t))
    cos_t = dr.sqrt((-sin_t + 1.0) * (sin_t + 1.0))
    acr, act = a * cos_r, a * cos_t
    rs = (acr - cos_t) / ((acr + cos_t) + DEN_EPS)
    rp = (cos_r - act) / ((act + cos_r) + DEN_EPS)
    fres = (rs * rs + rp * rp) * 0.5
    den = (nv * nh) * 4.0 + DEN_EPS
    i_s = ((p["k_s"] * dist) * fres) / den
    feats = _body_features(l, v)
    width = dr.width(feats[0])
    i_b = nets.body(feats[:4] + [dr.zeros(mi.Float, width), feats[4], p["eta"],
                                 alpha + dr.zeros(mi.Float, width),
                                 beta + dr.zeros(mi.Float, width), p["kappa"], feats[5]])
    scale = g_smith / (nl + DEN_EPS)
    return mi.Color3f(*[dr.select(mask, (i_s + rho * i_b) * scale, 0.0) for rho in p["rho"]])


# ------------------------------------------------------------------------ lobe fitting
class LobeFitModel:
    """What :func:`neural_brdfs.mitsuba_sampling.fit_lobe` needs of a model (spatial rows
    from the triangle table, ``forward`` on numpy rows), evaluated by a Dr.Jit model."""

    def __init__(self, drjit_model, tensors, spatial_kind):
        self.model, self.spatial_kind = drjit_model, spatial_kind
        self.vertex_features = tensors.get("spatial.vertex_features")
        self.triangles = tensors.get("spatial.triangles")

    spatial_features = ref.NeuralBrdf.spatial_features

    def forward(self, spatial, l, v):
        x = np.asarray(spatial, np.float32)
        x = np.clip(np.where(np.isnan(x), np.float32(0), x), -ref.SPATIAL_LIMIT,
                    ref.SPATIAL_LIMIT)
        cols = [mi.Float(np.ascontiguousarray(c)) for c in x.T]
        lf = mi.Vector3f(np.ascontiguousarray(np.asarray(l, np.float32).T))
        vf = mi.Vector3f(np.ascontiguousarray(np.asarray(v, np.float32).T))
        return np.array(self.model.forward(cols, lf, vf), np.float64).T
