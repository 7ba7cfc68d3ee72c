"""The metrics from Python: against scikit-image's SSIM, NVIDIA's flip-evaluator (where it
installs) and numpy formulas, with their settings; bad images are clear errors."""

import numpy as np
import pytest

from neural_brdfs import metrics


def pair(h, w, seed, gain=1.0):
    rng = np.random.default_rng(seed)
    ref = rng.random((h, w, 3), dtype=np.float32) * gain
    test = np.clip(ref + rng.normal(0, 0.05 * gain, ref.shape), 0, None).astype(np.float32)
    return test, ref


def test_psnr_matches_numpy_to_1e_9_and_reports_its_settings():
    t, r = pair(20, 30, 1)
    s = metrics.psnr(t, r)
    mse = np.mean((t.astype(np.float64) - r) ** 2)
    assert abs(s.value - 10 * np.log10(1 / mse)) < 1e-9
    assert s.settings["space"] == "display" and s.settings["pixels"] == 600
    assert metrics.psnr(r, r).value == np.inf
    m = np.zeros((20, 30), bool)
    m[5:10, 5:25] = True
    masked = metrics.psnr(t, r, mask=m)
    mse_m = np.mean((t[m].astype(np.float64) - r[m]) ** 2)
    assert abs(masked.value - 10 * np.log10(1 / mse_m)) < 1e-9 and masked.settings["pixels"] == 100


@pytest.mark.parametrize("shape", [(32, 48), (17, 23), (64, 64)])
def test_ssim_equals_scikit_image_to_1e_6(shape):
    skimage_metrics = pytest.importorskip("skimage.metrics")
    t, r = pair(*shape, seed=shape[0])
    t = np.clip(t, 0, 1)
    ours = metrics.ssim(t, r)
    ref = skimage_metrics.structural_similarity(
        t.astype(np.float64), r.astype(np.float64), channel_axis=-1, data_range=1,
        gaussian_weights=True, sigma=1.5, use_sample_covariance=False)
    assert abs(ours.value - ref) < 1e-6, (ours.value, ref)
    assert ours.settings["window"] == 11 and ours.settings["sigma"] == 1.5
    d = metrics.dssim(t, r)
    assert abs(d.value - (1 - ours.value) / 2) < 1e-15 and d.settings["metric"] == "dssim"


def test_linear_space_applies_the_clamped_srgb_oetf():
    t, r = pair(16, 16, 3, gain=2.0)
    oetf = lambda x: np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(np.clip(x, 0.0031308, None), 1 / 2.4) - 0.055)
    enc = lambda x: np.clip(oetf(np.clip(x, 0, 1).astype(np.float64)), 0, 1).astype(np.float32)
    assert abs(metrics.psnr(t, r, space="linear").value - metrics.psnr(enc(t), enc(r)).value) < 1e-4


@pytest.mark.parametrize("gain", [1.0, 300.0])
def test_hdr_flip_matches_nvidia_flip_evaluator_to_1e_4(gain):
    flip = pytest.importorskip("flip_evaluator")
    t, r = pair(40, 31, 9, gain)
    ours, fmap = metrics.hdr_flip(t, r, return_map=True)
    emap, mean, params = flip.evaluate(r, t, "HDR", applyMagma=False)
    assert abs(ours.value - mean) < 1e-4, (ours.value, mean)
    assert np.max(np.abs(fmap - np.squeeze(emap))) < 1e-3
    assert abs(ours.settings["start_exposure"] - params["startExposure"]) < 1e-4
    assert abs(ours.settings["stop_exposure"] - params["stopExposure"]) < 1e-4
    assert ours.settings["exposures"] == params["numExposures"]


def test_hdr_flip_reports_derived_exposures():
    t, r = pair(24, 17, 5, 4.0)
    s = metrics.hdr_flip(t, r)
    assert s.settings["exposures_from"] == "reference"
    assert s.settings["start_exposure"] < s.settings["stop_exposure"]
    given = metrics.hdr_flip(t, r, start_exposure=-1.0, stop_exposure=1.0)
    assert given.settings["exposures_from"] == "given"


def test_cube_root_rmse_matches_numpy_and_counts_dropped_samples():
    rng = np.random.default_rng(4)
    n = 1000
    pred, gt = rng.random((n, 3)), rng.random((n, 3))
    cl, cv = rng.random(n), rng.random(n)
    sat = rng.random(n) < 0.1
    s = metrics.cube_root_rmse(pred, gt, cl, cv, saturated=sat)
    cut = np.cos(np.radians(80))
    keep = (cl.astype(np.float32) >= cut) & (cv.astype(np.float32) >= cut) & ~sat
    p, g = pred.astype(np.float32)[keep], gt.astype(np.float32)[keep]
    want = np.sqrt(np.mean((np.cbrt(p.astype(np.float64)) - np.cbrt(g.astype(np.float64))) ** 2))
    assert abs(s.value - want) < 1e-6, (s.value, want)
    assert s.settings["kept"] == keep.sum()
    assert s.settings["kept"] + s.settings["grazing"] + s.settings["saturated"] == n


def test_bad_images_are_clear_errors():
    t, r = pair(8, 8, 5)
    with pytest.raises(ValueError, match="expected an \\(H, W, 3\\)"):
        metrics.psnr(t[..., :2], r[..., :2])
    with pytest.raises(ValueError, match="size|match"):
        metrics.psnr(t[:4], r)
    bad = t.copy()
    bad[2, 3, 1] = np.nan
    with pytest.raises(ValueError, match="NaN|not finite"):
        metrics.ssim(bad, r)
    with pytest.raises(ValueError, match="mask: shape"):
        metrics.psnr(t, r, mask=np.ones((4, 4), bool))
    with pytest.raises(ValueError, match="space must be"):
        metrics.psnr(t, r, space="log")
