"""The README's picture of a neural fit rendered in Mitsuba 3: a run's test view exported with
``experiments export --format mitsuba`` (the ``neural_brdf`` plugin on its portable weights),
rendered by ``mi.render`` and by our renderer, side by side with their difference.

    target/py-venv/bin/python benches/mitsuba_figure.py RUN_DIR [--pair view002_light030] \
        [--spp 64] [--out docs/images/neural-mitsuba.png]

Prints the render times and the PSNR of Mitsuba's pixel-centre render against ours (the
masked sRGB protocol of the tests). Needs the Python package with its native module, the
``mitsuba`` wheel and a libLLVM >= 16 (Debian bookworm: ``apt install libllvm19``).
"""

import argparse
import gc
import pathlib
import tempfile
import time

import numpy as np


def srgb(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run", type=pathlib.Path)
    ap.add_argument("--pair", default="view002_light030")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--out", type=pathlib.Path, default=pathlib.Path("docs/images/neural-mitsuba.png"))
    args = ap.parse_args()

    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    import neural_brdfs as nb
    import neural_brdfs.mitsuba as nbm
    from neural_brdfs import metrics

    run = nb.Run(args.run)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        run.export(pathlib.Path(tmp) / "export", "mitsuba")
        t_export = time.perf_counter() - t0
        xml = pathlib.Path(tmp) / "export" / "mitsuba" / f"{args.pair}.xml"
        t0 = time.perf_counter()
        scene = mi.load_file(str(xml))
        t_load = time.perf_counter() - t0
        t0 = time.perf_counter()
        filtered = np.array(mi.render(scene, spp=args.spp))[..., :3]
        t_first = time.perf_counter() - t0
        t0 = time.perf_counter()
        filtered = np.array(mi.render(scene, spp=args.spp))[..., :3]
        t_warm = time.perf_counter() - t0
        centres = nbm.render_pixel_centres(scene)
        del scene
        gc.collect()
    ours = np.array(mi.Bitmap(str(args.run / "renders" / f"{args.pair}.exr")))[..., :3]
    mask = nb.Scene(run.scene_path).mask(int(args.pair[4:7]))
    psnr = metrics.psnr(centres, ours, mask=mask, space="linear")
    diff = np.abs(srgb(filtered) - srgb(ours)) * 4.0
    row = np.concatenate([srgb(ours), srgb(filtered), np.clip(diff, 0, 1)], axis=1)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    mi.Bitmap((row * 255 + 0.5).astype(np.uint8)).write(str(args.out))
    print(f"{run.kind} {args.pair}: export {t_export:.2f} s, load {t_load:.2f} s, "
          f"mi.render {args.spp} spp {t_first:.2f} s (first, with JIT) / {t_warm:.2f} s (warm); "
          f"pixel-centre PSNR against ours {psnr.value:.2f} dB; wrote {args.out} "
          "(ours | Mitsuba 3 | 4x |difference|, sRGB)")


if __name__ == "__main__":
    main()
