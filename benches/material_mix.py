#!/usr/bin/env python3
"""Which few materials stand for the paper's 25: the analysis of issue 42's material-mix proxy.

Reads the runs of `benches/profiles/material_proxy.toml` (a Disney and a Single MLP fit, each to
its plateau, on Spot x each of the `full` profile's 25 MERL-derived materials), prints every
material's PSNR under both protocols, the mean over all 25, and the triples of materials whose
means come closest to it, with their cost (training steps to the plateau, summed over both
models, as a ratio to the current default's triple).

    cargo xtask reproduce-tables --profile benches/profiles/material_proxy.toml --out out/material-proxy
    python3 benches/material_mix.py out/material-proxy [--current a,b,c] [--budget 1.25]

A triple's distance is the largest of its Disney and its Single MLP deviations from the
25-material mean, in the paper's protocol's PSNR and in ours (dB): a triple representative in
both is representative whichever protocol a reader compares. Only the standard library is used.
"""

import argparse
import itertools
import json
import pathlib
import statistics
import sys


def load(out):
    runs = {}
    for d in sorted(pathlib.Path(out, "runs").iterdir()):
        try:
            info = json.loads((d / "run.json").read_text())
            m = json.loads((d / "metrics.json").read_text())
        except (OSError, ValueError):
            continue
        t = m.get("test")
        if not t or "paper" not in t:
            continue
        model = d.name.split("__")[2]
        material = info["object"].split("__", 1)[1]
        runs[(material, model)] = {
            "paper": t["paper"]["scores"]["psnr"],
            "ours": t["psnr"],
            "clean": t["clean"]["psnr"],
            "ceiling": t["ceiling"]["psnr"],
            "steps": m["steps"],
        }
    return runs


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", help="the proxy sweep's output directory")
    ap.add_argument("--current", default="blue-acrylic,gold-metallic-paint,grease-covered-steel")
    ap.add_argument("--budget", type=float, default=1.25,
                    help="largest cost of a triple, as a ratio to the current triple's")
    ap.add_argument("--top", type=int, default=10)
    a = ap.parse_args()
    runs = load(a.out)
    models = ["disney", "single_mlp"]
    materials = sorted({m for m, k in runs if all((m, x) in runs for x in models)})
    if len(materials) < 3:
        sys.exit(f"{a.out}: only {len(materials)} materials have both models evaluated")
    print(f"{len(materials)} materials with both models evaluated\n")
    print("| material | Disney (paper) | Single MLP (paper) | Disney (ours) | Single MLP (ours) "
          "| ceiling (ours) | steps |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for m in materials:
        d, s = runs[(m, "disney")], runs[(m, "single_mlp")]
        print(f"| {m} | {d['paper']:.2f} | {s['paper']:.2f} | {d['ours']:.2f} | {s['ours']:.2f} "
              f"| {d['ceiling']:.2f} | {d['steps'] + s['steps']} |")
    mean = {k: statistics.fmean(runs[(m, k)]["paper"] for m in materials) for k in models}
    mean_ours = {k: statistics.fmean(runs[(m, k)]["ours"] for m in materials) for k in models}
    print(f"\nmean of all {len(materials)}: Disney {mean['disney']:.2f} dB, Single MLP "
          f"{mean['single_mlp']:.2f} dB (paper's protocol); {mean_ours['disney']:.2f} and "
          f"{mean_ours['single_mlp']:.2f} dB (ours)")

    def summary(triple):
        dev = {k: statistics.fmean(runs[(m, k)]["paper"] for m in triple) - mean[k] for k in models}
        dev_ours = {k: statistics.fmean(runs[(m, k)]["ours"] for m in triple) - mean_ours[k]
                    for k in models}
        cost = sum(runs[(m, k)]["steps"] for m in triple for k in models)
        dist = max(abs(v) for v in list(dev.values()) + list(dev_ours.values()))
        return dist, dev, cost, dev_ours

    current = [m.strip() for m in a.current.split(",")]
    if all(m in materials for m in current):
        dist, dev, base_cost, dev_ours = summary(current)
        print(f"\ncurrent default {', '.join(current)}: Disney {dev['disney']:+.2f} dB, Single MLP "
              f"{dev['single_mlp']:+.2f} dB from the mean of all in the paper's protocol, "
              f"{dev_ours['disney']:+.2f} and {dev_ours['single_mlp']:+.2f} dB in ours "
              f"(distance {dist:.2f})")
    else:
        base_cost = None
        print(f"\ncurrent default {a.current}: not all in the proxy")
    ranked = []
    for triple in itertools.combinations(materials, 3):
        dist, dev, cost, dev_ours = summary(triple)
        ratio = cost / base_cost if base_cost else 1.0
        if ratio <= a.budget:
            ranked.append((dist, triple, dev, ratio, dev_ours))
    ranked.sort()
    print(f"\nthe {a.top} closest triples within {a.budget}x the current triple's cost "
          f"({len(ranked)} qualify):\n")
    print("| materials | Disney Δ paper | Single MLP Δ paper | Disney Δ ours | Single MLP Δ ours "
          "| cost |")
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    for dist, triple, dev, ratio, dev_ours in ranked[:a.top]:
        print(f"| {', '.join(triple)} | {dev['disney']:+.2f} | {dev['single_mlp']:+.2f} "
              f"| {dev_ours['disney']:+.2f} | {dev_ours['single_mlp']:+.2f} | {ratio:.2f}x |")


if __name__ == "__main__":
    main()
