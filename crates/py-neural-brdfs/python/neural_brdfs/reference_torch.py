"""Reference PyTorch implementation of the models of ``brdf-neural``: all nine kinds.

The purely neural kinds (``single_mlp``, ``additive_separate``, ``additive_shared`` and their
``_enhanced`` variants) are the models of :mod:`neural_brdfs.reference_numpy` (which documents
the pipeline and reads the export); the parametric kinds (``rp``, ``ts``, ``disney``,
``fmbrdf``: an MLP predicts the parameters of an analytic BRDF) live in
:mod:`neural_brdfs.reference_torch_parametric` and are re-exported here. All are
``torch.nn.Module`` subclasses of :class:`NeuralBrdf` whose ``state_dict`` names are the
exported tensor names (``mlp.layers.0.weight``, ``trunk.skip.weight``, ``fm_alpha``,
``spatial.vertex_features``...), so a model can be fine-tuned, moved to a GPU or re-exported
with PyTorch's own tools:

>>> m = load("runs/spot/export", device="cuda")               # any kind
>>> f = m(m.spatial_features(triangle, barycentric), l, v)    # (n, 3) f_r, 1/sr
>>> f = m.eval_points(triangle, barycentric, l, v)              # the same
>>> x, d = m.prepare(spatial, l, v)   # once: what Rust computes on the CPU (no gradient)
>>> f = m.forward_prepared(x, d)["f"]                           # the differentiable rest

``eval`` is also available with the signature of the numpy model when called with four
arguments; with none it is ``nn.Module.eval`` (the models have no train/eval differences).
FMBRDF needs its two fixed helper networks' weights (``load(..., fmbrdf_weights=...)``, by
default ``$NEURAL_BRDF_FMBRDF_WEIGHTS`` or the package's copy).

Directions are local-frame unit vectors (normal +z, ``l`` to the light, ``v`` to the viewer).
The direction features are computed in float32 without gradient (in Rust they are inputs
computed on the CPU), with ``atan2``, ``hypot``, ``sin`` and ``cos`` evaluated in float64 and
rounded, as in the numpy module (in float32 on devices without float64, where a feature may
differ by an ulp and, at an exact branch point such as ``phi_d`` near 0 / 2 pi, by a wrap);
the parametric kinds' pair geometry likewise (float32, no gradient). The networks and the
analytic BRDFs run in the parameters' dtype (float32 unless converted). This module and its
parametric sibling are the only ones of the package importing torch.
"""

from __future__ import annotations

import numpy as np
import torch
from torch import nn
import torch.nn.functional as F

try:
    from . import reference_numpy as _ref
except ImportError:  # a standalone copy next to reference_numpy.py
    import reference_numpy as _ref

#: Defined in :mod:`neural_brdfs.reference_torch_parametric`, re-exported (lazily).
_PARAMETRIC = ("ParametricBrdf", "PairGeometry", "pair_geometry", "FmbrdfNets",
               "read_fmbrdf_weights", "default_fmbrdf_weights", "read_export")
__all__ = ["load", "Mlp", "AngleFeatures", "SpatialTable", "NeuralBrdf", "SingleMlp",
           "AdditiveSeparate", "AdditiveShared", *_PARAMETRIC]

PI, TAU, FRAC_1_PI = float(_ref.PI_F32), float(_ref.TAU_F32), float(_ref.FRAC_1_PI_F32)


# ------------------------------------------------------------------------- direction features
def _f64(fn, *xs):
    """``fn`` evaluated in float64 and rounded to float32, as the numpy module does (float32
    on devices without float64, e.g. MPS)."""
    if xs[0].device.type == "mps":
        return fn(*xs)
    return fn(*(x.double() for x in xs)).float()


def _atan2(y, x):
    return _f64(torch.atan2, y, x)


def _hypot(x, y):
    return _f64(torch.hypot, x, y)


def _wrap_two_pi(phi):
    w = torch.where(phi < 0, phi + TAU, phi + 0.0)
    return torch.where(w >= TAU, torch.zeros_like(w), w)


def _length(a):
    return torch.sqrt(a[:, 0] * a[:, 0] + a[:, 1] * a[:, 1] + a[:, 2] * a[:, 2])


def _half_frame_xy(a, w, length_of_a):
    """x, y of ``w`` in the half frame of ``a = l + v`` (see the numpy module)."""
    rho = _hypot(a[:, 0], a[:, 1])
    one, zero = torch.ones_like(rho), torch.zeros_like(rho)
    ok = rho > 0
    r = torch.where(ok, rho, one)
    cp, sp = torch.where(ok, a[:, 0] / r, one), torch.where(ok, a[:, 1] / r, zero)
    ok = length_of_a > 0
    n = torch.where(ok, length_of_a, one)
    ct, st = torch.where(ok, a[:, 2] / n, one), torch.where(ok, rho / n, zero)
    x1 = w[:, 0] * cp + w[:, 1] * sp
    y1 = w[:, 1] * cp - w[:, 0] * sp
    return x1 * ct - w[:, 2] * st, y1, rho


def rusinkiewicz(l, v):
    """``[theta_h, theta_d, phi_d]``, ``phi_d`` in [0, 2 pi) (``angles::Rusinkiewicz``)."""
    a, w = l + v, l - v
    len_a = _length(a)
    dx, dy, rho = _half_frame_xy(a, w, len_a)
    return torch.stack([_atan2(rho, a[:, 2]), _atan2(_length(w), len_a),
                        _wrap_two_pi(_atan2(dy, dx))], dim=1)


def reciprocal_theta(l, v):
    """``[theta_h, theta_d, phi, phi + pi]``, ``phi = phi_d mod pi`` computed from ``+-d``
    (``angles::reciprocal_theta``), identical under swapping l and v."""
    r = rusinkiewicz(l, v)
    a, w = l + v, l - v
    rho = _hypot(a[:, 0], a[:, 1])
    dx, dy, _ = _half_frame_xy(a, w, torch.sqrt(rho * rho + a[:, 2] * a[:, 2]))
    flip = (dy < 0) | ((dy == 0) & (dx < 0))
    dx, dy = torch.where(flip, -dx, dx), torch.where(flip, -dy, dy)
    phi = _atan2(dy + 0.0, dx + 0.0)
    phi = torch.where(phi >= PI, torch.zeros_like(phi), phi)
    return torch.stack([r[:, 0], r[:, 1], phi, phi + PI], dim=1)


def view_light(l, v):
    """``[theta_v, theta_l, phi_v - phi_l]`` (``angles::ViewLight``)."""
    cz = l[:, 0] * v[:, 1] - l[:, 1] * v[:, 0]
    dxy = l[:, 0] * v[:, 0] + l[:, 1] * v[:, 1]
    return torch.stack([_atan2(_hypot(v[:, 0], v[:, 1]), v[:, 2]),
                        _atan2(_hypot(l[:, 0], l[:, 1]), l[:, 2]),
                        _wrap_two_pi(_atan2(cz, dxy))], dim=1)


def positional_encoding(p, frequencies=3, include_input=True, pi_factor=False):
    """``[p, sin(f_0 p), cos(f_0 p), ...]``, ``f_k = 2^k`` (float32 ``pi 2^k`` with
    ``pi_factor``), each block over all columns of ``p``."""
    blocks = [p] if include_input else []
    base = _ref.PI_F32 if pi_factor else _ref.F32(1)
    for k in range(frequencies):
        x = float(_ref.F32(base * _ref.F32(2.0 ** k))) * p
        blocks += [_f64(torch.sin, x), _f64(torch.cos, x)]
    return torch.cat(blocks, dim=1) if blocks else p.new_zeros((p.shape[0], 0))


class AngleFeatures(nn.Module):
    """The encoded direction features of ``brdf_neural::features`` (evaluation: no swap)."""

    def __init__(self, config: "_ref.AngleConfig"):
        super().__init__()
        self.config = config

    @torch.no_grad()
    def forward(self, l, v):
        c = self.config
        l, v = l.to(torch.float32), v.to(torch.float32)
        if l.ndim != 2 or l.shape[1] != 3 or l.shape != v.shape:
            raise ValueError(f"l, v: expected equal shapes (n, 3), got {tuple(l.shape)}, "
                             f"{tuple(v.shape)}")
        if c.reciprocity == "mapping":
            raw = reciprocal_theta(l, v)
        elif c.parametrization == "view_light":
            raw = view_light(l, v)
        else:
            raw = rusinkiewicz(l, v)
        return positional_encoding(raw, c.frequencies, c.include_input, c.pi_factor)


# ------------------------------------------------------------------------------------ networks
class Mlp(nn.Module):
    """``brdf_neural::mlp::Mlp`` (see :class:`reference_numpy.MlpSpec`):
    ``z_k = W_k h_k + b_k [+ S r] [+ U u]``, ReLU on hidden layers."""

    def __init__(self, spec: "_ref.MlpSpec"):
        super().__init__()
        self.spec = spec
        self.layers = nn.ModuleList(
            nn.Linear(spec.d_raw if k == 0 else spec.width, spec.out_of(k))
            for k in range(spec.n_linear))
        self.skip = None if spec.skip_into is None else nn.Linear(
            spec.d_raw, spec.out_of(spec.skip_into), bias=False)
        self.late = nn.Linear(spec.d_late, spec.out_of(spec.late_into), bias=False) if (
            spec.d_late > 0 and spec.late_into > 0) else None

    def forward(self, x, late=None):
        s = self.spec
        if (late is not None) != (s.d_late > 0):
            raise ValueError("Mlp: late input mismatch")
        if late is not None and s.late_into == 0:
            x, late = torch.cat([x, late], dim=1), None
        raw = h = x
        for k, layer in enumerate(self.layers):
            z = layer(h)
            if k == s.skip_into:
                z = z + self.skip(raw)
            if late is not None and k == s.late_into:
                z = z + self.late(late)
            h = F.relu(z) if k < s.hidden_layers else z
        return h


def additive_head(c: "_ref.ModelConfig", d_raw, s_raw):
    """``AdditiveHead::combine``: ``f_d = sigmoid(d) / pi`` (albedo clamp:
    ``(lo + (hi - lo) sigmoid(d)) / pi``), ``f_s = k softplus(s[:, :c])`` broadcast to RGB,
    ``f = f_d + f_s`` or, enhanced, ``xi = sigmoid(s[:, c:c+3])``, ``f = (1 - xi) f_d + f_s``."""
    s = torch.sigmoid(d_raw)
    if c.albedo_clamp:
        lo, hi = _ref.ALBEDO_RANGE_F32
        fd = (s * float(_ref.F32(hi - lo)) + float(lo)) * FRAC_1_PI
    else:
        fd = s * FRAC_1_PI
    n = 1 if c.scalar_specular else 3
    fs = (F.softplus(s_raw[:, :n], beta=1.0, threshold=_ref.SOFTPLUS_THRESHOLD)
          * float(_ref.F32(c.specular_softplus_scale))).expand(s_raw.shape[0], 3)
    out = {"diffuse_raw": fd, "specular": fs}
    if c.enhanced:
        xi = torch.sigmoid(s_raw[:, n:n + 3])
        out.update(xi=xi, diffuse=(1.0 - xi) * fd)
    else:
        out["diffuse"] = fd
    out["f"] = out["diffuse"] + fs
    return out


# ------------------------------------------------------------------------------- spatial table
class SpatialTable(nn.Module):
    """Per-vertex features ``vertex_features`` [V, dim] (float32) and ``triangles`` [T, 3]
    (int64 buffers): ``x = b0 s[t0] + b1 s[t1] + b2 s[t2]``, ``b0 = 1 - b1 - b2``, float32,
    in this order (rows of ``[1.0]`` for the ``uniform`` kind)."""

    def __init__(self, kind, vertex_features, triangles):
        super().__init__()
        self.kind = kind
        self.register_buffer("vertex_features", vertex_features)
        self.register_buffer("triangles", triangles)

    def forward(self, triangle, barycentric):
        dev = self.triangles.device
        if not isinstance(triangle, torch.Tensor):  # e.g. uint32 arrays of sample records
            triangle = np.asarray(triangle).astype(np.int64)
        tri = torch.as_tensor(triangle, device=dev).reshape(-1).to(torch.int64)
        bary = torch.as_tensor(barycentric, device=dev).to(torch.float32)
        if bary.ndim != 2 or bary.shape != (tri.shape[0], 2):
            raise ValueError(f"barycentric: expected ({tri.shape[0]}, 2), got {tuple(bary.shape)}")
        if not bool(torch.isfinite(bary).all()):
            raise ValueError("barycentric coordinates must be finite")
        if tri.numel() and (self.kind != "uniform" or self.triangles.shape[0]) and (
                int(tri.min()) < 0 or int(tri.max()) >= self.triangles.shape[0]):
            raise IndexError(f"triangle index out of range: the mesh has "
                             f"{self.triangles.shape[0]} triangles")
        if self.kind == "uniform":
            return torch.ones((tri.shape[0], 1), dtype=torch.float32, device=dev)
        table = self.vertex_features.to(torch.float32)
        corners = self.triangles[tri]
        b1, b2 = bary[:, :1], bary[:, 1:]
        out = (1.0 - b1 - b2) * table[corners[:, 0]]
        out = out + b1 * table[corners[:, 1]]
        return out + b2 * table[corners[:, 2]]


# -------------------------------------------------------------------------------------- models
class NeuralBrdf(nn.Module):
    """A fitted model of any kind; subclasses hold the networks under their exported names.

    ``forward_parts(spatial, l, v) = forward_prepared(*prepare(spatial, l, v))``: ``prepare``
    does what Rust does on the CPU before the networks (checks, spatial NaN -> 0 and clamp,
    the direction features), ``forward_prepared`` the differentiable rest."""

    _mlp_specs = staticmethod(_ref.mlp_specs)

    def __init__(self, config: "_ref.ModelConfig", spatial: SpatialTable):
        super().__init__()
        self.config = config
        self.specs = self._mlp_specs(config)
        self.angle_features = AngleFeatures(config.angles)
        self.spatial = spatial

    @property
    def kind(self):
        return self.config.kind

    def spatial_features(self, triangle, barycentric):
        """Interpolated spatial rows ``(n, dim)`` float32 (see :class:`SpatialTable`)."""
        return self.spatial(triangle, barycentric)

    def direction_features(self, l, v):
        """The direction inputs Rust computes on the CPU, without gradient: the encoded angle
        features ``(n, d)`` float32 (parametric kinds: their ``PairGeometry``)."""
        return self.angle_features(l, v)

    def prepare(self, spatial, l, v):
        """``(x, features)`` in the parameters' dtype and device: the checked spatial rows
        (NaN -> 0, clamped into [-1e3, 1e3]; differentiable) and :meth:`direction_features`."""
        p = next(self.parameters())
        x = torch.as_tensor(spatial, device=p.device).to(torch.float32)
        if x.ndim != 2 or x.shape[1] != self.config.spatial_dim:
            raise ValueError(f"spatial: expected (n, {self.config.spatial_dim}), "
                             f"got {tuple(x.shape)}")
        x = torch.where(torch.isnan(x), torch.zeros_like(x), x)
        x = x.clamp(-float(_ref.SPATIAL_LIMIT), float(_ref.SPATIAL_LIMIT))
        d = self.direction_features(torch.as_tensor(l, device=p.device),
                                    torch.as_tensor(v, device=p.device))
        if len(d) != x.shape[0]:
            raise ValueError(f"{x.shape[0]} spatial rows but {len(d)} direction pairs")
        return x.to(p.dtype), d.to(p.dtype)

    def forward_prepared(self, x, features):
        """The outputs of :meth:`forward_parts` from the results of :meth:`prepare` (what a
        training step computes; inputs already in the parameters' dtype and device)."""
        return self._network(x, features)

    def forward_parts(self, spatial, l, v):
        """Every output as a dict: ``f`` and, for additive kinds, ``diffuse`` (with the
        enhanced ``1 - xi``), ``diffuse_raw``, ``specular`` (and ``xi``); ``(n, 3)`` each;
        for parametric kinds ``params`` (the BRDF parameters)."""
        return self.forward_prepared(*self.prepare(spatial, l, v))

    def forward(self, spatial, l, v):
        """f_r ``(n, 3)`` (linear RGB, 1/sr) at spatial rows ``(n, dim)`` and local ``l, v``."""
        return self.forward_parts(spatial, l, v)["f"]

    def eval_points(self, triangle, barycentric, l, v):
        """``forward(spatial_features(triangle, barycentric), l, v)``."""
        return self.forward(self.spatial_features(triangle, barycentric), l, v)

    def eval(self, *args):
        """``eval(triangle, barycentric, l, v)``: :meth:`eval_points`; ``eval()``: the usual
        ``nn.Module.eval``."""
        if not args:
            return super().eval()
        return self.eval_points(*args)

    def _network(self, spatial, angles):
        raise NotImplementedError


class SingleMlp(NeuralBrdf):
    """``f = s softplus(MLP([x, PE]))`` (NOL: PE enters layer ``nol_layer``)."""

    def __init__(self, config, spatial):
        super().__init__(config, spatial)
        self.mlp = Mlp(self.specs["mlp"])

    def _network(self, spatial, angles):
        z = self.mlp(spatial, angles)
        scale = float(_ref.F32(self.config.single_mlp_softplus_scale))
        return {"f": F.softplus(z, beta=1.0, threshold=_ref.SOFTPLUS_THRESHOLD) * scale}


class AdditiveSeparate(NeuralBrdf):
    """``d = MLP_d(x)``, ``s = MLP_s([x, PE])``, combined by :func:`additive_head`."""

    def __init__(self, config, spatial):
        super().__init__(config, spatial)
        self.diffuse = Mlp(self.specs["diffuse"])
        self.specular = Mlp(self.specs["specular"])

    def _network(self, spatial, angles):
        return additive_head(self.config, self.diffuse(spatial), self.specular(spatial, angles))


class AdditiveShared(NeuralBrdf):
    """``t = trunk(x)``, ``d = head_d(t)``, ``s = head_s([t, PE])``, :func:`additive_head`."""

    def __init__(self, config, spatial):
        super().__init__(config, spatial)
        self.trunk = Mlp(self.specs["trunk"])
        self.diffuse = Mlp(self.specs["diffuse"])
        self.specular = Mlp(self.specs["specular"])

    def _network(self, spatial, angles):
        t = self.trunk(spatial)
        return additive_head(self.config, self.diffuse(t), self.specular(t, angles))


_CLASSES = {"single_mlp": SingleMlp, "additive_separate": AdditiveSeparate,
            "additive_separate_enhanced": AdditiveSeparate, "additive_shared": AdditiveShared,
            "additive_shared_enhanced": AdditiveShared}


def load(folder, device=None, dtype=torch.float32, fmbrdf_weights=None,
         lambda_mode="dense") -> NeuralBrdf:
    """Rebuilds the model of an export folder of any kind (checked by
    ``reference_torch_parametric.read_export``) with its parameters in ``dtype`` on
    ``device``. FMBRDF only: ``fmbrdf_weights`` (path, bytes or tensor dict; default
    ``default_fmbrdf_weights()``) and the Lambda network's ``lambda_mode`` (``"dense"`` or
    ``"segments"``)."""
    config, skind, tensors, _ = _parametric().read_export(folder)
    vf = tensors.get("spatial.vertex_features")
    tr = tensors.get("spatial.triangles")
    spatial = SpatialTable(
        skind,
        torch.from_numpy(vf.astype("float32")) if vf is not None
        else torch.zeros((0, config.spatial_dim)),
        torch.from_numpy(tr.astype("int64")) if tr is not None
        else torch.zeros((0, 3), dtype=torch.int64))
    if config.kind in _ref.PARAMETRIC_KINDS:
        model = _parametric().ParametricBrdf(config, spatial, fmbrdf_weights, lambda_mode)
    else:
        model = _CLASSES[config.kind](config, spatial)
    state = {k: torch.from_numpy(v) for k, v in tensors.items() if not k.startswith("spatial.")}
    state["spatial.vertex_features"] = spatial.vertex_features
    state["spatial.triangles"] = spatial.triangles
    model.load_state_dict(state, strict=True)
    model.to(dtype=dtype)
    if device is not None:
        model.to(device=device)
    return model.train(False)


def _parametric():
    try:
        from . import reference_torch_parametric as par
    except ImportError:  # a standalone copy
        import reference_torch_parametric as par
    return par


def __getattr__(name):
    """The parametric names of ``__all__``, from :mod:`reference_torch_parametric` (imported
    on first use: it subclasses :class:`NeuralBrdf`)."""
    if name in _PARAMETRIC:
        return getattr(_parametric(), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
