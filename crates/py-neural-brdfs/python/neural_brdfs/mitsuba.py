"""A Mitsuba 3 BSDF plugin, ``neural_brdf``, for the neural and parametric fits of this
workspace.

>>> import mitsuba as mi
>>> mi.set_variant("llvm_ad_rgb")            # or cuda_ad_rgb: a JIT variant with RGB colours
>>> import neural_brdfs.mitsuba               # registers "neural_brdf" (and on variant changes)
>>> img = mi.render(mi.load_file("view003_light002.xml"))

Importing the module registers the plugin for the current variant and again whenever the
variant changes; :func:`register` does it by hand (after ``mi.set_variant``, if the module was
imported before any variant was set). The BSDF element, attached to the run's scene mesh::

    <shape type="ply" id="object">
        <string name="filename" value="mesh.ply"/>  <!-- the scene mesh: its face order, no UVs -->
        <bsdf type="neural_brdf">
            <string name="filename" value="model.json"/>
        </bsdf>
    </shape>

=================  ========  ================================================================
parameter          type      meaning
=================  ========  ================================================================
``filename``       string    the run's ``model.json`` (required), resolved by Mitsuba's file
                             resolver (relative to the XML file's folder)
``weights``        string    the ``.safetensors`` file; default ``model.safetensors`` (else
                             ``weights.safetensors``) beside ``filename``
``sampling``       string    ``lobe`` (default: the fitted lobe mixed with cosine sampling,
                             :mod:`neural_brdfs.mitsuba_sampling`) or ``cosine``
``lobe_exponent``  float     overrides the fitted Phong exponent ``n``
``lobe_weight``    float     overrides the fitted lobe probability ``w`` (in [0, 1])
``precision``      string    the networks' matrix products: ``single`` (float32, the default on
                             LLVM) or ``half`` (float16: the only choice, and the default, on
                             CUDA, where Dr.Jit maps them to OptiX cooperative vectors)
``fmbrdf_weights`` string    FMBRDF only: its helper networks' ``fmbrdf_weights.bin``; default
                             ``$NEURAL_BRDF_FMBRDF_WEIGHTS``, else the package's own copy (the
                             one ``brdf-analytic`` embeds)
=================  ========  ================================================================

Models: the neural kinds ``single_mlp``, ``additive_separate``, ``additive_shared`` and their
``_enhanced`` forms, read and checked as :mod:`neural_brdfs.reference_numpy` reads them and
evaluated step by step as it does (angle features, NeRF encoding, ReLU MLPs with skip and late
inputs, heads) with Dr.Jit: each linear layer (its skip or late input folded into the same
matrix) is one cooperative-vector ``drjit.nn.matvec``, float32 on LLVM (equal to ``Run.eval``
to a few 1e-6 relative); CUDA's OptiX cooperative vectors multiply float16 only (median 4e-3,
max 3e-2 relative; ``precision="half"`` reproduces it on LLVM). Unrolling the products into
scalar FMAs instead takes LLVM 15 s to compile at width 64, growing quadratically. The
parametric kinds ``rp`` (Realistic Phong), ``ts`` (Torrance-Sparrow, GGX), ``disney`` and
``fmbrdf`` (:mod:`neural_brdfs.mitsuba_parametric`): their parameter MLP (tensors ``mlp.*``)
runs the same way, then the output nonlinearities and the analytic BRDF follow the Rust tensor
twins operation for operation in float32 (rp, ts, disney equal ``Run.eval`` to about 1e-6
relative, fmbrdf to about 1e-5: the Rust model evaluates its Lambda network by segments).
FMBRDF also needs its two fixed helper networks (Smith Lambda, body reflection), which are not
in ``model.safetensors``: the package ships them (``brdf-analytic``'s
``assets/fmbrdf/fmbrdf_weights.bin``, MIT, through the native module), and ``fmbrdf_weights``
points elsewhere; its kernels take LLVM several seconds each to compile. A file that is not a ``neural-brdfs-weights`` description, or
weights that do not fit it, is refused with a ``ValueError`` naming the file and the fault
(Mitsuba's loader re-raises both as ``RuntimeError`` with the message). Needs a libLLVM >= 16
for the LLVM variants (Mitsuba 3.9.1 itself aborts on ``llvm.maximum`` with LLVM 14/15).

Conventions (those of ``model.json``): the model's local frame is Duff et al. 2017's orthonormal
basis around the shading normal, ``l`` towards the light, ``v`` towards the viewer, the output
f_r in linear RGB (Mitsuba's RGB variants work in linear sRGB: no conversion), 1/sr. Mitsuba's
``si.sh_frame`` shares the normal but its tangent follows the UV parametrisation, so ``si.wi``
and ``wo`` are rotated about the normal into the model's frame (z kept exactly). In radiance
transport (cameras) ``v = si.wi`` and ``l = wo``; in importance transport (light tracing) the
roles swap. The BSDF is
one-sided: zero unless both directions are above the shading normal's horizon. ``eval`` returns
``f_r cos(theta_o)`` as Mitsuba's BSDFs do. A reciprocity-mapped model is evaluated through its
mapping; others are evaluated for the true (l, v), as in our renderer.

Spatial variation: ``model.safetensors`` holds the per-vertex features
``spatial.vertex_features`` ``[V, dim]`` and the scene's triangles ``spatial.triangles``
``[T, 3]``. A hit on triangle ``si.prim_index`` with barycentrics ``(b1, b2)`` gets the row
``(1 - b1 - b2) s[t0] + b1 s[t1] + b2 s[t2]`` with the model's own triangle table, so the mesh
needs no extra attributes but must be the run's scene mesh in the same face order. The
barycentrics are ``si.uv``, which Mitsuba sets to ``(b1, b2)`` on meshes without texture
coordinates: the mesh must not carry UVs (the exported ``mesh.ply`` has none).

Kernels: the first render of a scene JIT-compiles the networks into Mitsuba's kernel (2-5 s on
LLVM at width 64; Dr.Jit then caches it on disk). Dr.Jit records every *live* instance of a BSDF
class into each BSDF call, so drop scenes no longer used (and ``gc.collect()``) before loading
the next, or each kernel grows by their networks (15-20 s compiles in ``benches/mitsuba_plugin``
before it freed them). :func:`render_pixel_centres` renders with our renderer's protocol.
"""

from __future__ import annotations

import json
import os

import drjit as dr
import mitsuba as mi
import numpy as np

from . import mitsuba_parametric as par
from . import reference_numpy as ref
from .mitsuba_sampling import fit_lobe

__all__ = ["register", "load_model", "render_pixel_centres", "mlp_specs", "PLUGIN_NAME",
           "SUPPORTED_KINDS", "UnsupportedModelError"]

PLUGIN_NAME = "neural_brdf"
#: The model kinds the plugin renders: every neural kind and every parametric one (FMBRDF
#: given its helper networks' weights, see :class:`DrJitModel`).
SUPPORTED_KINDS = tuple(ref.NEURAL_KINDS) + par.SUPPORTED


def mlp_specs(config):
    """The networks of a supported kind by tensor prefix (neural or parametric)."""
    if config.kind in ref.PARAMETRIC_KINDS:
        return par.mlp_specs(config)
    return ref.mlp_specs(config)


class UnsupportedModelError(ValueError):
    """A model the plugin cannot render: FMBRDF without its helper networks' weights."""


# ---------------------------------------------------------------------------------- loading
def load_model(filename, weights=None):
    """Reads and checks ``model.json`` and its weights: ``(config, spatial_kind, tensors,
    description)`` as :func:`neural_brdfs.reference_numpy.read_export`, with errors that name
    the file and the fault (``ValueError``)."""
    filename = os.fspath(filename)
    try:
        with open(filename, encoding="utf-8") as fh:
            desc = json.load(fh)
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise ValueError(f"{filename}: not a JSON model description ({e})") from None
    if not isinstance(desc, dict) or desc.get("format") != "neural-brdfs-weights":
        got = desc.get("format") if isinstance(desc, dict) else type(desc).__name__
        raise ValueError(f"{filename}: not a neural-brdfs weights description (format "
                         f"{got!r}, expected 'neural-brdfs-weights'; pass the run's model.json)")
    if desc.get("version") != 1:
        raise ValueError(f"{filename}: unsupported version {desc.get('version')!r} (expected 1)")
    model = dict(desc.get("model") or {})
    try:
        kind = ref.kind_name(model.get("kind", desc.get("kind", "single_mlp")))
    except ValueError as e:
        raise ValueError(f"{filename}: {e}") from None
    if kind not in SUPPORTED_KINDS:
        raise UnsupportedModelError(
            f"{filename}: model kind {kind!r} is not rendered by the {PLUGIN_NAME} plugin "
            f"(supported: {', '.join(SUPPORTED_KINDS)})")
    output = str((desc.get("conventions") or {}).get("output", "linear RGB"))
    if "linear" not in output:
        raise ValueError(f"{filename}: output convention {output!r} is not linear RGB")
    model["kind"] = kind
    try:
        config = ref.ModelConfig.from_json(model)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{filename}: bad model configuration: {e}") from None
    spatial = desc.get("spatial") or {}
    skind, sdim = spatial.get("kind", "lbo"), int(spatial.get("dim", config.spatial_dim))
    if skind not in ("lbo", "position", "uniform") or sdim != config.spatial_dim:
        raise ValueError(f"{filename}: bad spatial section {spatial!r} (kind lbo, position or "
                         f"uniform; dim = model.spatial_dim = {config.spatial_dim})")
    if weights is None:
        folder = os.path.dirname(filename)
        cands = [os.path.join(folder, f) for f in ref._WEIGHT_FILES]
        weights = next((c for c in cands if os.path.exists(c)), None)
        if weights is None:
            raise FileNotFoundError(f"{filename}: no weights beside it (looked for {cands})")
    weights = os.fspath(weights)
    try:
        tensors, _ = ref.read_safetensors(weights)
    except (ValueError, KeyError, TypeError, UnicodeDecodeError) as e:
        msg = str(e) if str(e).startswith(weights) else f"{weights}: {e}"
        raise ValueError(f"not a valid safetensors file: {msg}") from None
    expected = {}
    for prefix, spec in mlp_specs(config).items():
        expected.update(spec.shapes(prefix))
    expected.update(par.extra_tensors(config))
    got = {n: tuple(t.shape) for n, t in tensors.items() if not n.startswith("spatial.")}
    if got != expected:
        diff = sorted(set(got.items()) ^ set(expected.items()))[:8]
        raise ValueError(f"{weights}: tensors do not match model kind {kind} of {filename} "
                         f"(name, shape; file vs model symmetric difference): {diff}")
    vf, tr = tensors.get("spatial.vertex_features"), tensors.get("spatial.triangles")
    if skind != "uniform":
        if vf is None or tr is None:
            raise ValueError(f"{weights}: spatial kind {skind!r} needs spatial.vertex_features "
                             f"and spatial.triangles, which the file lacks")
        if vf.ndim != 2 or vf.shape[1] != sdim or tr.ndim != 2 or tr.shape[1] != 3:
            raise ValueError(f"{weights}: spatial tensors of shapes {vf.shape}, {tr.shape}; "
                             f"expected [V, {sdim}] and [T, 3]")
        if tr.size and (tr.min() < 0 or tr.max() >= vf.shape[0]):
            raise ValueError(f"{weights}: spatial.triangles names vertices outside "
                             f"vertex_features")
    for n, t in tensors.items():
        if t.dtype.kind == "f" and not np.isfinite(t).all():
            raise ValueError(f"{weights}: tensor {n!r} holds NaN or infinite values")
    return config, skind, tensors, desc


# ----------------------------------------------------------------- the model in Dr.Jit
PI, TAU, INV_PI = float(ref.PI_F32), float(ref.TAU_F32), float(ref.FRAC_1_PI_F32)


def _wrap_two_pi(phi):
    w = dr.select(phi < 0, phi + TAU, phi + 0.0)
    return dr.select(w >= TAU, 0.0, w)


def _hypot(x, y):
    return dr.sqrt(dr.fma(x, x, y * y))


def _half_frame_xy(a, w, len_a):
    rho = _hypot(a.x, a.y)
    ok = rho > 0
    r = dr.select(ok, rho, 1.0)
    cp, sp = dr.select(ok, a.x / r, 1.0), dr.select(ok, a.y / r, 0.0)
    ok = len_a > 0
    n = dr.select(ok, len_a, 1.0)
    ct, st = dr.select(ok, a.z / n, 1.0), dr.select(ok, rho / n, 0.0)
    x1 = w.x * cp + w.y * sp
    y1 = w.y * cp - w.x * sp
    return x1 * ct - w.z * st, y1, rho


def raw_angles(angles: ref.AngleConfig, l, v):
    """``reference_numpy.angle_features``'s raw angles (3, or 4 with the mapping) in Dr.Jit."""
    if angles.parametrization == "view_light" and angles.reciprocity != "mapping":
        cz = l.x * v.y - l.y * v.x
        dxy = l.x * v.x + l.y * v.y
        return [dr.atan2(_hypot(v.x, v.y), v.z), dr.atan2(_hypot(l.x, l.y), l.z),
                _wrap_two_pi(dr.atan2(cz, dxy))]
    a, w = l + v, l - v
    len_a = dr.norm(a)
    dx, dy, rho = _half_frame_xy(a, w, len_a)
    th, td = dr.atan2(rho, a.z), dr.atan2(dr.norm(w), len_a)
    if angles.reciprocity != "mapping":
        return [th, td, _wrap_two_pi(dr.atan2(dy, dx))]
    flip = (dy < 0) | ((dy == 0) & (dx < 0))
    dx, dy = dr.select(flip, -dx, dx), dr.select(flip, -dy, dy)
    phi = dr.atan2(dy + 0.0, dx + 0.0)
    phi = dr.select(phi >= PI, 0.0, phi)
    return [th, td, phi, phi + PI]


def angle_features(angles: ref.AngleConfig, l, v):
    """The NeRF-encoded direction features, a list of Floats (block order as the reference)."""
    p = raw_angles(angles, l, v)
    out = list(p) if angles.include_input else []
    base = PI if angles.pi_factor else 1.0
    for k in range(angles.frequencies):
        f = float(np.float32(np.float32(base) * np.float32(2.0 ** k)))
        sc = [dr.sincos(f * x) for x in p]
        out += [s for s, _ in sc] + [c for _, c in sc]
    return out


def _softplus(x):
    """burn's softplus (``x`` above 20, else log1p(exp(x))), accurate for negative x."""
    u = dr.exp(-dr.abs(x))
    one_u = 1.0 + u
    log1p = dr.select(one_u == 1.0, u, dr.log(one_u) * u / (one_u - 1.0))
    return dr.select(x > ref.SOFTPLUS_THRESHOLD, x, dr.select(x > 0, x, 0.0) + log1p)


def _sigmoid(x):
    return dr.rcp(1.0 + dr.exp(-x))


class _Mlp:
    """An :class:`~neural_brdfs.reference_numpy.MlpSpec` network as packed Dr.Jit matrices;
    the skip (raw input) and late inputs of a layer are extra columns of its matrix."""

    def __init__(self, spec: ref.MlpSpec, tensors, prefix):
        self.spec = spec
        self.mats, self.biases = [], []
        for k in range(spec.n_linear):
            w = [tensors[f"{prefix}.layers.{k}.weight"]]
            if k == spec.skip_into:
                w.append(tensors[f"{prefix}.skip.weight"])
            if spec.d_late > 0 and spec.late_into > 0 and k == spec.late_into:
                w.append(tensors[f"{prefix}.late.weight"])
            self.mats.append(np.ascontiguousarray(np.concatenate(w, 1), np.float32))
            self.biases.append(np.asarray(tensors[f"{prefix}.layers.{k}.bias"], np.float32))

    def pack(self, half=False):
        """Packs the matrices, float32 or (``half``) float16 (the only type OptiX's
        cooperative vectors multiply on CUDA)."""
        n, tensor = len(self.mats), mi.TensorXf
        self.half = half
        if half:
            tensor = dr.float16_array_t(mi.TensorXf)
        packed = dr.nn.pack(*[tensor(m) for m in self.mats],
                            *[tensor(b) for b in self.biases], layout="inference")
        self.views, self.bias_views = packed[:n], packed[n:]

    def __call__(self, x, late=None):
        """``x``, ``late``: lists of Floats; returns the outputs as a list of Floats."""
        s = self.spec
        if self.half:
            f16 = dr.float16_array_t(mi.Float)
            x = [f16(c) for c in x]
            late = None if late is None else [f16(c) for c in late]
        if late is not None and s.late_into == 0:
            x, late = x + late, None
        h = x
        for k in range(s.n_linear):
            inp = list(h) if not isinstance(h, list) else h
            if k == s.skip_into:
                inp = inp + x
            if late is not None and k == s.late_into:
                inp = inp + late
            z = dr.nn.matvec(self.views[k], dr.nn.CoopVec(*inp), self.bias_views[k])
            h = dr.maximum(z, 0.0) if k < s.hidden_layers else z
        return [mi.Float(c) for c in h] if self.half else list(h)


class DrJitModel:
    """A neural BRDF in Dr.Jit: ``f(prim_index, b1, b2, l, v)`` -> ``mi.Color3f``."""

    def __init__(self, config, spatial_kind, tensors, half=False, fmbrdf_weights=None):
        self.config, self.spatial_kind, self.half = config, spatial_kind, half
        self.parametric = config.kind in ref.PARAMETRIC_KINDS
        self.nets = {p: _Mlp(s, tensors, p) for p, s in mlp_specs(config).items()}
        for net in self.nets.values():
            net.pack(half)
        self.fm = None
        if config.kind == "fmbrdf":
            path = fmbrdf_weights or par.default_fmbrdf_weights()
            if not isinstance(path, bytes) and not os.path.exists(path):
                raise UnsupportedModelError(
                    f"model kind 'fmbrdf' (FMBRDF) needs the weights of FMBRDF's two fixed "
                    f"helper networks (Smith Lambda, body reflection): {path} (the plugin's "
                    f"'fmbrdf_weights' parameter or ${par.FMBRDF_WEIGHTS_ENV}) does not exist; "
                    f"without either, the package's own copy is used")
            alpha, beta, c = par.fmbrdf_globals(tensors["fm_alpha"], tensors["fm_beta"])
            nets = par.FmbrdfNets(par.read_fmbrdf_weights(path), alpha, beta, half)
            self.fm = (nets, alpha, beta, c)
        self.dim = config.spatial_dim
        if spatial_kind != "uniform":
            vf = np.asarray(tensors["spatial.vertex_features"], np.float32)
            tr = np.asarray(tensors["spatial.triangles"]).astype(np.uint32)
            self.vertex_count, self.triangle_count = vf.shape[0], tr.shape[0]
            self.table = mi.Float(vf.reshape(-1))
            self.triangles = mi.UInt32(tr.reshape(-1))

    def spatial(self, prim, b1, b2, active=True):
        if self.spatial_kind == "uniform":
            return [dr.full(mi.Float, 1.0, dr.width(b1))]
        ok = active & (prim < self.triangle_count)
        t = [dr.gather(mi.UInt32, self.triangles, prim * 3 + c, ok) * self.dim for c in range(3)]
        b0 = 1.0 - b1 - b2
        out = []
        for j in range(self.dim):
            s0, s1, s2 = (dr.gather(mi.Float, self.table, t[c] + j, ok) for c in range(3))
            x = b0 * s0 + b1 * s1 + b2 * s2
            x = dr.select(dr.isnan(x), 0.0, x)  # select, not dr.clip: LLVM 'fminimum' fails
            out.append(dr.select(x > 1e3, 1e3, dr.select(x < -1e3, -1e3, x)))
        return out

    def forward(self, x, l, v):
        c = self.config
        if self.parametric:
            return par.forward(c, self.nets["mlp"](x), l, v, self.fm)
        ang = angle_features(c.angles, l, v)
        if c.kind == "single_mlp":
            z = self.nets["mlp"](x, ang)
            return mi.Color3f(*[_softplus(zi) * c.single_mlp_softplus_scale for zi in z])
        if c.kind.startswith("additive_separate"):
            d, s = self.nets["diffuse"](x), self.nets["specular"](x, ang)
        else:
            t = self.nets["trunk"](x)
            d, s = self.nets["diffuse"](t), self.nets["specular"](t, ang)
        if c.albedo_clamp:
            lo, hi = ref.ALBEDO_RANGE_F32
            fd = [(_sigmoid(di) * float(hi - lo) + float(lo)) * INV_PI for di in d]
        else:
            fd = [_sigmoid(di) * INV_PI for di in d]
        n = 1 if c.scalar_specular else 3
        fs = [_softplus(si) * c.specular_softplus_scale for si in s[:n]]
        fs = fs * 3 if n == 1 else fs
        if c.enhanced:
            fd = [(1.0 - _sigmoid(xi)) * fdi for xi, fdi in zip(s[n:n + 3], fd)]
        return mi.Color3f(*[a + b for a, b in zip(fd, fs)])

    def __call__(self, prim, b1, b2, l, v, active=True):
        return self.forward(self.spatial(prim, b1, b2, active), l, v)


# ---------------------------------------------------------------------------- the BSDF
_classes = {}


def _bsdf_class():
    """The BSDF class for the current variant (``mi.BSDF`` differs between variants)."""
    variant = mi.variant()
    if variant in _classes:
        return _classes[variant]

    class NeuralBrdfBsdf(mi.BSDF):
        """``neural_brdf``: see :mod:`neural_brdfs.mitsuba`."""

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            if not mi.is_rgb or mi.is_polarized or not dr.is_jit_v(mi.Float):
                raise ValueError(f"{PLUGIN_NAME}: needs a JIT variant with RGB colours "
                                 f"(llvm_ad_rgb, cuda_ad_rgb, ...), not {mi.variant()}")
            if "filename" not in props:
                raise ValueError(f"{PLUGIN_NAME}: the 'filename' parameter (model.json) is "
                                 f"required")
            fr = mi.file_resolver()
            self.filename = str(fr.resolve(str(props["filename"])))
            weights = props.get("weights", None)
            self.weights = None if weights is None else str(fr.resolve(str(weights)))
            config, skind, tensors, _ = load_model(self.filename, self.weights)
            cuda = mi.variant().startswith("cuda")
            self.precision = str(props.get("precision", "half" if cuda else "single"))
            if self.precision not in ("single", "half") or (cuda and self.precision != "half"):
                raise ValueError(f"{PLUGIN_NAME}: precision must be 'single' or 'half' ('half' "
                                 f"on CUDA: OptiX multiplies float16 only), got "
                                 f"{self.precision!r}")
            fm_weights = props.get("fmbrdf_weights", None)
            if fm_weights is not None:
                fm_weights = str(fr.resolve(str(fm_weights)))
            self.model = DrJitModel(config, skind, tensors, self.precision == "half", fm_weights)
            self.sampling = str(props.get("sampling", "lobe"))
            if self.sampling not in ("lobe", "cosine"):
                raise ValueError(f"{PLUGIN_NAME}: sampling must be 'lobe' or 'cosine', got "
                                 f"{self.sampling!r}")
            n = props.get("lobe_exponent", None)
            w = props.get("lobe_weight", None)
            self.fit_info = None
            if self.sampling == "cosine":
                n, w = 1.0, 0.0
            elif n is None or w is None:
                if self.model.parametric:
                    reference = par.LobeFitModel(self.model, tensors, skind)
                else:
                    reference = ref._CLASSES[config.kind](config, tensors, skind, np.float32)
                fn, fw, self.fit_info = fit_lobe(reference)
                n = fn if n is None else n
                w = fw if w is None else w
            if not (float(n) >= 0 and 0 <= float(w) <= 1):
                raise ValueError(f"{PLUGIN_NAME}: lobe_exponent must be >= 0 and lobe_weight "
                                 f"in [0, 1], got {n}, {w}")
            self.lobe_exponent, self.lobe_weight = float(n), float(w)
            flags = (mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.DiffuseReflection
                     | mi.BSDFFlags.FrontSide)
            self.m_components = [flags]
            self.m_flags = flags

        def _model_dirs(self, ctx, si, wo):
            """``(l, v)`` in the model's (Duff) frame from Mitsuba's local ``si.wi``, ``wo``:
            both frames share n, so (x, y) turn by the 2x2 block of the change of basis and z
            is kept exactly (fewer roundings than to_world then to_local)."""
            sh, duff = si.sh_frame, mi.Frame3f(si.sh_frame.n)
            a, b = dr.dot(duff.s, sh.s), dr.dot(duff.s, sh.t)
            c, d = dr.dot(duff.t, sh.s), dr.dot(duff.t, sh.t)

            def rot(w):
                return mi.Vector3f(dr.fma(a, w.x, b * w.y), dr.fma(c, w.x, d * w.y), w.z)

            wi_m, wo_m = rot(si.wi), rot(wo)
            if ctx.mode == mi.TransportMode.Importance:
                return wi_m, wo_m  # l, v
            return wo_m, wi_m

        def _f_cos(self, ctx, si, wo, active):
            cos_i, cos_o = mi.Frame3f.cos_theta(si.wi), mi.Frame3f.cos_theta(wo)
            active = active & (cos_i > 0) & (cos_o > 0)
            if not ctx.is_enabled(mi.BSDFFlags.GlossyReflection, 0):
                return mi.Color3f(0.0)
            l, v = self._model_dirs(ctx, si, wo)
            f = self.model(si.prim_index, si.uv.x, si.uv.y, l, v, active)
            return dr.select(active, f * cos_o, 0.0)

        def _pdf(self, ctx, si, wo, active):
            n, w = self.lobe_exponent, self.lobe_weight
            cos_i, cos_o = mi.Frame3f.cos_theta(si.wi), mi.Frame3f.cos_theta(wo)
            r = mi.Vector3f(-si.wi.x, -si.wi.y, si.wi.z)
            p = (1.0 - w) * cos_o * INV_PI
            if w > 0:
                c = dr.dot(r, wo)
                c = dr.select(c > 0, c, 0.0)
                cn = dr.power(c, n) if n > 0 else dr.select(c > 0, 1.0, 0.0)
                p += w * (n + 1.0) / (2.0 * PI) * cn
            ok = active & (cos_i > 0) & (cos_o > 0)
            return dr.select(ok, p, 0.0)

        def eval(self, ctx, si, wo, active=True):
            return self._f_cos(ctx, si, wo, active)

        def pdf(self, ctx, si, wo, active=True):
            if not ctx.is_enabled(mi.BSDFFlags.GlossyReflection, 0):
                return mi.Float(0.0)
            return self._pdf(ctx, si, wo, active)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self._f_cos(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def sample(self, ctx, si, sample1, sample2, active=True):
            n, w = self.lobe_exponent, self.lobe_weight
            bs = dr.zeros(mi.BSDFSample3f)
            wo = mi.warp.square_to_cosine_hemisphere(sample2)
            lobe = sample1 < w
            if w > 0:
                r = mi.Vector3f(-si.wi.x, -si.wi.y, si.wi.z)
                c = dr.power(sample2.x, 1.0 / (n + 1.0))
                s = dr.safe_sqrt(1.0 - c * c)
                sn, cs = dr.sincos(2.0 * PI * sample2.y)
                wo = dr.select(lobe, mi.Frame3f(r).to_world(mi.Vector3f(s * cs, s * sn, c)), wo)
            active = active & (mi.Frame3f.cos_theta(si.wi) > 0) & (mi.Frame3f.cos_theta(wo) > 0)
            if not ctx.is_enabled(mi.BSDFFlags.GlossyReflection, 0):
                active = mi.Bool(False)
            value, pdf = self.eval_pdf(ctx, si, wo, active)
            bs.wo, bs.pdf, bs.eta = wo, pdf, 1.0
            bs.sampled_component = mi.UInt32(0)
            bs.sampled_type = dr.select(lobe, mi.UInt32(+mi.BSDFFlags.GlossyReflection),
                                        mi.UInt32(+mi.BSDFFlags.DiffuseReflection))
            ok = active & (pdf > 0)
            return bs, dr.select(ok, value / dr.select(ok, pdf, 1.0), 0.0)

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys=[]):
            pass

        def to_string(self):
            return (f"NeuralBrdf[filename={self.filename!r}, kind={self.model.config.kind!r}, "
                    f"precision={self.precision!r}, sampling={self.sampling!r}, "
                    f"lobe_exponent={self.lobe_exponent:g}, "
                    f"lobe_weight={self.lobe_weight:g}]")

    _classes[variant] = NeuralBrdfBsdf
    return NeuralBrdfBsdf


def render_pixel_centres(scene, seed=0):
    """Renders ``scene``'s first sensor with one camera ray through each pixel centre, shaded
    by the scene's integrator: our renderer's protocol (one surface point per pixel, no pixel
    filter), so with a directional emitter and ``direct`` the image is exact, comparable pixel
    for pixel with a run's ``renders/<stem>.exr``. ``(H, W, 3)`` float32 numpy."""
    sensor = scene.sensors()[0]
    w, h = sensor.film().crop_size()
    idx = dr.arange(mi.UInt32, w * h)
    pos = mi.Point2f((mi.Float(idx % w) + 0.5) / w, (mi.Float(idx // w) + 0.5) / h)
    ray, _ = sensor.sample_ray(0.0, 0.5, pos, mi.Point2f(0.5))
    sampler = sensor.sampler().clone()
    sampler.seed(seed, w * h)
    radiance, _, _ = scene.integrator().sample(scene, sampler, ray)
    return np.asarray(radiance, np.float32).T.reshape(h, w, 3)


def register():
    """Registers ``neural_brdf`` for the current Mitsuba variant (a no-op without one)."""
    if mi.variant() is None:
        return
    cls = _bsdf_class()
    mi.register_bsdf(PLUGIN_NAME, lambda props: cls(props))


register()
mi.detail.add_variant_callback(lambda *args: register())
