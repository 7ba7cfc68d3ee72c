"""The Mitsuba 3 plugin ``neural_brdf`` (neural_brdfs.mitsuba) on the miniature sweep
(conftest.py): eval against Run.eval, sample/pdf consistency (chi^2, grazing included), an
end-to-end render against our renderer's test image, and clear errors for bad inputs.

Needs the ``mitsuba`` wheel (skipped without it) and a libLLVM that Dr.Jit's LLVM backend can
compile with (LLVM 14/15 abort on ``llvm.maximum``; Debian bookworm: ``apt install libllvm19``).
"""

import glob
import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

mi = pytest.importorskip(
    "mitsuba", reason="the Mitsuba 3 wheel is not installed (pip install mitsuba==3.9.1)")

_PROBE = ("import drjit as dr\nfrom drjit.llvm import Float\n"
          "x = dr.maximum(Float([1, -2, 3, 4, 5, 6, 7, 8, 9]), Float(0.5))\n"
          "print(dr.atan2(x, Float(2.0)).numpy().sum())\n")
_probe = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True)
if _probe.returncode != 0:
    pytest.skip("Dr.Jit's LLVM backend cannot compile here (a libLLVM older than 16 aborts on "
                "llvm.maximum; install a newer one, e.g. apt install libllvm19, or set "
                f"DRJIT_LIBLLVM_PATH): {_probe.stderr.strip()[:200]}", allow_module_level=True)

import drjit as dr  # noqa: E402

mi.set_variant("llvm_ad_rgb")
import neural_brdfs as nb  # noqa: E402
import neural_brdfs.mitsuba as nbm  # noqa: E402
from mitsuba.chi2 import ChiSquareTest, SphericalDomain  # noqa: E402
from neural_brdfs import metrics  # noqa: E402
from neural_brdfs import reference_numpy as ref  # noqa: E402

NEURAL = ("single_mlp", "additive_shared_enhanced")


@pytest.fixture(scope="module")
def bsdfs(run_dirs):
    return {k: mi.load_dict({"type": "neural_brdf", "filename": str(run_dirs[k] / "model.json")})
            for k in NEURAL}


@pytest.fixture(scope="module")
def glossy(run_dirs, tmp_path_factory):
    """A glossy variant of the additive fit: its specular scaled up 20 times."""
    src, out = run_dirs["additive_shared_enhanced"], tmp_path_factory.mktemp("glossy")
    desc = json.loads((src / "model.json").read_text())
    desc["model"]["specular_softplus_scale"] *= 20
    (out / "model.json").write_text(json.dumps(desc))
    shutil.copy(src / "model.safetensors", out)
    return mi.load_dict({"type": "neural_brdf", "filename": str(out / "model.json")})


def _si(n, wi, tri=17, uv=(0.2, 0.3), frame=None):
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.prim_index = tri if isinstance(tri, mi.UInt32) else mi.UInt32(tri)
    si.uv = uv if isinstance(uv, mi.Point2f) else mi.Point2f(*uv)
    si.sh_frame = frame if frame is not None else mi.Frame3f(mi.Normal3f(0, 0, 1))
    si.wi = wi if isinstance(wi, mi.Vector3f) else mi.Vector3f(*[float(x) for x in wi])
    return si


def _random_points(rng, triangles, n):
    tri = rng.integers(0, triangles, n)
    bary = rng.random((n, 2)).astype(np.float32)
    flip = bary.sum(1) > 1
    bary[flip] = 1 - bary[flip]
    return tri, bary


@pytest.mark.parametrize("kind", NEURAL)
def test_eval_equals_run_eval(kind, run_dirs, bsdfs):
    """10k random surface points and direction pairs in the local frame: f_r cos / cos equals
    the Rust model's f_r to 1e-5 relative."""
    run, model = nb.Run(run_dirs[kind]), ref.load(run_dirs[kind])
    rng = np.random.default_rng(1)
    n = 10_000
    tri, bary = _random_points(rng, model.triangles.shape[0], n)
    d = rng.normal(size=(2, n, 3))
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    d[:, :, 2] = np.abs(d[:, :, 2]) + 1e-3
    l, v = (x / np.linalg.norm(x, axis=1, keepdims=True) for x in d.astype(np.float32))
    want = run.eval(tri, bary, l, v)
    si = _si(n, mi.Vector3f(v.T), mi.UInt32(tri.astype(np.uint32)), mi.Point2f(bary.T))
    got = np.array(bsdfs[kind].eval(mi.BSDFContext(), si, mi.Vector3f(l.T))).T / l[:, 2:]
    np.testing.assert_allclose(got, want, rtol=1e-5, atol=0, err_msg=kind)
    # pdf and eval_pdf agree with the separate calls
    f2, p2 = bsdfs[kind].eval_pdf(mi.BSDFContext(), si, mi.Vector3f(l.T))
    np.testing.assert_array_equal(np.array(f2).T / l[:, 2:], got)
    np.testing.assert_array_equal(np.array(p2), np.array(bsdfs[kind].pdf(
        mi.BSDFContext(), si, mi.Vector3f(l.T))))


def test_half_precision_networks(run_dirs):
    """precision="half" (float16 products, what CUDA's cooperative vectors require) runs on
    LLVM too and stays within a few percent of the float32 model."""
    kind = "single_mlp"
    bsdf = mi.load_dict({"type": "neural_brdf", "precision": "half", "sampling": "cosine",
                         "filename": str(run_dirs[kind] / "model.json")})
    run = nb.Run(run_dirs[kind])
    rng = np.random.default_rng(4)
    n = 2000
    tri, bary = _random_points(rng, ref.load(run_dirs[kind]).triangles.shape[0], n)
    th = rng.uniform(0, 1.4, (2, n))
    ph = rng.uniform(0, 2 * np.pi, (2, n))
    d = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    l, v = d.astype(np.float32)
    want = run.eval(tri, bary, l, v)
    si = _si(n, mi.Vector3f(v.T), mi.UInt32(tri.astype(np.uint32)), mi.Point2f(bary.T))
    got = np.array(bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(l.T))).T / l[:, 2:]
    rel = np.abs(got - want) / want
    assert rel.max() < 0.1 and np.median(rel) < 0.01, (rel.max(), np.median(rel))


def test_eval_converts_mitsubas_frame_into_ours(run_dirs, bsdfs):
    """World directions at the test records' normals, with Mitsuba's tangent rotated about n:
    the plugin equals Run.eval(..., normal=n). Pairs with theta_h < 0.05 are left out: there
    phi_d is ill-conditioned and float32 rounding of the frame change moves it measurably."""
    kind = "single_mlp"
    run = nb.Run(run_dirs[kind])
    rec = run.samples("test")
    rng = np.random.default_rng(2)
    n = 10_000
    k = rng.integers(0, len(rec["triangle"]), n)
    nrm = rec["normal"][k].astype(np.float64)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    d = rng.normal(size=(2, n, 3))
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    d *= np.sign((d * nrm).sum(2, keepdims=True))
    lw, vw = d.astype(np.float32)
    want = run.eval(rec["triangle"][k], rec["barycentric"][k], lw, vw, normal=nrm)
    nn = mi.Normal3f(nrm.T.astype(np.float32))
    duff = mi.Frame3f(nn)
    sn, cs = dr.sincos(mi.Float(rng.uniform(0, 2 * np.pi, n).astype(np.float32)))
    frame = mi.Frame3f(cs * duff.s + sn * duff.t, -sn * duff.s + cs * duff.t, nn)
    si = _si(n, frame.to_local(mi.Vector3f(vw.T)), mi.UInt32(rec["triangle"][k].astype(np.uint32)),
             mi.Point2f(rec["barycentric"][k].T.astype(np.float32)), frame)
    wo = frame.to_local(mi.Vector3f(lw.T))
    cos_o = np.array(mi.Frame3f.cos_theta(wo))
    ok = (cos_o > 1e-3) & (np.array(mi.Frame3f.cos_theta(si.wi)) > 1e-3)
    got = np.array(bsdfs[kind].eval(mi.BSDFContext(), si, wo)).T / np.where(ok, cos_o, 1)[:, None]
    theta_h = ref.rusinkiewicz(nb.to_local(nrm, lw).astype(np.float32),
                               nb.to_local(nrm, vw).astype(np.float32))[:, 0]
    sel = ok & (theta_h > 0.05)
    assert sel.sum() > 0.9 * n
    np.testing.assert_allclose(got[sel], want[sel], rtol=1e-5, atol=0)
    np.testing.assert_allclose(got[ok], want[ok], rtol=1e-3, atol=0)


@pytest.mark.parametrize("lobe", ["fitted", "n8_w0.3", "n40_w0.6"])
@pytest.mark.parametrize("theta_deg", [0, 45, 80, 89])
def test_sampling_chi2(theta_deg, lobe, run_dirs, bsdfs):
    """Sampled directions follow pdf(): Mitsuba's chi^2 test at normal, oblique and grazing
    incidence, for the fitted sampler (the miniature fits are diffuse enough for cosine
    sampling alone) and forced lobes (the same code path as a fitted lobe)."""
    if lobe == "fitted":
        bsdf = bsdfs["single_mlp"]
    else:
        n, w = (float(x) for x in lobe[1:].split("_w"))
        bsdf = mi.load_dict({"type": "neural_brdf", "lobe_exponent": n, "lobe_weight": w,
                             "filename": str(run_dirs["single_mlp"] / "model.json")})
    _chi2(bsdf, theta_deg, tests=15)


@pytest.mark.parametrize("theta_deg", [0, 60, 89])
def test_sampling_chi2_glossy_fit(theta_deg, glossy):
    """The same for the lobe fitted to the glossy variant (n ~ 256): its peak needs a finer
    integration of the pdf per cell (ires 16) than Mitsuba's default."""
    assert glossy.lobe_weight > 0
    _chi2(glossy, theta_deg, tests=3, ires=16, res=61)


def _chi2(bsdf, theta_deg, tests, ires=4, res=81):
    th = np.radians(theta_deg)
    wi = (np.sin(th), 0.0, np.cos(th))

    def sample(s):
        bs, w = bsdf.sample(mi.BSDFContext(), _si(dr.width(s), wi), s[0], mi.Vector2f(s[1], s[2]))
        return bs.wo, dr.select(dr.all(w == 0), 0.0, 1.0)

    def pdf(wo):
        return bsdf.pdf(mi.BSDFContext(), _si(dr.width(wo), wi), wo)

    chi2 = ChiSquareTest(SphericalDomain(), sample, pdf, sample_dim=3, sample_count=400_000,
                         res=res, ires=ires)
    assert chi2.run(0.01, test_count=tests, quiet=True), chi2.messages


def test_sample_weight_is_eval_over_pdf(bsdfs):
    bsdf = bsdfs["single_mlp"]
    n = 4096
    rng = np.random.default_rng(3)
    th = rng.uniform(0, np.radians(89), n)
    wi = mi.Vector3f(np.stack([np.sin(th), 0 * th, np.cos(th)]).astype(np.float32))
    si = _si(n, wi, mi.UInt32(rng.integers(0, 100, n).astype(np.uint32)))
    u = rng.random((3, n)).astype(np.float32)
    bs, w = bsdf.sample(mi.BSDFContext(), si, mi.Float(u[0]), mi.Vector2f(u[1:]))
    f, p = bsdf.eval_pdf(mi.BSDFContext(), si, bs.wo)
    valid = np.array(bs.pdf) > 0
    assert valid.mean() > 0.8
    np.testing.assert_allclose(np.array(bs.pdf)[valid], np.array(p)[valid], rtol=1e-5)
    p = np.where(valid, np.array(p), 1.0)
    np.testing.assert_allclose(np.array(w).T[valid], (np.array(f) / p).T[valid],
                               rtol=1e-4, atol=1e-7)
    assert (np.array(w).T[~valid] == 0).all()


def test_fitted_lobe(bsdfs, glossy):
    """The fit never predicts more variance than cosine sampling, and finds a lobe on a glossy
    variant of the additive fit (its specular scaled up 20 times)."""
    for kind, bsdf in bsdfs.items():
        info = bsdf.fit_info
        assert info["cost"] <= info["cosine_cost"], (kind, info["cost"], info["cosine_cost"])
    assert glossy.lobe_weight > 0 and glossy.lobe_exponent >= 8, glossy
    assert glossy.fit_info["cost"] <= 0.95 * glossy.fit_info["cosine_cost"], glossy.fit_info


def neural_scene(neural_run, out):
    """The neural run's Mitsuba export (``experiments export --format mitsuba``): mesh,
    sensors, emitters, the ``neural_brdf`` BSDF and the portable weights beside them."""
    summary = nb.Run(neural_run).export(out / "export", "mitsuba")
    folder = out / "export" / "mitsuba"
    assert (folder / "model.json").exists() and (folder / "model.safetensors").exists(), summary
    assert 'type="neural_brdf"' in (folder / "object.xml").read_text()
    return folder


def test_neural_runs_export_to_mitsuba_only(run_dirs, tmp_path):
    with pytest.raises(Exception, match="neural model: it exports to Mitsuba 3 only"):
        nb.Run(run_dirs["single_mlp"]).export(tmp_path / "gltf", "gltf")


def test_end_to_end_render_matches_ours(run_dirs, scene_dir, tmp_path):
    """A test view and light of the single_mlp run rendered by Mitsuba with the plugin
    (direct illumination, one directional emitter) against the run's own render: >= 35 dB in
    the masked sRGB protocol; mi.render itself runs and lights the same pixels."""
    folder = neural_scene(run_dirs["single_mlp"], tmp_path)
    stems = sorted(os.path.basename(f)[:-4] for f in glob.glob(str(folder / "view*_light*.xml")))
    assert stems
    stem = stems[0]
    scene = mi.load_file(str(folder / f"{stem}.xml"))
    img = nbm.render_pixel_centres(scene)
    ours = np.array(mi.Bitmap(str(run_dirs["single_mlp"] / "renders" / f"{stem}.exr")))[..., :3]
    mask = nb.Scene(scene_dir).mask(int(stem[4:7]))
    p = metrics.psnr(img, ours, mask=mask, space="linear")
    assert p.value >= 35.0, (stem, p)
    filtered = np.array(mi.render(scene, spp=4))[..., :3]
    assert np.isfinite(filtered).all() and (filtered >= 0).all()
    both = (filtered.sum(-1) > 0) & (ours.sum(-1) > 0)
    assert both.sum() > 0.9 * (ours.sum(-1) > 0).sum()


def test_bad_files_are_clear_errors(run_dirs, tmp_path):
    single, disney = run_dirs["single_mlp"], run_dirs["disney"]
    with pytest.raises(nbm.UnsupportedModelError, match="'disney'.*parametric"):
        nbm.load_model(disney / "model.json")
    with pytest.raises(ValueError, match="config.toml: not a JSON model description"):
        nbm.load_model(single / "config.toml")
    with pytest.raises(ValueError, match="run.json: not a neural-brdfs weights description"):
        nbm.load_model(single / "run.json")
    bad = tmp_path / "truncated.safetensors"
    bad.write_bytes((single / "model.safetensors").read_bytes()[:1000])
    with pytest.raises(ValueError, match="truncated.safetensors: header length"):
        nbm.load_model(single / "model.json", bad)
    other = run_dirs["additive_shared_enhanced"] / "model.safetensors"
    with pytest.raises(ValueError, match="do not match model kind single_mlp"):
        nbm.load_model(single / "model.json", other)
    # through Mitsuba's loader: its RuntimeError carries our message
    with pytest.raises(RuntimeError, match="'disney'.*parametric"):
        mi.load_dict({"type": "neural_brdf", "filename": str(disney / "model.json")})
    with pytest.raises(RuntimeError, match="'filename' parameter"):
        mi.load_dict({"type": "neural_brdf"})
    # the module registers for a newly set variant too
    mi.set_variant("scalar_rgb")
    try:
        with pytest.raises(RuntimeError, match="JIT variant"):
            mi.load_dict({"type": "neural_brdf", "filename": str(single / "model.json")})
    finally:
        mi.set_variant("llvm_ad_rgb")
