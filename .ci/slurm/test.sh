#!/usr/bin/env bash
# The cluster path against a real Slurm (issue 58), on this host: Debian's slurm-wlm and munge
# (installed when missing), munged, slurmctld and slurmd started here (cluster.sh), then
#
# 1. the smoke profile submitted with `reproduce-tables --slurm` (46 runs, split into three
#    arrays by the cluster's MaxArraySize of 20); its collect job's tables must equal those of
#    a local `reproduce-tables --profile smoke`, wall-time cells aside;
# 2. preemption: a task requeued mid-training (`scontrol requeue`) resumes from its checkpoint
#    and ends with the same weights file, byte for byte, as an uninterrupted local run;
# 3. failure: a task whose scene file is corrupted is listed as failed by the collect job and
#    by `sweep-status`; the resubmit command the collect job printed, run after the file is
#    restored, completes the tables.
#
# Usage: .ci/slurm/test.sh [XTASK] (default: target/debug/xtask, the test build's). Every run
# uses one thread (the tasks ask for one CPU), so that local and cluster runs compute alike.
# The daemons are stopped by their PIDs on exit. Prints each part's wall time.
set -euo pipefail
cd "$(dirname "$0")/../.."
xtask=${1:-$PWD/target/debug/xtask}
[ -x "$xtask" ] || { echo "slurm test: no xtask at $xtask (build it first)" >&2; exit 1; }
xtask=$(realpath "$xtask")
source .ci/slurm/cluster.sh
t0=$SECONDS
cluster_install
tmp=$(mktemp -d "${TMPDIR:-/tmp}/nbrdf-slurm.XXXXXX")
trap 'cluster_down; rm -rf "$tmp"' EXIT
# A small MaxArraySize, so that the smoke profile's 46 runs go out as three arrays.
CLUSTER_MAX_ARRAY_SIZE=20 cluster_up "$tmp/cluster"
echo "slurm test: cluster up after $((SECONDS - t0)) s" >&2
export RAYON_NUM_THREADS=1
slurm=(--slurm --slurm-cpus 1 --slurm-mem 1500)

fail() {
    echo "slurm test FAILED: $*" >&2
    exit 1
}
# A field of the last submission in a sweep's slurm/sweep.json.
last() {
    python3 -c 'import json, sys
s = json.load(open(sys.argv[1] + "/slurm/sweep.json"))["submissions"][-1]
print(eval(sys.argv[2]))' "$1" "$2"
}
# Slurm holds a requeued job for two minutes (its BeginTime); the test lets it start at once.
release_requeued() {
    local j
    for j in $(squeue -h -t PD -o '%i %r' | awk '$2 == "BeginTime" {print $1}'); do
        scontrol update JobId="$j" StartTime=now >/dev/null 2>&1 || true
    done
}
# Waits until job $1 has left the queue (at most $2 s).
wait_job() {
    local end=$((SECONDS + $2))
    while squeue -h -j "$1" 2>/dev/null | grep -q .; do
        [ $SECONDS -lt $end ] || fail "job $1 still queued after $2 s: $(squeue -h)"
        release_requeued
        sleep 1
    done
}
# The tables of two sweeps, equal but for the cells that hold wall times: the time table
# (time.md, and its copy at the end of all.md) and the run-time table's seconds columns (whose
# best/second/third marks follow the seconds too, so those tables lose their marks).
same_tables() {
    python3 - "$1/tables" "$2/tables" <<'PY' || fail "the tables of $1 and $2 differ"
import pathlib, re, sys

def normal(text):
    out, mask, skip = [], None, False
    for line in text.splitlines():
        if line.startswith("**Where the time went"):
            skip = True
        elif skip and (line.startswith("**") or line.startswith("#")):
            skip = False
        if skip:
            continue
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if mask is None:
                mask = [bool(re.search(r"time \(s\)|^s to ", c)) for c in cells]
            if any(mask):
                cells = ["<time>" if i < len(mask) and mask[i] else re.sub(r"\*\*|\*|</?u>", "", c)
                         for i, c in enumerate(cells)]
            line = "| " + " | ".join(cells) + " |"
        else:
            mask = None
        out.append(line)
    return out

a, b = map(pathlib.Path, sys.argv[1:3])
bad = 0
for f in sorted(a.glob("*.md")):
    if f.name == "time.md":
        continue
    g = b / f.name
    if not g.is_file():
        print(f"{g} is missing", file=sys.stderr); bad += 1; continue
    x, y = normal(f.read_text()), normal(g.read_text())
    if x != y:
        first = next(i for i, (p, q) in enumerate(zip(x + [""], y + [""])) if p != q)
        print(f"{f.name} differs at line {first + 1}:\n  {x[first] if first < len(x) else '(end)'}\n  {y[first] if first < len(y) else '(end)'}", file=sys.stderr)
        bad += 1
print(f"{len(list(a.glob('*.md')))} tables compared, {bad} differ", file=sys.stderr)
sys.exit(1 if bad else 0)
PY
}

# 1. The smoke profile on the cluster and here.
t1=$SECONDS
"$xtask" reproduce-tables --profile smoke --out "$tmp/smoke-slurm" "${slurm[@]}" 2>"$tmp/submit.log" ||
    { cat "$tmp/submit.log" >&2; fail "submitting the smoke profile"; }
collect=$(last "$tmp/smoke-slurm" 's["collect_job"]')
arrays=$(last "$tmp/smoke-slurm" '[a["count"] for a in s["arrays"]]')
[ "$arrays" = "[20, 20, 6]" ] || fail "MaxArraySize 20: arrays of $arrays tasks"
wait_job "$collect" 900
"$xtask" reproduce-tables --profile smoke --out "$tmp/smoke-local" --jobs 2 >/dev/null 2>"$tmp/local.log" ||
    { tail -n 20 "$tmp/local.log" >&2; fail "the local smoke sweep"; }
same_tables "$tmp/smoke-slurm" "$tmp/smoke-local"
n=$(ls "$tmp/smoke-slurm/tables"/*.md | wc -l)
echo "slurm test: smoke on Slurm = smoke here ($n tables) in $((SECONDS - t1)) s" >&2

# 2. and 3. Preemption and failure, on the test's own two-run sweep.
t2=$SECONDS
out=$tmp/ci-slurm
"$xtask" reproduce-tables --profile .ci/slurm/preempt.toml --out "$out" "${slurm[@]}" \
    --sbatch=--hold 2>"$tmp/submit2.log" || { cat "$tmp/submit2.log" >&2; fail "submitting"; }
long=$(ls -d "$out"/runs/*blue-acrylic*)
broken=$(ls -d "$out"/runs/*gold-metallic-paint*)
scene=$(ls -d "$out"/scenes/*gold-metallic-paint*)
image=$(find "$scene" -name '*.exr' | sort | sed -n 1p)
cp "$image" "$tmp/kept.exr"
printf 'corrupt' | dd of="$image" bs=1 seek=100 conv=notrunc 2>/dev/null
array=$(last "$out" 's["arrays"][0]["job"]')
collect=$(last "$out" 's["collect_job"]')
scontrol release "$array" "$collect"
# Requeue the long run's task once it has a checkpoint and is still training.
end=$((SECONDS + 300))
until ls "$long"/checkpoints/step-* >/dev/null 2>&1; do
    [ $SECONDS -lt $end ] || fail "no checkpoint in $long"
    sleep 0.2
done
task=$(grep -l "$long" "$out"/slurm/submit-001/tasks-*.txt | sed -n 1p)
index=$(($(grep -n "^$long\$" "$task" | cut -d: -f1) - 1))
scontrol requeue "${array}_${index}"
echo "slurm test: requeued task ${array}_${index} at $(ls "$long"/checkpoints) after $((SECONDS - t2)) s" >&2
wait_job "$collect" 600
echo "slurm test: first collect job done after $((SECONDS - t2)) s" >&2
grep -q "start 2)" "$long/sweep.log" || fail "the long run's task did not start again: $(cat "$long/sweep.log")"
grep -q "stopped by a signal after step" "$long/sweep.log" ||
    fail "the long run did not stop at a step boundary: $(cat "$long/sweep.log")"
grep -q "resuming from the checkpoint at step" "$long/sweep.log" ||
    fail "the requeued task did not resume from the checkpoint: $(cat "$long/sweep.log")"
report=$out/slurm/failed.txt
[ -f "$report" ] || fail "the collect job wrote no failure list"
grep -q "failed: $broken" "$report" || fail "the failure list misses $broken: $(cat "$report")"
grep -q "run id" "$report" && grep -q "log $broken/sweep.log" "$report" || fail "ids or logs missing"
"$xtask" sweep-status "$out" | grep -q "1 done, 0 running, 1 failed" ||
    fail "sweep-status: $("$xtask" sweep-status "$out")"
cp "$tmp/kept.exr" "$image"
resubmit=$(grep -o 'cargo xtask slurm-resubmit .*' "$report" | sed -n 1p)
[ -n "$resubmit" ] || fail "no resubmit command in $report"
eval "\"$xtask\" ${resubmit#cargo xtask }" 2>"$tmp/resubmit.log" ||
    { cat "$tmp/resubmit.log" >&2; fail "resubmitting"; }
# The resubmission keeps the first one's options, --hold included.
scontrol release "$(last "$out" 's["arrays"][0]["job"]')" "$(last "$out" 's["collect_job"]')"
wait_job "$(last "$out" 's["collect_job"]')" 600
"$xtask" sweep-status "$out" | grep -q "2 runs: 2 done" || fail "not complete: $("$xtask" sweep-status "$out")"
# The uninterrupted runs, here.
"$xtask" reproduce-tables --profile .ci/slurm/preempt.toml --out "$tmp/local-ci" --jobs 1 \
    >/dev/null 2>"$tmp/local2.log" || { tail -n 20 "$tmp/local2.log" >&2; fail "the local runs"; }
for run in "$long" "$broken"; do
    cmp "$run/weights.bpk" "$tmp/local-ci/runs/${run##*/}/weights.bpk" ||
        fail "${run##*/}: the weights differ from an uninterrupted run's"
done
same_tables "$out" "$tmp/local-ci"
echo "slurm test: requeued mid-training, same weights; failure listed, resubmitted, complete in $((SECONDS - t2)) s" >&2
echo "slurm test: passed in $((SECONDS - t0)) s" >&2
