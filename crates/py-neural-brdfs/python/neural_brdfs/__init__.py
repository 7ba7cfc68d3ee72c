"""neural_brdfs: the neural-BRDF comparison workspace (Hofherr et al., WACV 2025) from Python.

* :class:`AnalyticBrdf`: Lambert, Realistic Phong, Torrance-Sparrow, Disney and FMBRDF, built
  from keyword parameters; ``eval``, ``sample`` and ``pdf`` on numpy arrays of local-frame
  directions (normal on +z, ``l`` towards the light, ``v`` towards the viewer), evaluated in
  float64 on all cores with the GIL released.
* :mod:`neural_brdfs.metrics`: PSNR, SSIM / DSSIM, HDR-FLIP and cube-root RMSE, each returned as
  a :class:`~neural_brdfs.metrics.Score` ``(value, settings)`` with the exact settings used.
* :class:`Scene`: a scene directory's images, flags, masks, cameras, lights, mesh and sample
  records as numpy arrays.
* :class:`Run`: a fitted run, evaluated at surface points and directions, and exported (MERL
  tables; glTF, Mitsuba 3 and pbrt-v4 scenes).
* :mod:`neural_brdfs.mitsuba` (optional, imported on its own; needs the ``mitsuba`` wheel): the
  Mitsuba 3 BSDF plugin ``neural_brdf`` rendering a neural run's ``model.json`` weights.

The conventions are those of the Rust crates (see ``docs/`` in the repository).
"""

import numpy as _np

from . import _native
from . import metrics
from ._native import Scene

__version__ = _native.__version__
__all__ = ["AnalyticBrdf", "Scene", "Run", "metrics", "to_local", "KINDS"]

#: The analytic BRDF kinds (aliases: ``rp``/``phong``, ``ts``).
KINDS = ("lambert", "realistic_phong", "torrance_sparrow", "disney", "fmbrdf")


def _rows(a, name, width=3, dtype=_np.float64):
    """``a`` as a C-contiguous ``(n, width)`` array of ``dtype`` and its leading shape."""
    a = _np.asarray(a, dtype=dtype)
    if a.ndim == 0 or a.shape[-1] != width:
        raise ValueError(f"{name}: expected an array of shape (..., {width}), got {a.shape}")
    return _np.ascontiguousarray(a.reshape(-1, width)), a.shape[:-1]


def to_local(normal, w):
    """World directions ``w`` ``(..., 3)`` in the local shading frame of ``normal`` (normal on
    +z): Duff et al. 2017's orthonormal basis, the frame training and evaluation use."""
    n = _np.asarray(normal, dtype=_np.float64)
    n = n / _np.linalg.norm(n, axis=-1, keepdims=True)
    x, y, z = n[..., 0], n[..., 1], n[..., 2]
    sign = _np.copysign(1.0, z)
    a = -1.0 / (sign + z)
    b = x * y * a
    t = _np.stack([1 + sign * x * x * a, sign * b, -sign * x], axis=-1)
    bt = _np.stack([b, sign + y * y * a, -y], axis=-1)
    w = _np.asarray(w, dtype=_np.float64)
    return _np.stack([(w * t).sum(-1), (w * bt).sum(-1), (w * n).sum(-1)], axis=-1)


def _param(v):
    if isinstance(v, (bool, _np.bool_)):
        return bool(v)
    arr = _np.asarray(v)
    if arr.ndim == 0:
        return float(arr)
    return tuple(float(x) for x in arr.reshape(-1))


class AnalyticBrdf:
    """An analytic BRDF, ``AnalyticBrdf(kind, **params)``.

    >>> b = AnalyticBrdf("disney", base_color=(0.8, 0.2, 0.1), roughness=0.3)
    >>> f = b.eval(l, v)            # (..., 3) RGB, 1/sr, without the cosine

    Parameters out of range raise ``ValueError`` naming the parameter and its range; unknown
    keywords raise ``TypeError`` listing the known ones. RGB parameters take one number (grey)
    or three. Directions are unit vectors of shape ``(..., 3)``; batch shapes broadcast.
    """

    def __init__(self, kind, **params):
        self._native = _native.AnalyticBrdf(kind, **{k: _param(v) for k, v in params.items()})

    @property
    def kind(self):
        """The canonical kind (``lambert``, ``realistic_phong``, ...)."""
        return self._native.kind

    @property
    def reciprocal(self):
        """Whether f(l, v) = f(v, l) (all but FMBRDF)."""
        return self._native.reciprocal

    @property
    def params(self):
        """The parameters as used (after the model's clamping)."""
        return dict(self._native.params())

    def eval(self, l, v):
        """f_r(l, v), shape ``(..., 3)``, float64; zero below the horizon."""
        l, v = _np.broadcast_arrays(_np.asarray(l, _np.float64), _np.asarray(v, _np.float64))
        lr, shape = _rows(l, "l")
        vr, _ = _rows(v, "v")
        return self._native.eval(lr, vr).reshape(shape + (3,))

    def sample(self, v, u):
        """Draws ``l`` for each ``v`` from uniforms ``u`` ``(..., 2)`` in [0, 1).

        Returns ``(l, weight, pdf, valid)``: weight = f cos / pdf; rows without a sample
        (``v`` below the horizon, a reflection below it) are zeros with ``valid`` False.
        """
        vr, shape = _rows(v, "v")
        ur, ushape = _rows(u, "u", width=2)
        if ushape != shape:
            raise ValueError(f"u has batch shape {ushape} but v has {shape}")
        l, w, pdf, valid = self._native.sample(vr, ur)
        return (
            l.reshape(shape + (3,)),
            w.reshape(shape + (3,)),
            pdf.reshape(shape),
            valid.reshape(shape),
        )

    def pdf(self, v, l):
        """The density of sampling ``l`` given ``v``, per solid angle, shape ``(...)``."""
        v, l = _np.broadcast_arrays(_np.asarray(v, _np.float64), _np.asarray(l, _np.float64))
        vr, shape = _rows(v, "v")
        lr, _ = _rows(l, "l")
        return self._native.pdf(vr, lr).reshape(shape)

    def __repr__(self):
        return repr(self._native)


class Run:
    """A fitted run directory, ``Run(path, scene=None, cache=None)``.

    ``scene`` overrides the scene directory recorded in the run's ``config.toml`` and
    ``cache`` its eigenpair cache.
    """

    def __init__(self, path, scene=None, cache=None):
        self._native = _native.Run(
            str(path), None if scene is None else str(scene), None if cache is None else str(cache)
        )

    path = property(lambda self: self._native.path, doc="The run directory.")
    kind = property(lambda self: self._native.kind, doc="The model kind (config name).")
    paper_name = property(lambda self: self._native.paper_name, doc="The model's name in the paper.")
    scene_path = property(lambda self: self._native.scene_path, doc="The scene directory.")

    def config_toml(self):
        """The run's configuration as TOML text."""
        return self._native.config_toml()

    def samples(self, split="test"):
        """The sample records of the run's scene (as :meth:`Scene.samples`)."""
        return self._native.samples(split)

    def eval(self, triangle, barycentric, l, v, normal=None, parts=False):
        """f_r at surface points for directions ``l``, ``v``.

        A point is a mesh ``triangle`` and ``barycentric`` ``(b1, b2)`` (as in the sample
        records). Directions are local-frame unit vectors, or world-space ones when the
        shading ``normal`` is given. Returns ``(n, 3)`` float32, or with ``parts`` a dict with
        ``f`` and, for additive models, ``diffuse``, ``diffuse_raw`` and ``specular``.
        """
        tri = _np.ascontiguousarray(_np.asarray(triangle).reshape(-1), dtype=_np.uint32)
        bary, _ = _rows(barycentric, "barycentric", width=2, dtype=_np.float32)
        lr, _ = _rows(l, "l", dtype=_np.float32)
        vr, _ = _rows(v, "v", dtype=_np.float32)
        nr = None if normal is None else _rows(normal, "normal", dtype=_np.float32)[0]
        return self._native.eval(tri, bary, lr, vr, nr, parts)

    def eval_samples(self, samples, parts=False):
        """f_r for sample records (a dict from :meth:`samples` or :meth:`Scene.samples`)."""
        return self.eval(
            samples["triangle"],
            samples["barycentric"],
            samples["l"],
            samples["v"],
            normal=samples["normal"],
            parts=parts,
        )

    def export_merl(self, out, vertex=None):
        """Writes the fitted BRDF at one surface point as a MERL ``.binary`` table."""
        return self._native.export_merl(str(out), vertex)

    def save_portable(self, out):
        """Writes ``model.safetensors`` and ``model.json`` (PyTorch layout; see
        :mod:`neural_brdfs.reference_numpy`) into ``out``; training writes them into the run
        directory already."""
        return self._native.save_portable(str(out))

    def export(self, out, formats="all"):
        """Writes the fitted material and test views for renderers (glTF, Mitsuba 3, pbrt-v4)."""
        return self._native.export(str(out), formats)

    def __repr__(self):
        return f"Run({str(self.path)!r}, kind={self.kind!r})"
