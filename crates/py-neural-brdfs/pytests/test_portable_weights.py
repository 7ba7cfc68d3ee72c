"""Weights others can read: a fitted model saved as model.safetensors + model.json and rebuilt
by the package's numpy reference module (neural kinds, always) and PyTorch one (every kind,
where torch is installed), agreeing with our model to 1e-5 (FMBRDF to 3e-5, see there); the
PyTorch parametric kinds stay finite, with finite gradients, at degenerate directions."""

import json

import numpy as np
import pytest

import neural_brdfs as nb
from neural_brdfs import reference_numpy

NEURAL = ["single_mlp", "additive_shared_enhanced"]
PARAMETRIC = ["rp", "ts", "disney", "fmbrdf"]
#: Elementwise relative tolerance of the PyTorch models against ours (see the test).
TORCH_RTOL = {"fmbrdf": 3e-5}


def local_dirs(rec, k):
    n = rec["normal"][k].astype(np.float64)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    sign = np.copysign(1.0, n[:, 2])
    a = -1.0 / (sign + n[:, 2])
    bb = n[:, 0] * n[:, 1] * a
    t = np.stack([1 + sign * n[:, 0] ** 2 * a, sign * bb, -sign * n[:, 0]], axis=1)
    b = np.stack([bb, sign + n[:, 1] ** 2 * a, -n[:, 1]], axis=1)
    frame = np.stack([t, b, n], axis=1)
    rot = lambda w: np.einsum("nij,nj->ni", frame, w[k]).astype(np.float32)
    return rot(rec["l"]), rot(rec["v"])


def test_training_writes_the_portable_files(run_dirs):
    for kind, path in run_dirs.items():
        desc = json.loads((path / "model.json").read_text())
        assert desc["format"] == "neural-brdfs-weights" and desc["kind"] == kind
        tensors, _ = reference_numpy.read_safetensors(path / "model.safetensors")
        assert tensors["spatial.vertex_features"].shape[1] == desc["spatial"]["dim"]


@pytest.mark.parametrize("kind", NEURAL)
def test_numpy_reference_equals_our_model_to_1e_5(run_dirs, tmp_path, kind):
    run = nb.Run(run_dirs[kind])
    run.save_portable(tmp_path)
    ref = reference_numpy.load(tmp_path)
    rec = run.samples("test")
    k = slice(0, 3000)
    l, v = local_dirs(rec, k)
    ours = run.eval(rec["triangle"][k], rec["barycentric"][k], l, v)
    theirs = ref.eval(rec["triangle"][k], rec["barycentric"][k], l, v)
    scale = max(1.0, float(np.abs(ours).max()))
    err = float(np.abs(theirs - ours).max()) / scale
    assert err < 1e-5, f"{kind}: max |numpy - ours| / max(1, |f|) = {err:.2e}"


def random_points(rec, n, seed=1):
    """n random surface points of the records' mesh and direction pairs above the horizon."""
    rng = np.random.default_rng(seed)
    tri = rng.integers(0, int(rec["triangle"].max()) + 1, n)
    bary = rng.random((n, 2)).astype(np.float32)
    flip = bary.sum(1) > 1
    bary[flip] = 1 - bary[flip]
    d = rng.normal(size=(2, n, 3))
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    d[:, :, 2] = np.abs(d[:, :, 2]) + 1e-3
    l, v = (x / np.linalg.norm(x, axis=1, keepdims=True) for x in d.astype(np.float32))
    return tri, bary, l, v


@pytest.mark.parametrize("dtype", ["float64", "float32"])
@pytest.mark.parametrize("kind", NEURAL + PARAMETRIC)
def test_torch_reference_equals_our_model_to_1e_5(run_dirs, tmp_path, kind, dtype):
    """The test records' first 3000 points: max |torch - ours| / max(1, |f|) < 1e-5; 10k random
    points and pairs: elementwise |torch - ours| <= rtol |ours|, rtol 1e-5 (FMBRDF 3e-5, both
    Lambda modes: Rust evaluates its Lambda network by segments, which its own test holds to
    the dense network to 2e-5). Measured on the miniature sweep, elementwise, float64 /
    float32: single_mlp 4.8e-7 / 5.9e-7, additive_shared_enhanced 4.9e-7 / 7.5e-7, rp 4.2e-7
    / 6.5e-7, ts 8.3e-7 / 6.7e-7, disney 9.6e-7 / 7.5e-7, fmbrdf 1.9e-6 / 3.0e-6."""
    torch = pytest.importorskip("torch")
    from neural_brdfs import reference_torch

    run = nb.Run(run_dirs[kind])
    run.save_portable(tmp_path)
    rec = run.samples("test")
    k = slice(0, 3000)
    l, v = local_dirs(rec, k)
    ours = run.eval(rec["triangle"][k], rec["barycentric"][k], l, v)
    tri, bary, l2, v2 = random_points(rec, 10_000)
    ours2 = run.eval(tri, bary, l2, v2)
    for mode in ("dense", "segments") if kind == "fmbrdf" else ("dense",):
        model = reference_torch.load(tmp_path, dtype=getattr(torch, dtype), lambda_mode=mode)
        with torch.no_grad():
            theirs = model.eval_points(
                torch.as_tensor(rec["triangle"][k].astype(np.int64)),
                torch.as_tensor(rec["barycentric"][k]), torch.as_tensor(l), torch.as_tensor(v),
            ).numpy()
            theirs2 = model.eval_points(tri, bary, l2, v2).numpy()
        assert theirs.dtype == np.dtype(dtype)
        err = float(np.abs(theirs - ours).max()) / max(1.0, float(np.abs(ours).max()))
        assert err < 1e-5, f"{kind}: max |torch - ours| / max(1, |f|) = {err:.2e}"
        np.testing.assert_allclose(theirs2, ours2, rtol=TORCH_RTOL.get(kind, 1e-5), atol=0,
                                   err_msg=f"{kind} {dtype} {mode}")


#: (l, v) pairs where a guard matters: l = v (at the normal, grazing, 45 degrees), n.l = 0,
#: n.v = 0, l = -v on the horizon, below the horizon, the mirror pair, grazing opposite pairs
#: (l + v almost 0), n.l = 1e-30.
_G, _S = float(np.sqrt(1 - 1e-12)), float(np.sqrt(0.5))
DEGENERATE = [((0, 0, 1), (0, 0, 1)), ((_G, 0, 1e-6), (_G, 0, 1e-6)), ((_S, 0, _S), (_S, 0, _S)),
              ((1, 0, 0), (0, 0, 1)), ((0, 0, 1), (0, 1, 0)), ((1, 0, 0), (1, 0, 0)),
              ((1, 0, 0), (-1, 0, 0)), ((0.6, 0, -0.8), (0, 0, 1)), ((0, 0, -1), (0, 0, -1)),
              ((0.6, 0, 0.8), (-0.6, 0, 0.8)), ((_G, 0, 1e-6), (-_G, 0, 1e-6)),
              ((1, 0, 1e-30), (0, 0, 1)), ((0.6, 0, 0.8), (0, 0.6, 0.8))]


@pytest.mark.parametrize("kind", PARAMETRIC)
def test_torch_parametric_kinds_are_finite_at_degenerate_directions(run_dirs, tmp_path, kind):
    """At every pair of DEGENERATE, float32 and float64 (FMBRDF: both Lambda modes): f finite,
    zero unless both directions are above the horizon, equal to ours to 1e-5; the gradients of
    a weighted sum of f in every parameter (FMBRDF: fm_alpha, fm_beta too) and in the spatial
    rows finite. FMBRDF's two Lambda modes give the same gradients in fm_alpha, fm_beta."""
    torch = pytest.importorskip("torch")
    from neural_brdfs import reference_torch

    run = nb.Run(run_dirs[kind])
    run.save_portable(tmp_path)
    l = np.array([p[0] for p in DEGENERATE], np.float32)
    v = np.array([p[1] for p in DEGENERATE], np.float32)
    tri, bary = np.arange(len(l)) * 7, np.full((len(l), 2), 0.3, np.float32)
    ours = run.eval(tri, bary, l, v)
    above = (l[:, 2] > 0) & (v[:, 2] > 0)
    assert np.isfinite(ours).all() and (ours[~above] == 0).all()
    for dtype in (torch.float32, torch.float64):
        grads = {}
        for mode in ("dense", "segments") if kind == "fmbrdf" else ("dense",):
            model = reference_torch.load(tmp_path, dtype=dtype, lambda_mode=mode)
            x = model.spatial_features(tri, bary).to(dtype).requires_grad_()
            f = model(x, torch.as_tensor(l), torch.as_tensor(v))
            w = torch.linspace(0.5, 2.0, len(l), dtype=dtype)[:, None]
            (f * w).sum().backward()
            got = f.detach().numpy()
            assert np.isfinite(got).all() and (got[~above] == 0).all(), (kind, mode, got)
            np.testing.assert_allclose(got, ours, rtol=1e-5, atol=0, err_msg=f"{kind} {mode}")
            assert torch.isfinite(x.grad).all(), (kind, dtype, mode)
            for name, p in model.named_parameters():
                assert p.grad is not None and torch.isfinite(p.grad).all(), (kind, name, mode)
            if kind == "fmbrdf":
                grads[mode] = np.array([float(model.fm_alpha.grad), float(model.fm_beta.grad)])
        if kind == "fmbrdf":
            np.testing.assert_allclose(grads["segments"], grads["dense"], rtol=1e-4)


EXPECTED_PARAMS = {"rp": 108_039, "ts": 108_039, "fmbrdf": 107_912, "disney": 108_684,
                   "single_mlp": 112_899, "additive_separate": 187_398,
                   "additive_shared": 160_134, "additive_separate_enhanced": 187_785,
                   "additive_shared_enhanced": 160_521}


def test_torch_models_have_the_rust_parameter_counts():
    """Fresh models of every kind in the default configuration (``model-spec``'s table; FMBRDF
    with its 2 global scalars): the same numbers of trainable scalars."""
    torch = pytest.importorskip("torch")
    from neural_brdfs import reference_torch as rt

    for kind, count in EXPECTED_PARAMS.items():
        config = reference_numpy.ModelConfig(kind=kind)
        table = rt.SpatialTable("lbo", torch.zeros((0, 160)),
                                torch.zeros((0, 3), dtype=torch.int64))
        cls = (rt.ParametricBrdf if kind in PARAMETRIC else rt.SingleMlp if kind == "single_mlp"
               else rt.AdditiveSeparate if "separate" in kind else rt.AdditiveShared)
        model = cls(config, table)
        assert sum(p.numel() for p in model.parameters()) == count, kind


def test_torch_parametric_load_errors_name_the_file(run_dirs, tmp_path):
    """An FMBRDF export relabelled as RP, and a bad FMBRDF helper-weights file: clear errors."""
    pytest.importorskip("torch")
    from neural_brdfs import reference_torch

    nb.Run(run_dirs["fmbrdf"]).save_portable(tmp_path)
    bad = tmp_path / "bad.bin"
    bad.write_bytes(b"FMBRDFW1\x01")
    with pytest.raises(ValueError, match="bad.bin: truncated or malformed"):
        reference_torch.load(tmp_path, fmbrdf_weights=str(bad))
    desc = json.loads((tmp_path / "model.json").read_text())
    desc["model"]["kind"] = "rp"
    (tmp_path / "model.json").write_text(json.dumps(desc))
    with pytest.raises(ValueError, match="model.safetensors: tensors do not match model kind rp"):
        reference_torch.load(tmp_path)


def test_parametric_kinds_are_refused_clearly(run_dirs, tmp_path):
    nb.Run(run_dirs["disney"]).save_portable(tmp_path)
    with pytest.raises(NotImplementedError, match="disney"):
        reference_numpy.load(tmp_path)


def test_torch_fmbrdf_lambda_by_segments_equals_the_dense_network():
    """As Rust's ``lambda_by_segments_equals_the_dense_network``: FMBRDF's Lambda network by
    segments against the dense network over the range of alpha, beta and tan theta from 0 to
    1e6 (float32): values to 2e-5 (|y| + 1e-3 max |y|), gradients in alpha, beta to 1e-4."""
    torch = pytest.importorskip("torch")
    from neural_brdfs import reference_torch_parametric as par

    nets = par.FmbrdfNets(par.read_fmbrdf_weights(par.default_fmbrdf_weights()))
    rng = np.random.default_rng(7)
    i = np.arange(3000)
    t = np.where(i % 10 == 0, 0.0, np.where(i % 10 == 1, 1.0, np.where(
        i % 10 == 2, 10.0 ** (3 * rng.random(3000)), 3 * rng.random(3000))))
    t = torch.as_tensor(np.append(t, 1e6).astype(np.float32))[:, None]
    weight = torch.as_tensor(rng.random(t.shape[0]).astype(np.float32) - 0.3)[:, None]
    for alpha, beta in [(0.001, 0.5), (0.05, 0.7), (0.3, 2.0), (1.0, 3.5), (2 * np.pi, 4.0)]:
        out = {}
        for mode in ("segments", "dense"):
            a = torch.full((1, 1), alpha, requires_grad=True)
            b = torch.full((1, 1), beta, requires_grad=True)
            y = nets.smith_lambda(t, a, b, mode)
            (y * weight).sum().backward()
            out[mode] = (y.detach().numpy(), float(a.grad), float(b.grad))
        (fast, ga, gb), (dense, ga_ref, gb_ref) = out["segments"], out["dense"]
        scale = max(float(np.abs(dense).max()), 1e-3)
        assert (np.abs(fast - dense) <= 2e-5 * (np.abs(dense) + 1e-3 * scale)).all(), alpha
        for g, g_ref in ((ga, ga_ref), (gb, gb_ref)):
            assert np.isfinite(g) and abs(g - g_ref) <= 1e-4 * max(abs(g_ref), 1e-3)
