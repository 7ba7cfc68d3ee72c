"""Scenes and fitted runs from Python, on a miniature sweep (conftest.py): arrays that agree
with each other (records against images, flags against masks), the round trip scene -> numpy
-> metrics, model evaluation in local and world frames, exports and errors."""

import numpy as np
import pytest

import neural_brdfs as nb
from neural_brdfs import metrics

FOREGROUND = 1 | 2 | 4


def duff_frame(n):
    """Duff et al. 2017's orthonormal basis (the frame training uses), rows t, b, n."""
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    sign = np.copysign(1.0, n[:, 2])
    a = -1.0 / (sign + n[:, 2])
    bb = n[:, 0] * n[:, 1] * a
    t = np.stack([1 + sign * n[:, 0] ** 2 * a, sign * bb, -sign * n[:, 0]], axis=1)
    b = np.stack([bb, sign + n[:, 1] ** 2 * a, -n[:, 1]], axis=1)
    return np.stack([t, b, n], axis=1)


def test_scene_arrays_agree_with_each_other(scene_dir):
    s = nb.Scene(scene_dir)
    assert (s.width, s.height, s.view_count) == (48, 48, 4)
    cam = s.camera(0)
    assert cam["K"].shape == (3, 3) and cam["R"].shape == (3, 3) and cam["t"].shape == (3,)
    np.testing.assert_allclose(cam["R"] @ cam["R"].T, np.eye(3), atol=1e-5)
    lights = s.lights(0)
    assert lights["direction"].shape == (12, 3)
    np.testing.assert_allclose(np.linalg.norm(lights["direction"], axis=1), 1, atol=1e-5)
    img = s.image(0, 0)
    assert img.shape == (48, 48, 3) and img.dtype == np.float32 and np.isfinite(img).all()
    mask = s.mask(0)
    assert 50 < mask.sum() < 48 * 48
    flags = s.flags(0, 0)
    np.testing.assert_array_equal((flags & FOREGROUND) != 0, mask)
    pos, tri = s.mesh()
    assert pos.shape[1] == 3 and tri.shape[1] == 3 and tri.max() < len(pos)


def test_sample_records_round_trip_to_the_images_exactly(scene_dir):
    s = nb.Scene(scene_dir)
    rec = s.samples("train")
    n = len(rec["pixel"])
    assert n > 1000 and all(len(a) == n for a in rec.values())
    for view, light in [(int(rec["view"][0]), int(rec["light"][0])), (int(rec["view"][-1]), int(rec["light"][-1]))]:
        sel = (rec["view"] == view) & (rec["light"] == light)
        img = s.image(view, light).reshape(-1, 3)
        np.testing.assert_array_equal(rec["observed"][sel], img[rec["pixel"][sel]])
        assert s.mask(view).reshape(-1)[rec["pixel"][sel]].all()
    np.testing.assert_allclose(np.linalg.norm(rec["l"], axis=1), 1, atol=1e-5)
    assert (np.sum(rec["l"] * rec["normal"], axis=1) > 0).all(), "records are lit"


def test_scene_to_numpy_to_metrics(scene_dir):
    """Records -> a noise-free render in numpy (f E cos) -> metrics against the observed image."""
    s = nb.Scene(scene_dir)
    rec = s.samples("test")
    view, light = int(rec["view"][0]), int(rec["light"][0])
    sel = (rec["view"] == view) & (rec["light"] == light) & rec["gt_valid"]
    cos = np.sum(rec["normal"][sel] * rec["l"][sel], axis=1, keepdims=True)
    render = np.zeros((s.height * s.width, 3), np.float32)
    render[rec["pixel"][sel]] = rec["gt_brdf"][sel] * rec["irradiance"][sel] * cos
    render = render.reshape(s.height, s.width, 3)
    mask = np.zeros(s.height * s.width, bool)
    mask[rec["pixel"][sel]] = True
    mask = mask.reshape(s.height, s.width)
    observed = s.image(view, light)
    p = metrics.psnr(np.clip(observed, 0, 1), np.clip(render, 0, 1), mask=mask)
    d = np.clip(observed, 0, 1)[mask].astype(np.float64) - np.clip(render, 0, 1)[mask]
    assert abs(p.value - 10 * np.log10(1 / np.mean(d**2))) < 1e-6
    assert p.settings["pixels"] == mask.sum()
    assert p.value > 25, f"records and image disagree beyond the noise: {p.value:.1f} dB"
    f = metrics.hdr_flip(observed, render, mask=mask)
    assert 0 <= f.value < 0.5


def test_runs_evaluate_in_local_and_world_frames_alike(run_dirs):
    assert set(run_dirs) >= {"disney", "single_mlp", "additive_shared_enhanced"}, run_dirs
    for kind, path in run_dirs.items():
        run = nb.Run(path)
        assert run.kind == kind
        rec = run.samples("test")
        k = slice(0, 2000)
        world = run.eval(rec["triangle"][k], rec["barycentric"][k], rec["l"][k], rec["v"][k],
                         normal=rec["normal"][k])
        assert world.shape == (2000, 3) and np.isfinite(world).all() and (world >= 0).all()
        frame = duff_frame(rec["normal"][k].astype(np.float64))
        l_loc = np.einsum("nij,nj->ni", frame, rec["l"][k])
        v_loc = np.einsum("nij,nj->ni", frame, rec["v"][k])
        np.testing.assert_allclose(nb.to_local(rec["normal"][k], rec["l"][k]), l_loc, atol=1e-12)
        local = run.eval(rec["triangle"][k], rec["barycentric"][k], l_loc, v_loc)
        np.testing.assert_allclose(local, world, rtol=1e-4, atol=1e-6, err_msg=kind)


def test_additive_parts_sum_to_the_brdf(run_dirs):
    run = nb.Run(run_dirs["additive_shared_enhanced"])
    rec = run.samples("test")
    out = run.eval_samples({k: v[:500] for k, v in rec.items()}, parts=True)
    np.testing.assert_allclose(out["diffuse"] + out["specular"], out["f"], rtol=1e-5, atol=1e-7)
    assert (out["diffuse_raw"] >= out["diffuse"] - 1e-7).all()


def test_exports(run_dirs, tmp_path):
    run = nb.Run(run_dirs["disney"])
    e = run.export_merl(tmp_path / "fit.binary")
    assert (tmp_path / "fit.binary").stat().st_size == 12 + 8 * 3 * 90 * 90 * 180
    assert e["vertex"] >= 0
    summary = run.export(tmp_path / "renderers", formats="gltf,mitsuba")
    assert summary["model"] == "disney" and summary["files"]
    for f in summary["files"]:
        assert (tmp_path / "renderers" / f).exists(), f


def test_bad_runs_and_points_are_clear_errors(run_dirs, tmp_path):
    with pytest.raises((OSError, ValueError), match="nowhere"):
        nb.Run(tmp_path / "nowhere")
    with pytest.raises((OSError, ValueError), match="nowhere"):
        nb.Scene(tmp_path / "nowhere")
    run = nb.Run(run_dirs["single_mlp"])
    up = np.array([[0.0, 0.0, 1.0]])
    with pytest.raises(IndexError, match="triangle\\[0\\] = 4000000000 out of range"):
        run.eval([4_000_000_000], [[0.2, 0.2]], up, up)
    with pytest.raises(ValueError, match="l has 2 rows but triangle has 1"):
        run.eval([0], [[0.2, 0.2]], np.repeat(up, 2, 0), up)
