"""Image and BRDF metrics, each returned with the exact settings it used.

Images are ``(H, W, 3)`` RGB arrays (converted to float32); masks ``(H, W)`` bool. PSNR and
SSIM work on display values in [0, 1] (``space="display"``) or on linear images through the
clamped sRGB OETF (``space="linear"``); HDR-FLIP takes linear HDR images. Every function
returns a :class:`Score` ``(value, settings)``.
"""

from collections import namedtuple

import numpy as _np

from . import _native

__all__ = ["Score", "psnr", "ssim", "dssim", "hdr_flip", "cube_root_rmse"]

#: A metric value with the settings that produced it.
Score = namedtuple("Score", ["value", "settings"])


def _image(a, name):
    a = _np.ascontiguousarray(a, dtype=_np.float32)
    if a.ndim != 3 or a.shape[2] != 3:
        raise ValueError(f"{name}: expected an (H, W, 3) RGB image, got shape {a.shape}")
    return a


def _mask(m):
    return None if m is None else _np.ascontiguousarray(m, dtype=bool)


def psnr(test, reference, mask=None, space="display"):
    """PSNR in dB (data range 1; ``inf`` for identical images)."""
    v, s = _native.psnr(_image(test, "test"), _image(reference, "reference"), _mask(mask), space)
    return Score(v, s)


def ssim(test, reference, mask=None, space="display", sigma=1.5, truncate=3.5, k1=0.01,
         k2=0.03, data_range=1.0):
    """SSIM with a Gaussian window; without a mask it equals scikit-image's
    ``structural_similarity(x, y, channel_axis=-1, data_range=1, gaussian_weights=True,
    sigma=1.5, use_sample_covariance=False)``."""
    v, s = _native.ssim(_image(test, "test"), _image(reference, "reference"), _mask(mask), space,
                        sigma, truncate, k1, k2, data_range)
    return Score(v, s)


def dssim(test, reference, mask=None, space="display", **ssim_settings):
    """DSSIM = (1 - SSIM) / 2."""
    v, s = ssim(test, reference, mask, space, **ssim_settings)
    s = dict(s, metric="dssim", definition="(1 - ssim) / 2")
    return Score((1.0 - v) / 2.0, s)


def hdr_flip(test, reference, mask=None, pixels_per_degree=None, start_exposure=None,
             stop_exposure=None, return_map=False):
    """HDR-FLIP (Andersson et al. 2021) of linear images; exposures from the reference unless
    given. With ``return_map``, returns ``(Score, error map (H, W))``."""
    ppd = _native.FLIP_DEFAULT_PPD if pixels_per_degree is None else float(pixels_per_degree)
    v, s, m = _native.hdr_flip(_image(test, "test"), _image(reference, "reference"),
                               _mask(mask), ppd, start_exposure, stop_exposure)
    score = Score(v, s)
    return (score, m) if return_map else score


def cube_root_rmse(pred, gt, cos_theta_l, cos_theta_v, saturated=None, max_angle_deg=80.0):
    """RMSE of cube roots of BRDF values (Lavoue et al. 2021) over samples ``(n, 3)``;
    samples beyond ``max_angle_deg``, saturated or with an invalid ground truth are dropped
    (counted in the settings). Raw value: the paper's tables multiply it by 100."""
    f32 = lambda a: _np.ascontiguousarray(a, dtype=_np.float32)
    sat = None if saturated is None else _np.ascontiguousarray(saturated, dtype=bool).reshape(-1)
    v, s = _native.cube_root_rmse(
        f32(pred).reshape(-1, 3), f32(gt).reshape(-1, 3), f32(cos_theta_l).reshape(-1),
        f32(cos_theta_v).reshape(-1), sat, float(max_angle_deg))
    return Score(v, s)
