#!/usr/bin/env bash
# The GPU measurements of the throughput issue in one lease of a lent GPU machine (no Rust
# toolchain, no network there): binaries built here with `--features wgpu` travel compressed in
# `.devrun/bin.tar.xz`, the Vulkan loader's Debian packages in `.gl/` (see the device tool's
# README). Scenes are generated there (the default profile's, and benches/profiles/
# paper_one_scene.toml at 512 px): both need no data files. Prepare with
# `benches/device_gpu_prepare.sh`, then run from the checkout's root on the device machine:
#
#   bash benches/device_gpu.sh            # logs packed into $OUT/logs.tar.gz
#
# Steps, each under its own time limit so that one hang cannot eat the lease:
#   1. the device: nvidia-smi, the Vulkan ICD, PyTorch's view of the GPU;
#   2. correctness: the wgpu path against the CPU (tests/gpu_backend.rs) on the real GPU;
#   3. the training step at batch 32,768, all 9 model kinds on wgpu, the Single MLP back to back
#      with PyTorch on CUDA (f32, three rounds), then PyTorch with TF32 and bf16 autocast once;
#   4. the same bench on the machine's CPU cores (flex) against PyTorch on the CPU;
#   5. end to end: profile_steps (every model of the default run's Spot x blue-acrylic, fixed
#      steps, then evaluation) on wgpu;
#   6. the paper's scale: the same for one scene of the `full` profile (512 px, batch 2^15),
#      three models (their evaluation at 512 px is the part the bench cannot give);
#   7. the CPU baselines of 3 and 5 on the machine's cores.
set -u
R=.devrun
OUT=${OUT:-/tmp/device-gpu}
LOGS=/tmp/device-gpu-logs
mkdir -p "$OUT" "$LOGS"
STEPS=${DEVICE_STEPS:-300}
# Every step ends by this many seconds after the start (the device tool's calls are limited).
DEADLINE=${DEVICE_DEADLINE:-560}
step() { echo; echo "== $(date +%T) $*"; }
run() { # run LIMIT LOG COMMAND...: time-limited, output to the terminal and $OUT/LOG
    local limit=$1 log=$2
    shift 2
    local left=$((DEADLINE - SECONDS))
    [ "$left" -lt "$limit" ] && limit=$left
    if [ "$limit" -lt 15 ]; then
        echo "-- $log: skipped, the deadline is near"
        return
    fi
    local t0=$SECONDS
    timeout "$limit" "$@" 2>&1 | tee "$LOGS/$log"
    echo "-- $log: exit ${PIPESTATUS[0]} after $((SECONDS - t0)) s"
}

step "device"
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[ -f "$icd" ] && export VK_DRIVER_FILES=$icd
nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.sm,clocks.max.sm --format=csv
nproc
python3 -c "import torch; print('torch', torch.__version__, torch.cuda.get_device_name(0))"
tar -xJf $R/bin.tar.xz -C $R
B=$R/bin
ls -la $B

step "wgpu against the CPU on this GPU"
run 60 gpu_backend.log $B/gpu_backend --test-threads=1

step "training step, wgpu, against PyTorch on CUDA"
run 200 step_wgpu.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_ALL_MODELS=1 BRDF_BENCH_BACKENDS=wgpu \
    BRDF_BENCH_PYTORCH=python3 $B/train_step --bench
for mode in f32 tf32 bf16; do
    flag=$([ $mode = f32 ] || echo --$mode)
    run 40 "pytorch_cuda_$mode.log" python3 benches/pytorch_step.py --device cuda $flag
done

step "the default run's scenes (no training)"
run 120 default_scenes.log $B/profile_steps --prepare default /tmp/default
step "end to end on wgpu: $STEPS steps per model, then evaluation"
run 200 profile_wgpu.log $B/profile_steps /tmp/default spot__blue-acrylic "$STEPS" wgpu

step "the paper's scale: one scene of the full profile at 512 px"
run 120 full_scene.log $B/profile_steps --prepare benches/profiles/paper_one_scene.toml /tmp/full
run 240 profile_full_wgpu.log $B/profile_steps /tmp/full spot__blue-acrylic "${FULL_STEPS:-50}" wgpu \
    "${FULL_MODELS:-SingleMlp,AdditiveSharedEnhanced,Disney}"

step "training step, CPU ($(nproc) threads), against PyTorch on the CPU"
run 120 step_cpu.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_ALL_MODELS=1 BRDF_BENCH_BACKENDS=flex \
    BRDF_BENCH_PYTORCH=python3 $B/train_step --bench

step "end to end on the CPU: $STEPS steps per model, then evaluation"
run 150 profile_cpu.log $B/profile_steps /tmp/default spot__blue-acrylic "$STEPS" cpu
step "done"
tar -czf "$OUT/logs.tar.gz" -C "$LOGS" .
