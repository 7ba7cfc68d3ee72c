"""Measures the Mitsuba 3 plugin ``neural_brdf`` (crates/py-neural-brdfs/python/neural_brdfs/
mitsuba.py) and prints every figure of its report, so they can be re-measured:

1. eval agreement with ``Run.eval`` (Rust) on 10k random surface points and direction pairs, in
   the local frame and through a Mitsuba frame rotated about the normal;
2. chi^2 p-values of sample/pdf at several incident angles (grazing included);
3. the RMSE of ``direct`` renders under a constant environment at equal spp, fitted-lobe against
   cosine sampling, both against a high-spp reference, on the glossiest fit and on a glossier
   variant of the additive fit (its specular scaled);
4. PSNR of Mitsuba's renders (pixel centres; and ``mi.render``'s box-filtered image on the
   pixels both light) against the runs' own renders of every test pair, masked sRGB protocol;
5. render times against ours (``Run.eval`` on the pair's records plus the shading).

    target/py-venv/bin/python benches/mitsuba_plugin.py [--out DIR] [--xtask PATH] [--quick]
        [--sections 1234] [--spp 16] [--ref-spp 2048] [--material NAME]

It trains a small sweep first (glossy MERL material, 3 models, ~1 min on 2 cores) with the
xtask binary (``$NEURAL_BRDF_XTASK`` or target/debug/xtask) unless DIR already holds it.
Needs ``pip install mitsuba==3.9.1`` and a libLLVM >= 16 for Dr.Jit (Debian: libllvm19).
"""

import argparse
import gc
import json
import os
import pathlib
import re
import shutil
import subprocess
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
PROFILE = """\
name = "mitsuba-bench"
description = "the Mitsuba plugin's measurements: one glossy scene, three models"
[data]
meshes = ["embedded:spot"]
materials = ["{material}"]
size = 64
views = 4
lights = 12
[run]
seed = 7
[run.model]
width = 64
[run.features.lbo]
k_max = 32
first = 16
blocks = 1
block_len = 8
[run.train]
profile = "quick"
iterations = 2000
batch_size = 1024
warmup_steps = 10
checkpoint_every = 500
log_every = 10
validate_every = 25
patience = 400
[run.eval]
energy_pairs = 4
reciprocity_pairs = 200
[sweep]
models = ["disney", "single_mlp", "additive_shared_enhanced"]
"""


def sweep(out, xtask, material="specular-red-phenolic"):
    if not list(pathlib.Path(out).glob("runs/*/model.json")):
        pathlib.Path(out).mkdir(parents=True, exist_ok=True)
        prof = pathlib.Path(out) / "profile.toml"
        prof.write_text(PROFILE.replace("{material}", material))
        t = time.time()
        subprocess.run([xtask, "reproduce-tables", "--profile", str(prof), "--out", str(out),
                        "--jobs", "1"], check=True, stdout=subprocess.DEVNULL)
        print(f"trained the bench sweep in {time.time() - t:.0f} s")
    runs = {}
    for p in pathlib.Path(out).glob("runs/*/config.toml"):
        kind = re.search(r'^kind = "([^"]+)"', p.read_text(), re.M).group(1)
        runs[kind] = p.parent
    scene = next(p.parent for p in pathlib.Path(out).glob("scenes/*/manifest.json"))
    return runs, scene


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(ROOT / "target" / "mitsuba-bench"))
    ap.add_argument("--xtask", default=os.environ.get("NEURAL_BRDF_XTASK",
                                                      str(ROOT / "target" / "debug" / "xtask")))
    ap.add_argument("--spp", type=int, default=16, help="spp of the RMSE comparison")
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--quick", action="store_true", help="fewer samples everywhere")
    ap.add_argument("--material", default="specular-red-phenolic",
                    help="the MERL-derived material of the bench sweep")
    ap.add_argument("--sections", default="1234", help="which of the sections 1-4 to run")
    a = ap.parse_args()

    import drjit as dr
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    import neural_brdfs as nb
    import neural_brdfs.mitsuba as nbm
    from mitsuba.chi2 import ChiSquareTest, SphericalDomain
    from neural_brdfs import metrics
    from neural_brdfs import reference_numpy as ref

    runs, scene_dir = sweep(a.out, a.xtask, a.material)
    work = pathlib.Path(a.out) / "mitsuba"
    shutil.rmtree(work, ignore_errors=True)
    nb.Run(runs["disney"]).export(work / "export", "mitsuba")
    base = work / "export" / "mitsuba"
    neural = [k for k in ref.NEURAL_KINDS if k in runs]
    print(f"runs: {sorted(runs)}; scene {scene_dir.name}; {mi.variant()}, "
          f"Dr.Jit {dr.__version__}, Mitsuba {mi.__version__}")

    def make_si(n, wi, tri, uv, frame=None):
        si = dr.zeros(mi.SurfaceInteraction3f, n)
        si.prim_index, si.uv, si.wi = tri, uv, wi
        si.sh_frame = frame if frame is not None else mi.Frame3f(mi.Normal3f(0, 0, 1))
        return si

    # ----------------------------------------------------------------- 1. eval agreement
    if "1" in a.sections:
        print("\n== 1. eval against Run.eval (10k random points and pairs; max relative error)")
        bsdfs = {}
        for kind in neural:
            t = time.time()
            bsdfs[kind] = mi.load_dict({"type": "neural_brdf",
                                        "filename": str(runs[kind] / "model.json")})
            load_s = time.time() - t
            run, model = nb.Run(runs[kind]), ref.load(runs[kind])
            rng = np.random.default_rng(0)
            n = 10_000
            tri = rng.integers(0, model.triangles.shape[0], n)
            bary = rng.random((n, 2)).astype(np.float32)
            bary[bary.sum(1) > 1] = 1 - bary[bary.sum(1) > 1]
            d = rng.normal(size=(2, n, 3))
            d[:, :, 2] = np.abs(d[:, :, 2])
            l, v = (x / np.linalg.norm(x, axis=1, keepdims=True) for x in d.astype(np.float32))
            want = run.eval(tri, bary, l, v)
            si = make_si(n, mi.Vector3f(v.T), mi.UInt32(tri.astype(np.uint32)), mi.Point2f(bary.T))
            times = []
            for _ in range(2):
                t = time.time()
                f = bsdfs[kind].eval(mi.BSDFContext(), si, mi.Vector3f(l.T))
                dr.eval(f)
                times.append(time.time() - t)
            got = np.array(f).T / l[:, 2:]
            rel = np.abs(got - want) / np.abs(want)
            # world frame: a Mitsuba tangent frame rotated about n
            rec = run.samples("test")
            k = rng.integers(0, len(rec["triangle"]), n)
            nrm = rec["normal"][k].astype(np.float64)
            nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
            d = rng.normal(size=(2, n, 3))
            d *= np.sign((d * nrm).sum(2, keepdims=True))
            lw, vw = (x / np.linalg.norm(x, axis=1, keepdims=True) for x in d.astype(np.float32))
            want_w = run.eval(rec["triangle"][k], rec["barycentric"][k], lw, vw, normal=nrm)
            nn = mi.Normal3f(nrm.T.astype(np.float32))
            duff = mi.Frame3f(nn)
            sn, cs = dr.sincos(mi.Float(rng.uniform(0, 6.28, n).astype(np.float32)))
            fr = mi.Frame3f(cs * duff.s + sn * duff.t, -sn * duff.s + cs * duff.t, nn)
            si = make_si(n, fr.to_local(mi.Vector3f(vw.T)),
                         mi.UInt32(rec["triangle"][k].astype(np.uint32)),
                         mi.Point2f(rec["barycentric"][k].T.astype(np.float32)), fr)
            wo = fr.to_local(mi.Vector3f(lw.T))
            co = np.array(mi.Frame3f.cos_theta(wo))
            ok = (co > 1e-3) & (np.array(mi.Frame3f.cos_theta(si.wi)) > 1e-3)
            got_w = np.array(bsdfs[kind].eval(mi.BSDFContext(), si, wo)).T
            got_w /= np.where(ok, co, 1)[:, None]
            th = ref.rusinkiewicz(nb.to_local(nrm, lw).astype(np.float32),
                                  nb.to_local(nrm, vw).astype(np.float32))[:, 0]
            rel_w = (np.abs(got_w - want_w) / np.abs(want_w)).max(1)
            b = bsdfs[kind]
            print(f"{kind}: local max rel {rel.max():.2e}; world frame max rel "
                  f"{rel_w[ok].max():.2e} "
                  f"(theta_h > 0.05: {rel_w[ok & (th > 0.05)].max():.2e}); load + lobe fit "
                  f"{load_s:.2f} s; eval 10k {times[0]:.3f} s first (JIT), {times[1]:.3f} s warm; "
                  f"lobe n = {b.lobe_exponent:g}, w = {b.lobe_weight:g} (relative 2nd moment "
                  f"{b.fit_info['cost']:.3f}, cosine {b.fit_info['cosine_cost']:.3f})")

    variants = {kind: runs[kind] for kind in neural}
    if "additive_shared_enhanced" in runs:  # a glossier variant: specular x20
        g = work / "glossy"
        g.mkdir(parents=True)
        desc = json.loads((runs["additive_shared_enhanced"] / "model.json").read_text())
        desc["model"]["specular_softplus_scale"] *= 20
        (g / "model.json").write_text(json.dumps(desc))
        shutil.copy(runs["additive_shared_enhanced"] / "model.safetensors", g)
        variants["additive_shared_enhanced, specular x20"] = g

    # ------------------------------------------------------------------------ 2. chi^2
    if "2" in a.sections:
        print("\n== 2. chi^2 (Mitsuba's ChiSquareTest, 1M samples, res 101, ires 16; p-values)")
        configs = [(k, {}) for k in variants] + [
            ("single_mlp", {"lobe_exponent": n, "lobe_weight": w}) for n, w in ((8.0, 0.3),
                                                                                (40.0, 0.6))]
        for kind, extra in configs:
            bsdf = mi.load_dict({"type": "neural_brdf", **extra,
                                 "filename": str(variants[kind] / "model.json")})
            ps = []
            for deg in (0, 30, 60, 80, 89):
                th = np.radians(deg)
                wi = mi.Vector3f(float(np.sin(th)), 0.0, float(np.cos(th)))

                def sample(s, wi=wi, bsdf=bsdf):
                    si = make_si(dr.width(s), wi, mi.UInt32(17), mi.Point2f(0.2, 0.3))
                    bs, w = bsdf.sample(mi.BSDFContext(), si, s[0], mi.Vector2f(s[1], s[2]))
                    return bs.wo, dr.select(dr.all(w == 0), 0.0, 1.0)

                def pdf(wo, wi=wi, bsdf=bsdf):
                    si = make_si(dr.width(wo), wi, mi.UInt32(17), mi.Point2f(0.2, 0.3))
                    return bsdf.pdf(mi.BSDFContext(), si, wo)

                chi = ChiSquareTest(SphericalDomain(), sample, pdf, sample_dim=3,
                                    sample_count=200_000 if a.quick else 1_000_000, res=101,
                                    ires=16)
                ok = chi.run(0.01, test_count=5, quiet=True)
                ps.append(f"{deg} deg: p = {chi.p_value:.3f}{'' if ok else ' FAIL'}")
            print(f"{kind} (n = {bsdf.lobe_exponent:g}, w = {bsdf.lobe_weight:g}): "
                  + "; ".join(ps))

    # -------------------------------------------------------------- 3. RMSE vs cosine
    if "3" in a.sections:
        print(f"\n== 3. RMSE at {a.spp} spp against a {a.ref_spp} spp reference, constant "
              f"environment, `direct` integrator (object pixels)")
        view_xml = sorted(base.glob("view*_light*.xml"))[0].read_text()
        sensor = re.search(r"<sensor.*</sensor>", view_xml, re.S).group(0)
        for name, folder in variants.items():
            for f in ("model.json", "model.safetensors"):
                shutil.copy(folder / f, base / f)

            def scene(sampling, emitter_samples, bsdf_samples):
                xml = (f'<scene version="3.0.0"><integrator type="direct">'
                       f'<integer name="emitter_samples" value="{emitter_samples}"/>'
                       f'<integer name="bsdf_samples" value="{bsdf_samples}"/></integrator>{sensor}'
                       f'<emitter type="constant"><rgb name="radiance" value="1.0"/></emitter>'
                       f'<shape type="ply"><string name="filename" value="mesh.ply"/>'
                       f'<bsdf type="neural_brdf"><string name="filename" value="model.json"/>'
                       f'<string name="sampling" value="{sampling}"/></bsdf></shape></scene>')
                p = base / f"rmse_{sampling}.xml"
                p.write_text(xml)
                return mi.load_file(str(p))

            ref_spp = a.ref_spp // (4 if a.quick else 1)
            reference = np.array(mi.render(scene("lobe", 1, 1), spp=ref_spp))
            mask = reference.sum(-1) > 0
            out = []
            for label, es, bs in (("BSDF sampling only", 0, 1),
                                  ("MIS with emitter sampling", 1, 1)):
                rmse = {}
                for sampling in ("lobe", "cosine"):
                    sc = scene(sampling, es, bs)
                    errs = []
                    for seed in range(4):
                        img = np.array(mi.render(sc, spp=a.spp, seed=seed + 1))
                        errs.append(np.mean((img - reference)[mask] ** 2))
                    rmse[sampling] = float(np.sqrt(np.mean(errs)))
                out.append(f"{label}: lobe {rmse['lobe']:.5f}, cosine {rmse['cosine']:.5f}, "
                           f"ratio {rmse['lobe'] / rmse['cosine']:.3f}")
            b = scene("lobe", 1, 1).shapes()[0].bsdf()
            print(f"{name} (n = {b.lobe_exponent:g}, w = {b.lobe_weight:g}): " + "; ".join(out))

    # --------------------------------------------------- 4./5. renders against ours
    bsdfs = bsdf = b = sc = sample = pdf = chi = None  # noqa: F841
    gc.collect()  # dead BSDFs would still join every BSDF call of the renders
    if "4" in a.sections:
        print("\n== 4./5. test renders against ours (masked sRGB PSNR) and render times")
        sc_data = nb.Scene(scene_dir)
        for kind in neural:
            for f in ("model.json", "model.safetensors"):
                shutil.copy(runs[kind] / f, base / f)
            (base / "object.xml").write_text(
                '<scene version="3.0.0"><shape type="ply" id="object">'
                '<string name="filename" value="mesh.ply"/><bsdf type="neural_brdf">'
                '<string name="filename" value="model.json"/></bsdf></shape></scene>')
            run = nb.Run(runs[kind])
            rec = run.samples("test")
            rows = []
            for xml in sorted(base.glob("view*_light*.xml")):
                stem = xml.stem
                vi, li = int(stem[4:7]), int(stem[13:16])
                scene = None
                gc.collect()  # only this scene's BSDF in the kernels (see above)
                t = time.time()
                scene = mi.load_file(str(xml))
                t_load = time.time() - t
                t = time.time()
                img = nbm.render_pixel_centres(scene)
                t_centres = time.time() - t
                t = time.time()
                filt = np.array(mi.render(scene, spp=64))[..., :3]
                t_render = time.time() - t
                ours = np.array(mi.Bitmap(str(runs[kind] / "renders" / f"{stem}.exr")))[..., :3]
                mask = sc_data.mask(vi)
                p = metrics.psnr(img, ours, mask=mask, space="linear").value
                both = (filt.sum(-1) > 0) & (ours.sum(-1) > 0)
                pf = metrics.psnr(filt, ours, mask=both, space="linear").value
                # ours: the model on the pair's lit records, shaded f E cos, scattered into pixels
                sel = (rec["view"] == vi) & (rec["light"] == li)
                t = time.time()
                sub = {k: v[sel] for k, v in rec.items()}
                f = run.eval_samples(sub)
                cos = np.maximum((sub["normal"] * sub["l"]).sum(1, keepdims=True), 0)
                mine = np.zeros((sc_data.height * sc_data.width, 3), np.float32)
                mine[sub["pixel"]] = f * sub["irradiance"] * cos
                t_ours = time.time() - t
                rows.append((stem, p, pf, t_load, t_centres, t_render, t_ours))
            print(f"{kind}:")
            for stem, p, pf, tl, tc, tr, to in rows:
                print(f"  {stem}: PSNR pixel centres {p:.2f} dB, mi.render 64 spp (both lit) "
                      f"{pf:.2f} dB; Mitsuba load {tl:.2f} s, pixel centres {tc:.3f} s, "
                      f"mi.render 64 spp {tr:.2f} s; ours {to:.3f} s")
            ps = np.array([r[1] for r in rows])
            print(f"  min / median PSNR (pixel centres) {ps.min():.2f} / {np.median(ps):.2f} dB")


if __name__ == "__main__":
    main()
