"""The metrics from Python: against scikit-image's SSIM, NVIDIA's flip-evaluator (where it
installs) and numpy formulas, with their settings; bad images, values outside a space's range
and a black background without a mask or exposures are clear errors."""

import numpy as np
import pytest

from neural_brdfs import metrics


def pair(h, w, seed, gain=1.0):
    rng = np.random.default_rng(seed)
    ref = rng.random((h, w, 3), dtype=np.float32) * gain
    test = np.clip(ref + rng.normal(0, 0.05 * gain, ref.shape), 0, None).astype(np.float32)
    return test, ref


def display_pair(h, w, seed):
    """``pair`` with the test image clipped to display values in [0, 1]."""
    test, ref = pair(h, w, seed)
    return np.clip(test, 0, 1), ref


def disc_on_black(size=32, radiance=4.0):
    """A linear HDR render of a bright disc on a black background (the field's usual image: the
    median pixel is black), a test render 10 % darker, and the disc's mask."""
    y, x = np.mgrid[:size, :size] + 0.5
    inside = (x - size / 2) ** 2 + (y - size / 2) ** 2 < (size / 4) ** 2
    ref = np.zeros((size, size, 3), np.float32)
    ref[inside] = np.float32([1.0, 0.8, 0.6]) * radiance
    return ref * np.float32(0.9), ref, inside


def test_psnr_matches_numpy_to_1e_9_and_reports_its_settings():
    t, r = display_pair(20, 30, 1)
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
    t, r = display_pair(8, 8, 5)
    with pytest.raises(ValueError, match="expected an \\(H, W, 3\\)"):
        metrics.psnr(t[..., :2], r[..., :2])
    with pytest.raises(ValueError, match="size|match"):
        metrics.psnr(t[:4], r)
    bad = t.copy()
    bad[2, 3, 1] = np.nan
    with pytest.raises(ValueError, match="NaN|not finite"):
        metrics.ssim(bad, r)
    with pytest.raises(ValueError, match="NaN|not finite"):  # NaN first, not the range
        metrics.psnr(bad * 4, r)
    with pytest.raises(ValueError, match="mask: shape"):
        metrics.psnr(t, r, mask=np.ones((4, 4), bool))
    with pytest.raises(ValueError, match="space must be"):
        metrics.psnr(t, r, space="log")


@pytest.mark.parametrize("metric", [metrics.psnr, metrics.ssim, metrics.dssim])
@pytest.mark.parametrize("which", ["test", "reference"])
def test_display_space_rejects_linear_hdr_values_naming_the_image(metric, which):
    hdr, _, _ = disc_on_black()
    hdr[0, 0] = 4.5  # the maximum, on the background
    ldr = np.clip(hdr, 0, 1) * np.float32(0.8)
    args = (hdr, ldr) if which == "test" else (ldr, hdr)
    with pytest.raises(ValueError, match=rf'^{which}: maximum 4\.5 is above 1, but space="display"'
                       r'.*pass space="linear" for linear \(HDR\) renders.*clip'):
        metric(*args)
    with pytest.raises(ValueError, match=rf"^{which}: maximum 4\.5"):  # masked-out pixels too
        metric(*args, mask=hdr[..., 0] < 4.5)
    assert np.isfinite(metric(*args, space="linear").value)


@pytest.mark.parametrize("metric", [metrics.psnr, metrics.ssim, metrics.dssim])
@pytest.mark.parametrize("space", ["display", "linear"])
@pytest.mark.parametrize("which", ["test", "reference"])
def test_negative_values_are_rejected_in_both_spaces_naming_the_image(metric, space, which):
    t, r = display_pair(32, 32, 11)
    neg = (t if which == "test" else r).copy()
    neg[3, 4, 2] = -0.25
    args = (neg, r) if which == "test" else (t, neg)
    want = rf'^{which}: minimum -0\.25 is below 0, but space="{space}"'
    with pytest.raises(ValueError, match=want):
        metric(*args, space=space)


def test_images_in_range_still_work_in_both_spaces():
    t, r = display_pair(32, 32, 12)
    t[0, 0], r[0, 0], r[1, 1] = 0.0, 1.0, 0.0  # the bounds themselves are in range
    for metric in (metrics.psnr, metrics.ssim, metrics.dssim):
        s = metric(t, r)
        assert np.isfinite(s.value) and s.settings["space"] == "display"
    assert np.isfinite(metrics.ssim(t * 255, r * 255, data_range=255.0).value)
    with pytest.raises(ValueError, match="^test: maximum 255 is above 1"):
        metrics.ssim(t * 255, r * 255)
    ht, hr = pair(32, 32, 13, gain=3.0)  # linear HDR, up to 3
    assert hr.max() > 1
    for metric in (metrics.psnr, metrics.ssim, metrics.dssim):
        s = metric(ht, hr, space="linear")
        assert np.isfinite(s.value) and s.settings["space"] == "linear"
    ht, hr, inside = disc_on_black(radiance=0.5)  # an object on black: fine for PSNR and SSIM
    assert np.isfinite(metrics.psnr(ht, hr, space="linear").value)
    assert np.isfinite(metrics.ssim(ht, hr, mask=inside, space="linear").value)


def test_hdr_flip_on_a_black_background_asks_for_a_mask_or_exposures():
    t, r, inside = disc_on_black()
    assert np.median(r) == 0
    with pytest.raises(ValueError, match="median luminance 0") as e:
        metrics.hdr_flip(t, r)
    assert "mask=" in str(e.value) and "start_exposure=" in str(e.value)
    assert "stop_exposure=" in str(e.value)
    with pytest.raises(ValueError, match="mask=.*start_exposure="):  # one exposure is not enough
        metrics.hdr_flip(t, r, start_exposure=-1.0)
    masked = metrics.hdr_flip(t, r, mask=inside)
    assert np.isfinite(masked.value) and 0 < masked.value < 1
    assert masked.settings["exposures_from"] == "reference"
    assert masked.settings["pixels"] == inside.sum()
    given, fmap = metrics.hdr_flip(t, r, start_exposure=-2.0, stop_exposure=1.0, return_map=True)
    assert np.isfinite(given.value) and 0 < given.value < 1
    assert given.settings["exposures_from"] == "given"
    assert given.settings["start_exposure"] == -2.0 and given.settings["stop_exposure"] == 1.0
    assert fmap.shape == (32, 32) and np.all(np.isfinite(fmap))
