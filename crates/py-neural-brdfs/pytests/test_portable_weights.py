"""Weights others can read: a fitted model saved as model.safetensors + model.json and rebuilt
by the package's numpy reference module (always) and PyTorch one (where torch is installed),
agreeing with our model to 1e-5."""

import json

import numpy as np
import pytest

import neural_brdfs as nb
from neural_brdfs import reference_numpy

NEURAL = ["single_mlp", "additive_shared_enhanced"]


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


@pytest.mark.parametrize("kind", NEURAL)
def test_torch_reference_equals_our_model_to_1e_5(run_dirs, tmp_path, kind):
    torch = pytest.importorskip("torch")
    from neural_brdfs import reference_torch

    run = nb.Run(run_dirs[kind])
    run.save_portable(tmp_path)
    model = reference_torch.load(tmp_path, dtype=torch.float64)
    rec = run.samples("test")
    k = slice(0, 3000)
    l, v = local_dirs(rec, k)
    ours = run.eval(rec["triangle"][k], rec["barycentric"][k], l, v)
    with torch.no_grad():
        theirs = model.eval_points(
            torch.as_tensor(rec["triangle"][k].astype(np.int64)),
            torch.as_tensor(rec["barycentric"][k]), torch.as_tensor(l), torch.as_tensor(v),
        ).numpy()
    err = float(np.abs(theirs - ours).max()) / max(1.0, float(np.abs(ours).max()))
    assert err < 1e-5, f"{kind}: max |torch - ours| / max(1, |f|) = {err:.2e}"


def test_parametric_kinds_are_refused_clearly(run_dirs, tmp_path):
    nb.Run(run_dirs["disney"]).save_portable(tmp_path)
    with pytest.raises(NotImplementedError, match="disney"):
        reference_numpy.load(tmp_path)
