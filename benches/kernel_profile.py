#!/usr/bin/env python3
"""Where a training step's GPU time goes, from CubeCL's kernel profile log.

CubeCL writes one line per kernel launch (`| 1.23ms | KernelName...`) when a `cubecl.toml` in
the working directory asks for it:

    [profiling.logger]
    level = "basic"
    file = "/tmp/cubecl_profile.log"

A log of the `train_step` bench also holds CubeCL's throughput probes (`LaunchOverhead`,
`*Throughput`), which this script drops, the model's initialisation, and whatever the bench
times after the steps. With `--steps N` (the bench runs one untimed and 7 timed steps a model
kind, so 8) it finds the steps themselves: the first kernel launched exactly N times, at even
intervals after its first launch, marks where each step starts, and the launches between the
last two marks are one whole step. It prints the launches between consecutive marks (equal
counts say the segmentation is right) and that step's kernels by time. Without `--steps` it
sums the whole log by kernel.

    python3 benches/kernel_profile.py /tmp/cubecl_profile.log --steps 8

Works with any CubeCL runtime; on lavapipe (Mesa's Vulkan on the CPU) the times are a CPU's,
but the launch counts are the GPU's.
"""

import argparse
import collections
import re
import sys

UNIT_MS = {"ns": 1e-6, "µs": 1e-3, "us": 1e-3, "ms": 1.0, "s": 1e3}
LINE = re.compile(r"\|\s*([0-9.]+)(ns|µs|us|ms|s)\s*\|\s*(.*)")
PROBES = ("LaunchOverhead", "Throughput")


def launches(path):
    """(ms, kernel name) of every launch in the log but the throughput probes."""
    out = []
    with open(path, errors="replace") as f:
        for line in f:
            m = LINE.match(line)
            if not m:
                continue
            # Generic arguments and hashes of the kernel's comptime settings stay; the
            # argument lists (after `<`) go.
            name = re.sub(r"<.*", "", m.group(3).strip())[:90]
            if not any(p in name for p in PROBES):
                out.append((float(m.group(1)) * UNIT_MS[m.group(2)], name))
    return out


def step_marks(rows, steps):
    """(marker, indices of its launches): the kernel launched exactly `steps` times whose
    launches after the first are evenly spaced (each step launches the same kernels), the
    earliest such; or None."""
    where = collections.defaultdict(list)
    for i, (_, name) in enumerate(rows):
        where[name].append(i)
    even = []
    for name, idx in where.items():
        gaps = [b - a for a, b in zip(idx, idx[1:])]
        if len(idx) == steps and len(set(gaps[1:])) <= 1:
            even.append((idx[0], name))
    if not even:
        return None
    _, marker = min(even)
    return marker, where[marker]


def table(rows, top):
    """Prints `rows` summed by kernel, the longest first."""
    total, count = collections.Counter(), collections.Counter()
    for ms, name in rows:
        total[name] += ms
        count[name] += 1
    grand = sum(total.values()) or 1.0
    print(f"{len(rows)} launches, {grand:.2f} ms of kernel time")
    for name, ms in total.most_common(top):
        print(f"{ms:10.3f} ms {100 * ms / grand:5.1f} % {count[name]:6d} x  {name}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("log", help="CubeCL's profile log")
    p.add_argument("--steps", type=int, help="training steps in the log (the bench: 8 a kind)")
    p.add_argument("--top", type=int, default=25, help="kernels listed (default 25)")
    a = p.parse_args()
    try:
        rows = launches(a.log)
    except OSError as e:
        sys.exit(f"{a.log}: cannot read the profile log: {e.strerror}")
    if not rows:
        sys.exit(f"{a.log}: no kernel launches (is the profiling logger on?)")
    if a.steps is None:
        table(rows, a.top)
        return
    marks = step_marks(rows, a.steps)
    if marks is None or len(marks[1]) < 2:
        sys.exit(f"{a.log}: no kernel is launched exactly {a.steps} times; not {a.steps} steps?")
    marker, idx = marks
    print(f"step marker: {marker}")
    print("launches between marks:", ", ".join(str(b - a) for a, b in zip(idx, idx[1:])))
    print("the last whole step:")
    table(rows[idx[-2] : idx[-1]], a.top)


if __name__ == "__main__":
    main()
