"""Image and BRDF metrics, each returned with the exact settings it used.

Images are ``(H, W, 3)`` RGB arrays (converted to float32); masks ``(H, W)`` bool. PSNR and
SSIM work on display values in [0, 1] (``space="display"``, the default) or on linear images
through the clamped sRGB OETF (``space="linear"``); HDR-FLIP takes linear HDR images. Values
outside a space's range are errors naming the image, not silently wrong scores: above 1 or below
0 in ``display`` (a linear HDR render passed without ``space="linear"``), below 0 in ``linear``.
Every function returns a :class:`Score` ``(value, settings)``.
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


def _in_range(a, name, space, top=1.0):
    """``a`` after checking it lies in ``space``'s range: [0, ``top``] for ``display`` (``top``
    is SSIM's ``data_range``, else 1), >= 0 for ``linear``. One min and one max over the whole
    image (masked-out pixels too). A NaN makes both NaN, so no comparison holds and the native
    check reports it with its pixel; an unknown ``space`` is left to the native error too."""
    if a.size == 0 or space not in ("display", "linear"):
        return a
    lo, hi = float(a.min()), float(a.max())
    if space == "display" and hi > top:
        raise ValueError(
            f'{name}: maximum {hi:.6g} is above {top:g}, but space="display" takes display '
            f'values in [0, {top:g}]; pass space="linear" for linear (HDR) renders, or clip '
            f'display values to [0, {top:g}]')
    if space == "display" and lo < 0.0:
        raise ValueError(
            f'{name}: minimum {lo:.6g} is below 0, but space="display" takes display values in '
            f'[0, {top:g}]; clip display values to [0, {top:g}] (space="linear", for linear '
            f'(HDR) renders, rejects negative values too)')
    if lo < 0.0:
        raise ValueError(
            f'{name}: minimum {lo:.6g} is below 0, but space="linear" takes linear radiance, '
            f'which is non-negative; clip the image at 0 if the negative values are noise')
    return a


def _pair(test, reference, space, top=1.0):
    return (_in_range(_image(test, "test"), "test", space, top),
            _in_range(_image(reference, "reference"), "reference", space, top))


def psnr(test, reference, mask=None, space="display"):
    """PSNR of display-space images in [0, 1] (sRGB); for linear HDR renders pass space="linear".

    In dB with data range 1 (``inf`` for identical images). Values outside [0, 1] in
    ``display``, or below 0 in ``linear``, raise a ``ValueError`` naming the image."""
    t, r = _pair(test, reference, space)
    v, s = _native.psnr(t, r, _mask(mask), space)
    return Score(v, s)


def ssim(test, reference, mask=None, space="display", sigma=1.5, truncate=3.5, k1=0.01,
         k2=0.03, data_range=1.0):
    """SSIM of display-space images in [0, 1] (sRGB); for linear HDR renders pass space="linear".

    Gaussian window; without a mask it equals scikit-image's
    ``structural_similarity(x, y, channel_axis=-1, data_range=1, gaussian_weights=True,
    sigma=1.5, use_sample_covariance=False)``. Values outside [0, ``data_range``] in
    ``display``, or below 0 in ``linear``, raise a ``ValueError`` naming the image."""
    top = float(data_range) if data_range > 0 else 1.0  # a bad data_range: the native error
    t, r = _pair(test, reference, space, top)
    v, s = _native.ssim(t, r, _mask(mask), space, sigma, truncate, k1, k2, data_range)
    return Score(v, s)


def dssim(test, reference, mask=None, space="display", **ssim_settings):
    """DSSIM of display-space images in [0, 1] (sRGB); for linear HDR renders pass space="linear".

    DSSIM = (1 - SSIM) / 2, with :func:`ssim`'s settings and range checks."""
    v, s = ssim(test, reference, mask, space, **ssim_settings)
    s = dict(s, metric="dssim", definition="(1 - ssim) / 2")
    return Score((1.0 - v) / 2.0, s)


def hdr_flip(test, reference, mask=None, pixels_per_degree=None, start_exposure=None,
             stop_exposure=None, return_map=False):
    """HDR-FLIP (Andersson et al. 2021) of linear HDR images (radiance, not display values).

    Exposures come from the reference's (masked) luminance unless both are given. A reference
    whose median luminance is 0, such as an object on a black background, has no exposure range:
    that is a ``ValueError`` asking for ``mask=`` (the object's pixels) or explicit
    ``start_exposure=`` and ``stop_exposure=``. With ``return_map``, returns
    ``(Score, error map (H, W))``."""
    ppd = _native.FLIP_DEFAULT_PPD if pixels_per_degree is None else float(pixels_per_degree)
    try:
        v, s, m = _native.hdr_flip(_image(test, "test"), _image(reference, "reference"),
                                   _mask(mask), ppd, start_exposure, stop_exposure)
    except ValueError as e:
        if "zero median" not in str(e):
            raise
        raise ValueError(
            "reference: median luminance 0 (e.g. an object on a black background), so HDR-FLIP "
            "cannot derive its exposure range (the stop exposure log2(2.11887 / median) is "
            "infinite); pass mask= (the object's pixels: the exposures then come from their "
            "luminance) or both start_exposure= and stop_exposure= (log2 exposures)") from e
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
