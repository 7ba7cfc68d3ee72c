#!/usr/bin/env python3
"""Where a sweep's training steps go under the plateau rule.

For every evaluated run of a sweep folder (`<out>/runs/*/curve.csv` and `metrics.json`), the
steps of each phase of the rule (the first rate, then the decayed rate), and how many of them
come after the phase's last smoothed best: the mean of the last `smoothing` validation losses,
restarted at the decay, improving on the best so far by `min_improvement` (the quick profile's
1 % and the default's 3). Those steps are the rule's confirmation wait, the price of knowing a
plateau is one. A reconstruction from the curve, not the trainer's own state: it matches the
rule where the curve holds every validation loss (it does, at `validate_every`).

Usage: python3 benches/plateau_wait.py OUT [--smoothing 3] [--min-improvement 0.01]
"""
import argparse
import csv
import glob
import json
import os


def last_best(losses, smoothing, min_improvement):
    """The step of the last smoothed best of one phase's (step, loss) list."""
    best, at = None, losses[0][0]
    for i in range(len(losses)):
        window = [v for _, v in losses[max(0, i - smoothing + 1) : i + 1]]
        mean = sum(window) / len(window)
        if best is None or mean < best * (1 - min_improvement):
            best, at = mean, losses[i][0]
    return at


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--smoothing", type=int, default=3)
    ap.add_argument("--min-improvement", type=float, default=0.01)
    a = ap.parse_args()
    runs = steps = wait_first = wait_decayed = 0
    for run in sorted(glob.glob(os.path.join(a.out, "runs", "*", ""))):
        metrics, curve = os.path.join(run, "metrics.json"), os.path.join(run, "curve.csv")
        if not (os.path.exists(metrics) and os.path.exists(curve)):
            continue
        m = json.load(open(metrics))
        rows = [r for r in csv.DictReader(open(curve)) if r["val_loss"]]
        if not rows:
            continue
        val = [(int(r["step"]), float(r["val_loss"]), float(r["lr"])) for r in rows]
        rate = val[0][2]
        first = [(s, v) for s, v, lr in val if lr >= rate * 0.99]
        decayed = [(s, v) for s, v, lr in val if lr < rate * 0.99]
        end_first = first[-1][0] if first else 0
        wait_first += end_first - last_best(first, a.smoothing, a.min_improvement) if first else 0
        if decayed:
            wait_decayed += m["steps"] - last_best(decayed, a.smoothing, a.min_improvement)
        steps += m["steps"]
        runs += 1
    wait = wait_first + wait_decayed
    print(f"{runs} runs, {steps} steps; after the last smoothed best: {wait} "
          f"({100 * wait / max(1, steps):.1f} %; first rate {wait_first}, decayed {wait_decayed})")


if __name__ == "__main__":
    main()
