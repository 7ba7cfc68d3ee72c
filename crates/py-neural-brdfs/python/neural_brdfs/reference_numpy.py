"""Reference numpy implementation of the neural BRDF models of ``brdf-neural``.

Rebuilds a fitted model from an export folder (``model.safetensors`` or ``weights.safetensors``
and ``model.json``, from ``experiments::portable``) and evaluates it with numpy alone:

>>> m = load("runs/spot/export")
>>> f = m.eval(triangle, barycentric, l, v)          # (n, 3) f_r, linear RGB, 1/sr
>>> f = m.forward(m.spatial_features(triangle, barycentric), l, v)   # the same

Directions are unit vectors in the local shading frame (normal +z, ``l`` towards the light,
``v`` towards the viewer). The pipeline follows the Rust code step by step:

1. spatial rows: ``x = b0 s[t0] + b1 s[t1] + b2 s[t2]``, ``b0 = 1 - b1 - b2`` (float32, in this
   order), then NaN -> 0 and clamped into [-1e3, 1e3] (``brdf_neural::batch``);
2. direction features (float32, as ``angles``/``brdf_neural::features``): Rusinkiewicz
   ``(theta_h, theta_d, phi_d)``, the view-light triplet ``(theta_v, theta_l, phi_v - phi_l)``,
   or the reciprocity mapping ``(theta_h, theta_d, phi, phi + pi)``, ``phi = phi_d mod pi``;
   then the NeRF encoding ``[p, sin(f_0 p), cos(f_0 p), ..., sin(f_{L-1} p), cos(f_{L-1} p)]``,
   ``f_k = 2^k`` (``pi 2^k`` with ``pi_factor``), each block over all angles. Every + - * /
   and sqrt is a float32 operation as in Rust; atan2, hypot, sin and cos are evaluated in
   float64 and rounded to float32 (what glibc's float functions return, to within an ulp);
3. the networks (ReLU MLPs with skip and late inputs, :class:`Mlp`) in float64 on the float32
   weights, and the heads (:func:`additive_head`, :class:`SingleMlp`).

Only the neural kinds are supported; the parametric ones (RP, TS, Disney, FMBRDF) raise
:class:`NotImplementedError`. Random-swap reciprocity acts in training only: evaluation uses the
true directions, as in Rust.
"""

from __future__ import annotations

import json
import os
import struct
from dataclasses import dataclass, fields
from typing import Dict, Optional, Tuple

import numpy as np

__all__ = ["load", "read_export", "read_safetensors", "ModelConfig", "AngleConfig", "MlpSpec",
           "mlp_specs", "angle_features", "Mlp", "NeuralBrdf", "SingleMlp", "AdditiveSeparate",
           "AdditiveShared", "NEURAL_KINDS", "PARAMETRIC_KINDS"]

F32 = np.float32
#: Rust's ``std::f32::consts`` PI, TAU, FRAC_1_PI; ``NERFACTOR_ALBEDO_RANGE``; ``SPATIAL_LIMIT``;
#: burn's softplus threshold (``beta x`` above it returns ``x``).
PI_F32, TAU_F32, FRAC_1_PI_F32 = F32(np.pi), F32(2.0 * np.pi), F32(1.0 / np.pi)
ALBEDO_RANGE_F32, SPATIAL_LIMIT, SOFTPLUS_THRESHOLD = (F32(0.0023), F32(0.6038)), F32(1e3), 20.0

NEURAL_KINDS = ("single_mlp", "additive_separate", "additive_shared",
                "additive_separate_enhanced", "additive_shared_enhanced")
PARAMETRIC_KINDS = ("rp", "ts", "fmbrdf", "disney")
_PAPER_NAMES = {"rp": "RP", "ts": "TS", "fmbrdf": "FMBRDF", "disney": "Disney",
                "single_mlp": "Single MLP", "additive_separate": "Add. Sep.",
                "additive_shared": "Add. Shared", "additive_separate_enhanced": "Enh. Add. Sep.",
                "additive_shared_enhanced": "Enh. Add. Shared"}
_WEIGHT_FILES = ("model.safetensors", "weights.safetensors")

# ---------------------------------------------------------------------------------- safetensors
_DTYPES = {"F64": "<f8", "F32": "<f4", "F16": "<f2", "I64": "<i8", "I32": "<i4", "U32": "<u4",
           "I16": "<i2", "U16": "<u2", "I8": "i1", "U8": "u1", "BOOL": "?", "BF16": "<u2"}


def read_safetensors(path) -> Tuple[Dict[str, np.ndarray], dict]:
    """Reads a safetensors file: ``(tensors, metadata)``.

    Layout: u64 little-endian header length ``N``, ``N`` bytes of JSON
    ``{name: {dtype, shape, data_offsets: [begin, end]}, "__metadata__": {...}}`` (offsets
    relative to the end of the header), then the raw little-endian data. BF16 is widened to F32.
    """
    with open(path, "rb") as fh:
        raw = fh.read()
    if len(raw) < 8:
        raise ValueError(f"{path}: too short for a safetensors file")
    (n,) = struct.unpack("<Q", raw[:8])
    if 8 + n > len(raw):
        raise ValueError(f"{path}: header length {n} exceeds the file")
    header = json.loads(raw[8:8 + n].decode("utf-8"))
    data = memoryview(raw)[8 + n:]
    meta = header.pop("__metadata__", None) or {}
    out = {}
    for name, info in header.items():
        dtype, shape = info["dtype"], [int(s) for s in info["shape"]]
        if dtype not in _DTYPES:
            raise ValueError(f"{path}: tensor {name!r} has unsupported dtype {dtype}")
        begin, end = (int(o) for o in info["data_offsets"])
        dt = np.dtype(_DTYPES[dtype])
        if not 0 <= begin <= end <= len(data) or end - begin != int(np.prod(shape)) * dt.itemsize:
            raise ValueError(f"{path}: tensor {name!r} has inconsistent data_offsets")
        a = np.frombuffer(data[begin:end], dtype=dt).reshape(shape).copy()
        if dtype == "BF16":
            a = (a.astype(np.uint32) << 16).view(np.float32)
        out[name] = a
    return out, meta


# ------------------------------------------------------------------------------- configuration
@dataclass(frozen=True)
class AngleConfig:
    """``brdf_neural::AngleConfig`` with its ``PositionalEncoding`` flattened."""

    parametrization: str = "rusinkiewicz"   # or "view_light"
    reciprocity: str = "none"               # "none" | "random_swap" | "mapping"
    swap_probability: float = 0.5           # training only
    frequencies: int = 3
    include_input: bool = True
    pi_factor: bool = False

    @property
    def raw_dim(self) -> int:  # 3 angles, 4 with the reciprocity mapping
        return 4 if self.reciprocity == "mapping" else 3

    @property
    def dim(self) -> int:  # encoded width raw_dim (include_input + 2 L): 21, or 28 (mapping)
        return self.raw_dim * (int(self.include_input) + 2 * self.frequencies)


@dataclass(frozen=True)
class ModelConfig:
    """``brdf_neural::ModelConfig`` (serde names and defaults of ``model.rs``)."""

    kind: str = "single_mlp"
    spatial_dim: int = 160
    width: int = 128
    skip_layer: int = 3
    separate_skip_at: int = 2
    shared_diffuse_head_layers: int = 1
    angles: AngleConfig = AngleConfig()
    nol: bool = False
    nol_layer: int = 3
    albedo_clamp: bool = False
    scalar_specular: bool = False
    specular_softplus_scale: float = 0.5
    single_mlp_softplus_scale: float = 1.0
    disney_gamma: bool = False

    enhanced = property(lambda self: self.kind.endswith("_enhanced"))
    #: Specular net width: 1 or 3 channels, +3 for xi when enhanced.
    specular_outputs = property(
        lambda self: (1 if self.scalar_specular else 3) + (3 if self.enhanced else 0))

    @staticmethod
    def from_json(d: dict) -> "ModelConfig":
        """Parses the serde form (missing fields take defaults, unknown ones are errors)."""
        d = dict(d)
        ang = dict(d.pop("angles", {}) or {})
        enc = dict(ang.pop("encoding", {}) or {})
        _no_unknown("model", d, {f.name for f in fields(ModelConfig)})
        _no_unknown("model.angles", ang, {"parametrization", "reciprocity", "swap_probability"})
        _no_unknown("model.angles.encoding", enc, {"frequencies", "include_input", "pi_factor"})
        if "kind" in d:
            d["kind"] = kind_name(d["kind"])
        cfg = ModelConfig(**d, angles=AngleConfig(**ang, **enc))
        cfg.validate()
        return cfg

    def validate(self) -> None:
        """The checks of ``ModelConfig::validate`` that concern the neural kinds."""
        a = self.angles
        for bad, msg in [
                (a.parametrization not in ("rusinkiewicz", "view_light"),
                 f"unknown angle parametrization {a.parametrization!r}"),
                (a.reciprocity not in ("none", "random_swap", "mapping"),
                 f"unknown reciprocity option {a.reciprocity!r}"),
                (a.reciprocity == "mapping" and a.parametrization != "rusinkiewicz",
                 "the reciprocity mapping is defined on Rusinkiewicz angles only"),
                (self.spatial_dim <= 0 or self.width <= 0, "spatial_dim and width must be > 0"),
                ((self.albedo_clamp or self.scalar_specular) and not self.kind.startswith("add"),
                 f"albedo_clamp / scalar_specular apply to additive models, not {self.kind}"),
                (not (self.specular_softplus_scale > 0 and self.single_mlp_softplus_scale > 0),
                 "softplus scales must be positive")]:
            if bad:
                raise ValueError(msg)


def _no_unknown(where, d, known):
    extra = sorted(set(d) - set(known))
    if extra:
        raise ValueError(f"{where}: unknown field(s) {extra} (known: {sorted(known)})")


def kind_name(name: str) -> str:
    """A model kind's configuration name from a configuration or paper name."""
    n = str(name).strip().lower()
    for k, p in _PAPER_NAMES.items():
        if n in (k, p.lower()):
            return k
    raise ValueError(f"unknown model kind {name!r}")


@dataclass(frozen=True)
class MlpSpec:
    """``brdf_neural::mlp::MlpConfig``: linear layer k < hidden_layers is Linear + ReLU, layer
    ``hidden_layers`` the linear output (when ``d_output``); the raw input ``r`` (x, plus the
    late input when ``late_into == 0``) re-enters at layer ``skip_into`` through ``skip``
    (no bias); a late input ``u`` enters layer ``late_into > 0`` through ``late`` (no bias):

        z_k = W_k h_k + b_k [+ S r if k == skip_into] [+ U u if k == late_into],
        h_{k+1} = relu(z_k) for hidden k, output z_k otherwise.
    """

    d_input: int
    width: int
    hidden_layers: int
    d_output: Optional[int] = None
    skip_into: Optional[int] = None
    d_late: int = 0
    late_into: int = 0

    d_raw = property(lambda self: self.d_input + (self.d_late if self.late_into == 0 else 0))
    n_linear = property(lambda self: self.hidden_layers + (self.d_output is not None))

    def out_of(self, k: int) -> int:
        return self.width if k < self.hidden_layers else self.d_output

    def shapes(self, prefix: str) -> Dict[str, tuple]:
        """Expected tensor names and PyTorch-layout shapes ``[out, in]``."""
        n = self.n_linear
        if n == 0 or (self.skip_into is not None and not 1 <= self.skip_into < n) or (
                self.d_late > 0 and self.late_into >= n):
            raise ValueError(f"{prefix}: layer indices out of range in {self}")
        s = {}
        for k in range(n):
            s[f"{prefix}.layers.{k}.weight"] = (self.out_of(k), self.d_raw if k == 0 else self.width)
            s[f"{prefix}.layers.{k}.bias"] = (self.out_of(k),)
        if self.skip_into is not None:
            s[f"{prefix}.skip.weight"] = (self.out_of(self.skip_into), self.d_raw)
        if self.d_late > 0 and self.late_into > 0:
            s[f"{prefix}.late.weight"] = (self.out_of(self.late_into), self.d_late)
        return s


def mlp_specs(c: ModelConfig) -> Dict[str, MlpSpec]:
    """The networks of a neural kind by tensor prefix (``single_mlp.rs``,
    ``additive_separate.rs``, ``additive_shared.rs``)."""
    a = c.angles.dim
    if c.kind == "single_mlp":
        return {"mlp": MlpSpec(c.spatial_dim, c.width, 5, 3, c.skip_layer, a,
                               c.nol_layer if c.nol else 0)}
    if c.kind in ("additive_separate", "additive_separate_enhanced"):
        d = MlpSpec(c.spatial_dim, c.width, 4, 3, c.separate_skip_at + 1)
        s = MlpSpec(c.spatial_dim, c.width, 2 if c.nol else 4, c.specular_outputs,
                    None if c.nol else c.separate_skip_at + 1, a, 0)
        return {"diffuse": d, "specular": s}
    if c.kind in ("additive_shared", "additive_shared_enhanced"):
        extra, hidden = (2, 3) if c.nol else (0, 5)
        t = MlpSpec(c.spatial_dim, c.width, hidden, None,
                    c.skip_layer if c.skip_layer < hidden else None)
        d = MlpSpec(c.width, c.width, c.shared_diffuse_head_layers + extra, 3)
        s = MlpSpec(c.width, c.width, 2 + extra, c.specular_outputs, None, a, 0)
        return {"trunk": t, "diffuse": d, "specular": s}
    if c.kind in PARAMETRIC_KINDS:
        raise NotImplementedError(_parametric_message(c.kind))
    raise ValueError(f"unknown model kind {c.kind!r}")


def _parametric_message(kind):
    return (f"model kind {kind!r} ({_PAPER_NAMES[kind]}) is a parametric model driven by an "
            f"MLP; the reference modules implement only the neural kinds {NEURAL_KINDS}")


# ------------------------------------------------------------------------- direction features
def _f32_rows(a, name, width):
    a = np.asarray(a, dtype=F32)
    if a.ndim != 2 or a.shape[1] != width:
        raise ValueError(f"{name}: expected shape (n, {width}), got {a.shape}")
    return a


def _atan2(y, x):
    """float32 atan2, evaluated in float64 and rounded (as correctly rounded as glibc's)."""
    return np.arctan2(y.astype(np.float64), x.astype(np.float64)).astype(F32)


def _hypot(x, y):
    return np.hypot(x.astype(np.float64), y.astype(np.float64)).astype(F32)


def _wrap_two_pi(phi):
    """(-pi, pi] -> [0, 2 pi) in float32, -0 -> +0, a result that rounds to 2 pi -> 0."""
    w = np.where(phi < 0, phi + TAU_F32, phi + F32(0))
    return np.where(w >= TAU_F32, F32(0), w).astype(F32)


def _half_frame_xy(a, w, length_of_a):
    """x, y of ``w`` rotated by R_b(-theta_h) R_n(-phi_h) of the half vector ``a = l + v``."""
    rho = _hypot(a[:, 0], a[:, 1])
    ok = rho > 0
    r = np.where(ok, rho, F32(1))
    cp, sp = np.where(ok, a[:, 0] / r, F32(1)), np.where(ok, a[:, 1] / r, F32(0))
    ok = length_of_a > 0
    n = np.where(ok, length_of_a, F32(1))
    ct, st = np.where(ok, a[:, 2] / n, F32(1)), np.where(ok, rho / n, F32(0))
    x1 = w[:, 0] * cp + w[:, 1] * sp
    y1 = w[:, 1] * cp - w[:, 0] * sp
    return x1 * ct - w[:, 2] * st, y1, rho


def _length(a):
    return np.sqrt(a[:, 0] * a[:, 0] + a[:, 1] * a[:, 1] + a[:, 2] * a[:, 2])


def rusinkiewicz(l, v):
    """``angles::Rusinkiewicz::from_local``: ``theta_h = atan2(|a_xy|, a_z)``,
    ``theta_d = atan2(|w|, |a|)``, ``phi_d = wrap(atan2(d_y, d_x))`` with ``a = l + v``,
    ``w = l - v`` rotated into the half frame. float32, ``(n, 3)``."""
    a, w = l + v, l - v
    len_a = _length(a)
    dx, dy, rho = _half_frame_xy(a, w, len_a)
    return np.stack([_atan2(rho, a[:, 2]), _atan2(_length(w), len_a),
                     _wrap_two_pi(_atan2(dy, dx))], axis=1).astype(F32)


def reciprocal_theta(l, v):
    """``angles::reciprocal_theta``: ``[theta_h, theta_d, phi, phi + pi]``, ``phi`` the
    azimuth of ``+-d`` (sign chosen so that ``d_y > 0``, or ``d_y = 0, d_x >= 0``) in [0, pi);
    bit-identical under swapping l and v. float32, ``(n, 4)``."""
    r = rusinkiewicz(l, v)
    a, w = l + v, l - v
    rho = _hypot(a[:, 0], a[:, 1])
    dx, dy, _ = _half_frame_xy(a, w, np.sqrt(rho * rho + a[:, 2] * a[:, 2]))
    flip = (dy < 0) | ((dy == 0) & (dx < 0))
    dx, dy = np.where(flip, -dx, dx), np.where(flip, -dy, dy)
    phi = _atan2(dy + F32(0), dx + F32(0))
    phi = np.where(phi >= PI_F32, F32(0), phi).astype(F32)
    return np.stack([r[:, 0], r[:, 1], phi, phi + PI_F32], axis=1).astype(F32)


def view_light(l, v):
    """``angles::ViewLight::from_local``: ``[theta_v, theta_l, wrap(atan2((l x v)_z,
    l_xy . v_xy))]``, polar angles as ``atan2(|x_xy|, x_z)``. float32, ``(n, 3)``."""
    cz = l[:, 0] * v[:, 1] - l[:, 1] * v[:, 0]
    dxy = l[:, 0] * v[:, 0] + l[:, 1] * v[:, 1]
    return np.stack([_atan2(_hypot(v[:, 0], v[:, 1]), v[:, 2]),
                     _atan2(_hypot(l[:, 0], l[:, 1]), l[:, 2]),
                     _wrap_two_pi(_atan2(cz, dxy))], axis=1).astype(F32)


def positional_encoding(p, frequencies=3, include_input=True, pi_factor=False):
    """``angles::PositionalEncoding``: ``[p, sin(f_0 p), cos(f_0 p), ..., sin(f_{L-1} p),
    cos(f_{L-1} p)]``, ``f_k = 2^k`` (times pi in float32 with ``pi_factor``); ``f p`` rounded to
    float32, sin/cos evaluated in float64 and rounded (glibc's sinf/cosf are about as
    accurate). ``(n, d)`` -> ``(n, d (include_input + 2 L))`` float32."""
    p = np.asarray(p, dtype=F32)
    blocks = [p] if include_input else []
    base = PI_F32 if pi_factor else F32(1)
    for k in range(frequencies):
        x = (F32(base * F32(2.0 ** k)) * p).astype(np.float64)
        blocks += [np.sin(x).astype(F32), np.cos(x).astype(F32)]
    return np.concatenate(blocks, axis=1) if blocks else np.zeros((p.shape[0], 0), F32)


def angle_features(a: AngleConfig, l, v):
    """The encoded direction features of ``brdf_neural::features`` (no swap: evaluation)."""
    l, v = _f32_rows(l, "l", 3), _f32_rows(v, "v", 3)
    if l.shape != v.shape:
        raise ValueError(f"l and v differ in shape: {l.shape} vs {v.shape}")
    with np.errstate(all="ignore"):
        if a.reciprocity == "mapping":
            raw = reciprocal_theta(l, v)
        elif a.parametrization == "view_light":
            raw = view_light(l, v)
        else:
            raw = rusinkiewicz(l, v)
        return positional_encoding(raw, a.frequencies, a.include_input, a.pi_factor)


# ------------------------------------------------------------------------------------ networks
def softplus(x):
    """burn's softplus (beta 1, threshold 20): ``x`` where ``x > 20``, else ``log1p(exp(x))``."""
    return np.where(x > SOFTPLUS_THRESHOLD, x,
                    np.log1p(np.exp(np.minimum(x, SOFTPLUS_THRESHOLD))))


def sigmoid(x):
    """``exp(-log(1 + exp(-x)))`` as burn's default, written stably."""
    return np.exp(-np.logaddexp(0.0, -x))


class Mlp:
    """:class:`MlpSpec`'s network evaluated in ``dtype`` (float64 by default)."""

    def __init__(self, spec: MlpSpec, tensors, prefix, dtype=np.float64):
        self.spec = spec
        get = lambda n: None if n not in tensors else np.asarray(tensors[n], dtype)  # noqa: E731
        n = spec.n_linear
        self.weights = [get(f"{prefix}.layers.{k}.weight") for k in range(n)]
        self.biases = [get(f"{prefix}.layers.{k}.bias") for k in range(n)]
        self.skip = get(f"{prefix}.skip.weight")
        self.late = get(f"{prefix}.late.weight")

    def __call__(self, x, late=None):
        s = self.spec
        if (late is not None) != (s.d_late > 0):
            raise ValueError("Mlp: late input mismatch")
        if late is not None and s.late_into == 0:
            x, late = np.concatenate([x, late], axis=1), None
        raw = h = x
        for k, (w, b) in enumerate(zip(self.weights, self.biases)):
            z = h @ w.T + b
            if k == s.skip_into:
                z = z + raw @ self.skip.T
            if late is not None and k == s.late_into:
                z = z + late @ self.late.T
            h = np.maximum(z, 0.0) if k < s.hidden_layers else z
        return h


def additive_head(c: ModelConfig, d_raw, s_raw):
    """``AdditiveHead::combine`` (``output.rs``):

    * ``f_d = sigmoid(d) / pi`` or, with ``albedo_clamp``, ``(lo + (hi - lo) sigmoid(d)) / pi``,
      ``[lo, hi] = [0.0023, 0.6038]``;
    * ``f_s = k softplus(s[:, :c])`` (``c`` = 1 broadcast to RGB with ``scalar_specular``, else
      3; ``k = specular_softplus_scale``);
    * plain: ``f = f_d + f_s``; enhanced: ``xi = sigmoid(s[:, c:c+3])``,
      ``f = (1 - xi) f_d + f_s``.
    """
    s = sigmoid(d_raw)
    if c.albedo_clamp:
        lo, hi = ALBEDO_RANGE_F32
        fd = (s * F32(hi - lo) + lo) * FRAC_1_PI_F32
    else:
        fd = s * FRAC_1_PI_F32
    n = 1 if c.scalar_specular else 3
    fs = np.broadcast_to(softplus(s_raw[:, :n]) * F32(c.specular_softplus_scale),
                         (s_raw.shape[0], 3)).copy()
    out = {"diffuse_raw": fd, "specular": fs}
    if c.enhanced:
        xi = sigmoid(s_raw[:, n:n + 3])
        out.update(xi=xi, diffuse=(1.0 - xi) * fd)
    else:
        out["diffuse"] = fd
    out["f"] = out["diffuse"] + fs
    return out


# -------------------------------------------------------------------------------------- models
class NeuralBrdf:
    """A fitted neural BRDF: the networks, the angle features and the spatial table."""

    def __init__(self, config: ModelConfig, tensors, spatial_kind="lbo", dtype=np.float64):
        self.config, self.spatial_kind, self.dtype = config, spatial_kind, dtype
        self.specs = mlp_specs(config)
        self.nets = {p: Mlp(s, tensors, p, dtype) for p, s in self.specs.items()}
        self.vertex_features = tensors.get("spatial.vertex_features")
        self.triangles = tensors.get("spatial.triangles")

    kind = property(lambda self: self.config.kind)

    def spatial_features(self, triangle, barycentric):
        """``x = b0 s[t0] + b1 s[t1] + b2 s[t2]``, ``(b0, b1, b2) = (1 - b1 - b2, b1, b2)`` in
        float32 and in this order, as ``experiments::data::spatial_features`` (``[1.0]`` rows
        for the ``uniform`` kind). ``(n,)``, ``(n, 2)`` -> ``(n, dim)`` float32."""
        tri = np.asarray(triangle).reshape(-1).astype(np.int64)
        bary = _f32_rows(barycentric, "barycentric", 2)
        if bary.shape[0] != tri.shape[0] or not np.isfinite(bary).all():
            raise ValueError(f"barycentric: expected ({tri.shape[0]}, 2) finite values")
        if self.triangles is not None and tri.size and (
                tri.min() < 0 or tri.max() >= self.triangles.shape[0]):
            raise IndexError(f"triangle index out of range: the mesh has "
                             f"{self.triangles.shape[0]} triangles")
        if self.spatial_kind == "uniform":
            return np.ones((tri.shape[0], 1), F32)
        if self.vertex_features is None or self.triangles is None:
            raise ValueError("the export holds no spatial.vertex_features / spatial.triangles")
        table = np.asarray(self.vertex_features, F32)
        corners = self.triangles[tri].astype(np.int64)
        b1, b2 = bary[:, :1], bary[:, 1:]
        out = (F32(1) - b1 - b2) * table[corners[:, 0]]
        out = out + b1 * table[corners[:, 1]]
        return (out + b2 * table[corners[:, 2]]).astype(F32)

    def forward_parts(self, spatial, l, v):
        """Every output as a dict: ``f`` and, for additive kinds, ``diffuse`` (with the
        enhanced ``1 - xi``), ``diffuse_raw``, ``specular`` (and ``xi``); ``(n, 3)`` each."""
        x = _f32_rows(spatial, "spatial", self.config.spatial_dim)
        x = np.clip(np.where(np.isnan(x), F32(0), x), -SPATIAL_LIMIT, SPATIAL_LIMIT)
        ang = angle_features(self.config.angles, l, v)
        if ang.shape[0] != x.shape[0]:
            raise ValueError(f"{x.shape[0]} spatial rows but {ang.shape[0]} direction pairs")
        with np.errstate(over="ignore", under="ignore"):
            return self._network(x.astype(self.dtype), ang.astype(self.dtype))

    def forward(self, spatial, l, v):
        """f_r ``(n, 3)`` (linear RGB, 1/sr) at spatial rows ``(n, dim)`` and local ``l, v``."""
        return self.forward_parts(spatial, l, v)["f"]

    __call__ = forward

    def eval(self, triangle, barycentric, l, v):
        """``forward(spatial_features(triangle, barycentric), l, v)``."""
        return self.forward(self.spatial_features(triangle, barycentric), l, v)

    def __repr__(self):
        return f"{type(self).__name__}(kind={self.kind!r}, spatial={self.spatial_kind!r})"


class SingleMlp(NeuralBrdf):
    """``f = s softplus(MLP([x, PE]))``, ``s = single_mlp_softplus_scale``; NOL: PE enters
    linear layer ``nol_layer`` instead of layer 0."""

    def _network(self, spatial, angles):
        z = self.nets["mlp"](spatial, angles)
        return {"f": softplus(z) * F32(self.config.single_mlp_softplus_scale)}


class AdditiveSeparate(NeuralBrdf):
    """``d = MLP_d(x)``, ``s = MLP_s([x, PE])``, combined by :func:`additive_head`."""

    def _network(self, spatial, angles):
        d = self.nets["diffuse"](spatial)
        return additive_head(self.config, d, self.nets["specular"](spatial, angles))


class AdditiveShared(NeuralBrdf):
    """``t = trunk(x)`` (last ReLU activations), ``d = head_d(t)``, ``s = head_s([t, PE])``,
    combined by :func:`additive_head`."""

    def _network(self, spatial, angles):
        t = self.nets["trunk"](spatial)
        d = self.nets["diffuse"](t)
        return additive_head(self.config, d, self.nets["specular"](t, angles))


_CLASSES = {"single_mlp": SingleMlp, "additive_separate": AdditiveSeparate,
            "additive_separate_enhanced": AdditiveSeparate, "additive_shared": AdditiveShared,
            "additive_shared_enhanced": AdditiveShared}


# -------------------------------------------------------------------------------------- loading
def read_export(folder):
    """``(config, spatial_kind, tensors, description)`` of an export folder, checked: format,
    version, kind, every network tensor present with its shape and none left over."""
    with open(os.path.join(folder, "model.json"), encoding="utf-8") as fh:
        desc = json.load(fh)
    if desc.get("format") != "neural-brdfs-weights" or desc.get("version") != 1:
        raise ValueError(f"{folder}/model.json: expected format 'neural-brdfs-weights' "
                         f"version 1, got {desc.get('format')!r} {desc.get('version')!r}")
    model = dict(desc.get("model") or {})
    kind = kind_name(model.get("kind", desc.get("kind", "single_mlp")))
    if kind in PARAMETRIC_KINDS:
        raise NotImplementedError(_parametric_message(kind))
    model["kind"] = kind
    config = ModelConfig.from_json(model)
    spatial = desc.get("spatial") or {}
    skind, sdim = spatial.get("kind", "lbo"), int(spatial.get("dim", config.spatial_dim))
    if skind not in ("lbo", "position", "uniform"):
        raise ValueError(f"unknown spatial kind {skind!r}")
    if sdim != config.spatial_dim:
        raise ValueError(f"spatial dim {sdim} differs from the model's spatial_dim "
                         f"{config.spatial_dim}")
    path = next((os.path.join(folder, f) for f in _WEIGHT_FILES
                 if os.path.exists(os.path.join(folder, f))), None)
    if path is None:
        raise FileNotFoundError(f"{folder}: none of {_WEIGHT_FILES}")
    tensors, _ = read_safetensors(path)
    expected = {}
    for prefix, spec in mlp_specs(config).items():
        expected.update(spec.shapes(prefix))
    got = {n: tuple(t.shape) for n, t in tensors.items() if not n.startswith("spatial.")}
    if got != expected:
        diff = sorted(set(got.items()) ^ set(expected.items()))
        raise ValueError(f"{path}: tensors do not match kind {kind} (name, shape; file vs model "
                         f"symmetric difference): {diff}")
    vf, tr = tensors.get("spatial.vertex_features"), tensors.get("spatial.triangles")
    if vf is not None and (vf.ndim != 2 or vf.shape[1] != sdim):
        raise ValueError(f"spatial.vertex_features has shape {vf.shape}, expected [V, {sdim}]")
    if tr is not None:
        if tr.ndim != 2 or tr.shape[1] != 3:
            raise ValueError(f"spatial.triangles has shape {tr.shape}, expected [T, 3]")
        if vf is not None and tr.size and (tr.min() < 0 or tr.max() >= vf.shape[0]):
            raise ValueError("spatial.triangles names vertices outside vertex_features")
    return config, skind, tensors, desc


def load(folder, dtype=np.float64) -> NeuralBrdf:
    """Rebuilds the model of an export folder; the networks compute in ``dtype``."""
    config, skind, tensors, _ = read_export(folder)
    return _CLASSES[config.kind](config, tensors, skind, dtype)
