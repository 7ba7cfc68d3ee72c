"""FMBRDF's helper-network weights (``fmbrdf_weights.bin``), read in one place for the torch
reference and the Mitsuba plugin: where they come from (:func:`default_fmbrdf_weights`) and
their tensors, checked by name and shape (:func:`read_fmbrdf_weights`). numpy only."""

from __future__ import annotations

import os
import struct

import numpy as np

__all__ = ["FMBRDF_WEIGHTS_ENV", "FMBRDF_TENSORS", "default_fmbrdf_weights",
           "read_fmbrdf_weights"]

FMBRDF_WEIGHTS_ENV = "NEURAL_BRDF_FMBRDF_WEIGHTS"
# The helper networks' layers and their weight shapes (out, in).
FMBRDF_TENSORS = (
    [(f"shadowing.fc{k}", s) for k, s in ((1, (300, 4)), (2, (100, 300)), (3, (50, 100)),
                                         (4, (1, 50)))]
    + [(f"body_reflection.fc_I{k}", s) for k, s in ((1, (200, 11)), (2, (100, 200)),
                                                   (3, (100, 100)), (4, (1, 100)))])


def default_fmbrdf_weights():
    """``$NEURAL_BRDF_FMBRDF_WEIGHTS`` (a path), else the bytes of ``brdf-analytic``'s
    ``assets/fmbrdf/fmbrdf_weights.bin`` from the native module (as the Mitsuba plugin)."""
    env = os.environ.get(FMBRDF_WEIGHTS_ENV)
    if env:
        return env
    try:
        from . import _native
    except ImportError:
        raise FileNotFoundError(
            f"FMBRDF's helper networks' weights: the native module is not importable here; "
            f"set ${FMBRDF_WEIGHTS_ENV} or pass fmbrdf_weights (a path to "
            f"crates/brdf-analytic/assets/fmbrdf/fmbrdf_weights.bin)") from None
    return bytes(_native.fmbrdf_weights_file())


def read_fmbrdf_weights(path):
    """FMBRDF's helper-network tensors of ``fmbrdf_weights.bin`` (a path or its bytes; format:
    ``assets/fmbrdf/NOTICE.md``: magic ``FMBRDFW1``, u32 count, then per tensor u32 name
    length, name, u32 ndim, u32 dims, f32 LE data): ``{name: float32 array}``, checked."""
    if isinstance(path, (bytes, bytearray)):
        data, path = bytes(path), "the package's FMBRDF weights"
    else:
        with open(path, "rb") as fh:
            data = fh.read()
    if data[:8] != b"FMBRDFW1":
        raise ValueError(f"{path}: not an FMBRDF weights file (magic {data[:8]!r})")
    try:
        (count,), pos, out = struct.unpack_from("<I", data, 8), 12, {}
        for _ in range(count):
            (n,) = struct.unpack_from("<I", data, pos)
            name = data[pos + 4:pos + 4 + n].decode()
            (ndim,) = struct.unpack_from("<I", data, pos + 4 + n)
            dims = struct.unpack_from(f"<{ndim}I", data, pos + 8 + n)
            pos += 8 + n + 4 * ndim
            size = int(np.prod(dims))
            out[name] = np.frombuffer(data, "<f4", size, pos).reshape(dims).astype(np.float32)
            pos += 4 * size
    except (struct.error, ValueError, UnicodeDecodeError) as e:
        raise ValueError(f"{path}: truncated or malformed FMBRDF weights file ({e})") from None
    for name, shape in FMBRDF_TENSORS:
        w, b = out.get(name + ".weight"), out.get(name + ".bias")
        if w is None or b is None or w.shape != shape or b.shape != shape[:1]:
            raise ValueError(f"{path}: lacks {name}.weight {shape} / .bias {shape[:1]}")
    return out
