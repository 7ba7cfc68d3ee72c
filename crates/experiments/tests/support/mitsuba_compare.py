"""Renders scenes written by `experiments export` with Mitsuba 3 and compares them with the
fit's own renders of the same test pairs (opt-in check; needs `pip install mitsuba`).

    python mitsuba_compare.py EXPORT_DIR RUN_DIR [STEM ...] [--spp N]

EXPORT_DIR is the folder `experiments export --out` wrote, RUN_DIR the run after
`experiments eval` (its renders/<stem>.exr). Without stems, every exported test pair. Prints per
pair the PSNR (sRGB, clamped to [0, 1]) over the object and over the pixels both images light,
the pixel counts, and the ratio of Mitsuba's to our channel sums over the common pixels.
"""
import argparse, glob, os
import numpy as np
import mitsuba as mi

mi.set_variant("scalar_rgb")


def srgb(x):
    x = np.clip(x, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("export_dir")
    p.add_argument("run_dir")
    p.add_argument("stems", nargs="*")
    p.add_argument("--spp", type=int, default=256)
    a = p.parse_args()
    stems = a.stems or sorted(
        os.path.basename(f)[:-4]
        for f in glob.glob(os.path.join(a.export_dir, "mitsuba", "view*_light*.xml"))
    )
    for stem in stems:
        scene = mi.load_file(os.path.join(a.export_dir, "mitsuba", f"{stem}.xml"))
        img = np.array(mi.render(scene, spp=a.spp))[..., :3]
        ours = np.array(mi.Bitmap(os.path.join(a.run_dir, "renders", f"{stem}.exr")))[..., :3]
        lit_ours, lit_mi = ours.sum(-1) > 0, img.sum(-1) > 0
        both = lit_ours & lit_mi

        def psnr(m):
            d = (srgb(img) - srgb(ours))[m]
            return 10 * np.log10(1.0 / np.mean(d**2))

        ratio = img[both].sum(0) / ours[both].sum(0)
        print(
            f"{stem}: PSNR object {psnr(lit_ours | lit_mi):.2f} dB, both lit {psnr(both):.2f} dB; "
            f"lit pixels ours {int(lit_ours.sum())} mitsuba {int(lit_mi.sum())} both {int(both.sum())}; "
            f"mitsuba/ours channel sums {np.round(ratio, 3)}"
        )


if __name__ == "__main__":
    main()
