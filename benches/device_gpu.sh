#!/usr/bin/env bash
# The GPU measurements of the throughput issue on a lent GPU machine (no Rust toolchain, no
# network there): binaries built here with `--features wgpu` travel compressed in
# `.devrun/bin.tar.xz`, the Vulkan loader's Debian packages in `.gl/` (see the device tool's
# README). Scenes are generated there (the default profile's, and benches/profiles/
# paper_one_scene.toml at 512 px): both need no data files. Prepare with
# `benches/device_gpu_prepare.sh`, then run from the checkout's root on the device machine, one
# stage a call of the device tool (the 15 minutes a session is lent hold the first two):
#
#   bash benches/device_gpu.sh step      # logs packed into $OUT/step.tar.gz
#   bash benches/device_gpu.sh final     # logs packed into $OUT/final.tar.gz
#   bash benches/device_gpu.sh e2e       # logs packed into $OUT/e2e.tar.gz (a third lease)
#   bash benches/device_gpu.sh paper     # the full profile's one scene, all 9 models; one lease
#   bash benches/device_gpu.sh eval      # evaluation's start-up, previous build against this one
#   bash benches/device_gpu.sh loop      # the loop with losses read every step or every 100 steps,
#                                        # SM use, and the warm-up with a persistent GPU cache
#   bash benches/device_gpu.sh cpu       # the many-core CPU: the flex step of all 9 kinds against
#                                        # PyTorch on as many threads, the weight gradients' split
#   bash benches/device_gpu.sh kinds     # the wgpu step of all 9 kinds against PyTorch's step of
#                                        # each kind on CUDA: eager f32, TF32, a CUDA graph
#   bash benches/device_gpu.sh linear    # the linear layers on gpu-kernels against burn's:
#                                        # correctness, all 9 kinds' steps beside PyTorch's,
#                                        # split lengths, the training loop
#   bash benches/device_gpu.sh tiles     # after `linear`: gpu-kernels' split rule and both
#                                        # tiles, every kind beside PyTorch, the loop
#   bash benches/device_gpu.sh checks    # gpu-kernels unchecked (the default), checked, and
#                                        # with 4-wide shared reads (64v, 128v): one layer's
#                                        # products, every kind beside PyTorch, the loop with
#                                        # FMBRDF's dense Lambda network, the start-up
#   bash benches/device_gpu.sh cuda      # CubeCL's CUDA runtime (NVRTC) against wgpu, and bf16
#                                        # products on tensor cores: correctness, one layer,
#                                        # every kind beside PyTorch f32 and bf16 autocast, the
#                                        # loop in f32 and bf16
#
# With autotune on (the wgpu feature), the first use of every matrix-product shape in a process
# is benchmarked, and the first process on a fresh machine also compiles every kernel and runs
# CubeCL's throughput probes: allow about 10 s a model kind for that.
#
# `step`:
#   1. the device: nvidia-smi, the Vulkan ICD, PyTorch's view of the GPU;
#   2. correctness: the wgpu path against the CPU (tests/gpu_backend.rs) on the real GPU;
#   3. the baseline: the previous build's training step (`.devrun_old/bin.tar.xz`, when
#      carried: burn's wgpu without autotune, fusion or the batch split), same machine;
#   4. the training step at batch 32,768, three model kinds on wgpu, without and with the batch
#      split (`brdf_neural::batch_split`), one layer's products alone, and the Single MLP back to
#      back with PyTorch on CUDA (f32, three rounds);
#   5. where a step's GPU time goes: CubeCL's kernel profile of Single MLP steps, summed by kernel;
#   6. the step on the machine's CPU cores (flex), without and with the batch split.
# `final`: the correctness test with minimal autotune, all 9 kinds' steps at the trainer's
# split (against PyTorch in `kinds`), and three models end to end on the default run's scene.
# `paper`: all 9 models on one scene of the `full` profile (512 px, batch 2^15): the real
# training loop's samples/s after a warm-up, the validation pass, the evaluation at 512 px; then
# the default run's Single MLP for its converged CPU fit's steps; the GPU's use, sampled.
# `e2e`:
#   7. end to end: profile_steps (every model of the default run's Spot x blue-acrylic, fixed
#      steps, then evaluation) on wgpu;
#   8. the paper's scale: the same for one scene of the `full` profile (512 px, batch 2^15).
set -u
STAGE=${1:-step}
R=.devrun
OUT=${OUT:-/tmp/device-gpu}
LOGS=/tmp/device-gpu-logs/$STAGE
mkdir -p "$OUT" "$LOGS"
STEPS=${DEVICE_STEPS:-300}
# Every step ends by this many seconds after the start (the device tool's calls are limited).
DEADLINE=${DEVICE_DEADLINE:-400}
step() { echo; echo "== $(date +%T) $*"; }
run() { # run LIMIT LOG COMMAND...: time-limited, output to the terminal and $LOGS/LOG
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
[ -d $R/bin ] || tar -xJf $R/bin.tar.xz -C $R
B=$R/bin
ls -la $B

if [ "$STAGE" = step ]; then
    python3 -c "import torch; print('torch', torch.__version__, torch.cuda.get_device_name(0))"
    step "wgpu against the CPU on this GPU"
    run 120 gpu_backend.log $B/gpu_backend --test-threads=1

    if [ -f .devrun_old/bin.tar.xz ]; then
        step "baseline: the previous build's step on wgpu"
        mkdir -p /tmp/old && tar -xJf .devrun_old/bin.tar.xz -C /tmp/old
        run 60 step_wgpu_old.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_BACKENDS=wgpu \
            /tmp/old/bin/train_step --bench
    fi

    step "training step, wgpu: batch split 1 and 64, against PyTorch on CUDA"
    run 150 step_wgpu.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_BACKENDS=wgpu \
        BRDF_BENCH_SPLIT=1,64 BRDF_BENCH_PYTORCH=python3 $B/train_step --bench

    step "kernel profile of the Single MLP step (split 64)"
    printf '[profiling.logger]\nlevel = "basic"\nfile = "/tmp/cubecl_profile.log"\n' >cubecl.toml
    run 60 step_profiled.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_BACKENDS=wgpu BRDF_BENCH_SPLIT=64 \
        $B/train_step --bench
    rm -f cubecl.toml
    python3 benches/kernel_profile.py /tmp/cubecl_profile.log | tee "$LOGS/kernel_profile.txt"

    step "training step on the machine's CPU cores (flex): batch split 1 and 16"
    run 90 step_cpu.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_BACKENDS=flex BRDF_BENCH_SPLIT=1,16 \
        $B/train_step --bench
fi

if [ "$STAGE" = final ]; then
    # What a second, shorter call measures after `step` (autotune makes the first use of every
    # shape slow: the all-model bench with two splits outlasted its limit there).
    step "wgpu against the CPU on this GPU (autotune minimal)"
    run 90 gpu_backend.log env CUBECL_AUTOTUNE_LEVEL=minimal $B/gpu_backend --test-threads=1
    step "training step, wgpu, the trainer's split (64 parts), all 9 kinds (PyTorch: \`kinds\`)"
    run 170 step_wgpu.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_ALL_MODELS=1 BRDF_BENCH_BACKENDS=wgpu \
        $B/train_step --bench
    step "end to end on wgpu: $STEPS steps, three models, then evaluation"
    run 50 default_scenes.log $B/profile_steps --prepare default /tmp/default
    run 130 profile_wgpu.log $B/profile_steps /tmp/default spot__blue-acrylic "$STEPS" wgpu \
        "${E2E_MODELS:-SingleMlp,AdditiveSharedEnhanced,Disney}"
fi

if [ "$STAGE" = paper ]; then
    # One call for the paper's scale (items 4 and 5 of the throughput issue): every model of
    # Table 1 on one scene of the `full` profile, against the previous build's Single MLP; then
    # the default run's Single MLP for the steps of its converged CPU fit. `nvidia-smi dmon`
    # samples the GPU's use every second. Each model's warm-up fit (PROFILE_WARMUP_STEPS) runs
    # as many steps as the measured one, so that both hold one validation pass (every 250
    # steps in the `full` profile) and autotune's start-up stays in the warm-up.
    nvidia-smi dmon -s u -d 1 >"$LOGS/gpu_use.log" 2>&1 &
    DMON=$!
    export PROFILE_WARMUP_STEPS=${FULL_STEPS:-250}
    step "wgpu: batch rows selected on the device against the rows gathered on the CPU"
    run 45 gpu_backend.log $B/gpu_backend spatial_rows --test-threads=1
    step "the paper's scale: one scene of the full profile at 512 px (scene, features, runs)"
    run 150 full_scene.log $B/profile_steps --prepare benches/profiles/paper_one_scene.toml /tmp/full
    if [ -f .devrun_old/bin.tar.xz ]; then
        step "baseline: the previous build (batch rows gathered on the CPU), Single MLP"
        mkdir -p /tmp/old && tar -xJf .devrun_old/bin.tar.xz -C /tmp/old
        run 100 profile_full_old.log /tmp/old/bin/profile_steps /tmp/full spot__blue-acrylic \
            "${FULL_STEPS:-250}" wgpu SingleMlp
    fi
    step "the full profile on wgpu, all 9 models (evaluated at 512 px: ${FULL_EVAL:-Fmbrdf})"
    run "${FULL_LIMIT:-330}" profile_full_wgpu.log env PROFILE_EVAL="${FULL_EVAL:-Fmbrdf}" \
        $B/profile_steps /tmp/full spot__blue-acrylic "${FULL_STEPS:-250}" wgpu ${FULL_MODELS:+"$FULL_MODELS"}
    step "the default run's scene: the Single MLP for the 1,400 steps of its converged CPU fit"
    export PROFILE_WARMUP_STEPS=50
    run 40 default_scenes.log $B/profile_steps --prepare default /tmp/default
    run 80 profile_wgpu.log $B/profile_steps /tmp/default spot__blue-acrylic \
        "${DEFAULT_STEPS:-1400}" wgpu SingleMlp
    kill $DMON
fi

if [ "$STAGE" = eval ]; then
    # Evaluation's start-up on a GPU (benches/README.md, "Why evaluation was slow on a GPU"):
    # a Single MLP fitted and evaluated three times in one process (PROFILE_EVAL_REPEAT: the
    # first evaluation pays for new kernel shapes, the later ones are the steady state), by the
    # previous build (`.devrun_old`, when carried: passes padded to powers of two) and by this
    # one (padded and split into the training loop's parts of 512 rows). The NVIDIA driver's
    # shader cache is off and so is CubeCL's persistent autotune cache, so that neither process
    # reuses the other's compilations; CubeCL logs each kernel compiled and each autotune
    # decision. Then both builds train the default run's Single MLP for the 1,400 steps of its
    # converged CPU fit, without evaluation: its validation pass every 100 steps is where the
    # split should show in training (stop 37: 5.4 of 10.2 ms a step). One call of up to 560 s:
    # DEVICE_DEADLINE=560 bash benches/device_gpu.sh eval
    export __GL_SHADER_DISK_CACHE=0
    step "the default run's scenes (no training)"
    run 40 default_scenes.log $B/profile_steps --prepare default /tmp/default
    logged() { # logged NAME: cubecl.toml logging compilations and tuning to $LOGS/NAME-*.log
        rm -f "$LOGS/$1"-*.log
        printf '[compilation.logger]\nlevel = "basic"\nfile = "%s"\n' "$LOGS/$1-compile.log" >cubecl.toml
        printf '[autotune]\ndisable_cache = true\n[autotune.logger]\nlevel = "minimal"\nfile = "%s"\n' \
            "$LOGS/$1-autotune.log" >>cubecl.toml
    }
    if [ -f .devrun_old/bin.tar.xz ]; then
        mkdir -p /tmp/old && tar -xJf .devrun_old/bin.tar.xz -C /tmp/old
        logged old
        step "the previous build: a Single MLP evaluated three times"
        run 130 eval_old.log env PROFILE_EVAL_REPEAT=3 /tmp/old/bin/profile_steps /tmp/default \
            spot__blue-acrylic 100 wgpu SingleMlp
    fi
    logged new
    step "this build: the same"
    run 130 eval_new.log env PROFILE_EVAL_REPEAT=3 $B/profile_steps /tmp/default \
        spot__blue-acrylic 100 wgpu SingleMlp
    rm -f cubecl.toml
    wc -l "$LOGS"/*-compile.log "$LOGS"/*-autotune.log
    step "the default run's Single MLP, 1,400 steps, no evaluation: the previous build, this one"
    if [ -f .devrun_old/bin.tar.xz ]; then
        run 90 train_old.log env PROFILE_EVAL=none /tmp/old/bin/profile_steps /tmp/default \
            spot__blue-acrylic 1400 wgpu SingleMlp
    fi
    run 90 train_new.log env PROFILE_EVAL=none $B/profile_steps /tmp/default \
        spot__blue-acrylic 1400 wgpu SingleMlp
fi

if [ "$STAGE" = e2e ]; then
    step "the default run's scenes (no training)"
    run 120 default_scenes.log $B/profile_steps --prepare default /tmp/default
    step "end to end on wgpu: $STEPS steps per model, then evaluation"
    run 200 profile_wgpu.log $B/profile_steps /tmp/default spot__blue-acrylic "$STEPS" wgpu

    step "the paper's scale: one scene of the full profile at 512 px"
    run 100 full_scene.log $B/profile_steps --prepare benches/profiles/paper_one_scene.toml /tmp/full
    run 200 profile_full_wgpu.log $B/profile_steps /tmp/full spot__blue-acrylic \
        "${FULL_STEPS:-50}" wgpu "${FULL_MODELS:-SingleMlp,AdditiveSharedEnhanced,Disney}"
fi
if [ "$STAGE" = loop ]; then
    # The training loop's host round trips (item 2 of the throughput issue): the default run's
    # Single MLP and FMBRDF for the 1,400 steps of the converged CPU fit, reading the loss
    # every step (NEURAL_BRDF_LOSS_READS=1, the loop before the loss windows) and every 100
    # steps (the GPU's default, `experiments::train_loop::GPU_LOSS_READS`), alternately, with
    # `nvidia-smi dmon` sampling the SM use every second (the log marks where each run starts).
    # The four runs are separate processes sharing one fresh persistent GPU cache
    # (brdf_neural::gpu_cache): the first pays autotune and kernel compilation in its warm-up
    # table, the later ones show what is left of that start-up.
    export PROFILE_WARMUP_STEPS=50 PROFILE_EVAL=none NEURAL_BRDF_GPU_CACHE=/tmp/gpu-cache
    rm -rf "$NEURAL_BRDF_GPU_CACHE"
    run 60 default_scenes.log $B/profile_steps --prepare default /tmp/default
    nvidia-smi dmon -s u -d 1 -o T >"$LOGS/gpu_use.log" 2>&1 &
    DMON=$!
    for round in 1 2; do
        for reads in 1 100; do
            echo "== $(date +%T) reads $reads round $round" >>"$LOGS/gpu_use.log"
            run 70 "loop_reads${reads}_r$round.log" env NEURAL_BRDF_LOSS_READS=$reads \
                $B/profile_steps /tmp/default spot__blue-acrylic 1400 wgpu SingleMlp,Fmbrdf
        done
    done
    kill $DMON
fi
if [ "$STAGE" = kinds ]; then
    # Item 1 of the throughput issue: every kind's step (batch 2^15, the trainer's split) back
    # to back with PyTorch's step of the same kind (`benches/pytorch_step.py --kind`, rebuilt
    # from `neural_brdfs.reference_torch`), eager f32 with TF32 off, three rounds; then
    # PyTorch alone with TF32 and with the step captured in a CUDA graph (the stretch target).
    # One call: DEVICE_DEADLINE=560 bash benches/device_gpu.sh kinds
    export PYTHONPATH=$PWD/crates/py-neural-brdfs/python${PYTHONPATH:+:$PYTHONPATH}
    python3 -c "import torch; print('torch', torch.__version__, torch.cuda.get_device_name(0))"
    step "the wgpu step, all 9 kinds, against PyTorch eager f32 on CUDA"
    run 380 step_kinds.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_ALL_MODELS=1 BRDF_BENCH_BACKENDS=wgpu \
        BRDF_BENCH_RATES=1 BRDF_BENCH_PYTORCH=python3 $B/train_step --bench
    step "PyTorch alone: TF32, then a CUDA graph (f32), all 9 kinds"
    run 60 torch_tf32.log python3 benches/pytorch_step.py --kind all --device cuda --tf32 --reps 30
    run 60 torch_graph.log python3 benches/pytorch_step.py --kind all --device cuda --cuda-graph \
        --reps 30
fi
if [ "$STAGE" = cpu ]; then
    # Item 5 of the throughput issue: the f32 step on all the machine's cores against PyTorch
    # on as many threads (`benches/pytorch_step.py --kind`, the model rebuilt from
    # `neural_brdfs.reference_torch`), back to back, every kind; then the same on two cores
    # (`taskset`), the development machine's count. Before the steps, the weight-gradient
    # products alone (`benches/weight_gradient.rs`): the kernels' split (32 blocks of k at
    # 2^15) against gemm over the output and against 8, 16 and 64 blocks, on all threads and
    # on one. No GPU is used. The package's Python sources come from the checkout.
    export PYTHONPATH=$PWD/crates/py-neural-brdfs/python${PYTHONPATH:+:$PYTHONPATH}
    lscpu | grep -E "Model name|^CPU\(s\)|Thread|Flags" | cut -c1-300
    # A short call (the second of a lease): CPU_WGRAD=0 skips the weight gradients alone,
    # PYTORCH_ROUNDS=1 times PyTorch once a kind instead of three times.
    export BRDF_BENCH_PYTORCH_ROUNDS=${PYTORCH_ROUNDS:-3}
    if [ "${CPU_WGRAD:-1}" != 0 ]; then
        step "weight gradients: all threads, then one"
        run 60 wgrad_all.log env CPU_KERNELS_BENCH_BATCH=32768 $B/weight_gradient --bench '^$'
        run 60 wgrad_one.log env CPU_KERNELS_BENCH_BATCH=32768 RAYON_NUM_THREADS=1 \
            $B/weight_gradient --bench '^$'
    fi
    step "the f32 step on all cores, all 9 kinds, against PyTorch on as many threads"
    run 300 step_cpu_all.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_ALL_MODELS=1 \
        BRDF_BENCH_BACKENDS=flex BRDF_BENCH_PYTORCH=python3 $B/train_step --bench
    step "the same on two cores, Single MLP and Disney"
    run 120 step_cpu_two.log env RAYON_NUM_THREADS=2 BRDF_BENCH_QUICK=1 \
        BRDF_BENCH_MODELS=single_mlp,disney BRDF_BENCH_BACKENDS=flex BRDF_BENCH_PYTORCH=python3 \
        taskset -c 0,1 $B/train_step --bench
fi
if [ "$STAGE" = linear ]; then
    # The linear layers on this workspace's GPU kernels (`gpu-kernels`, NEURAL_BRDF_GPU_LINEAR=
    # ours: the bias fused into a tiled product, split-K inside the weight gradient) against
    # burn's (CubeCL's autotuned product, the trainer's batch split), in one call of a 15-minute
    # lease: first the wgpu tests against the CPU on our kernels; then every kind's step at
    # batch 2^15 on ours, each back to back with PyTorch eager f32 (TF32 off, one round), and
    # the same steps on burn's kernels; the Single MLP's step with other split lengths
    # (NEURAL_BRDF_GPU_SPLIT_LEN); then the default run's Single MLP for 1,400 steps on each,
    # `nvidia-smi dmon` sampling the SM use. All processes share one persistent GPU cache, so
    # autotune's choices are paid once. One call: DEVICE_DEADLINE=470 bash benches/device_gpu.sh linear
    export PYTHONPATH=$PWD/crates/py-neural-brdfs/python${PYTHONPATH:+:$PYTHONPATH}
    export NEURAL_BRDF_GPU_CACHE=/tmp/gpu-cache
    python3 -c "import torch; print('torch', torch.__version__, torch.cuda.get_device_name(0))"
    step "wgpu against the CPU on this GPU, the linear layers on gpu-kernels"
    run 60 gpu_backend_ours.log env NEURAL_BRDF_GPU_LINEAR=ours CUBECL_AUTOTUNE_LEVEL=minimal \
        $B/gpu_backend --test-threads=1
    step "the wgpu step, all 9 kinds, linear layers on ours, against PyTorch eager f32"
    run 150 step_ours.log env NEURAL_BRDF_GPU_LINEAR=ours BRDF_BENCH_QUICK=1 \
        BRDF_BENCH_ALL_MODELS=1 BRDF_BENCH_BACKENDS=wgpu BRDF_BENCH_RATES=1 \
        BRDF_BENCH_PYTORCH=python3 BRDF_BENCH_PYTORCH_ROUNDS=1 $B/train_step --bench
    step "the wgpu step, all 9 kinds, linear layers on burn's kernels"
    run 120 step_burn.log env NEURAL_BRDF_GPU_LINEAR=burn BRDF_BENCH_QUICK=1 \
        BRDF_BENCH_ALL_MODELS=1 BRDF_BENCH_BACKENDS=wgpu BRDF_BENCH_RATES=1 $B/train_step --bench
    for len in 512 8192; do
        step "the Single MLP step on ours, split length $len"
        run 30 "step_ours_split$len.log" env NEURAL_BRDF_GPU_LINEAR=ours \
            NEURAL_BRDF_GPU_SPLIT_LEN=$len BRDF_BENCH_QUICK=1 BRDF_BENCH_MODELS=single_mlp \
            BRDF_BENCH_BACKENDS=wgpu BRDF_BENCH_RATES=1 $B/train_step --bench
    done
    export PROFILE_WARMUP_STEPS=50 PROFILE_EVAL=none
    run 40 default_scenes.log $B/profile_steps --prepare default /tmp/default
    nvidia-smi dmon -s u -d 1 -o T >"$LOGS/gpu_use.log" 2>&1 &
    DMON=$!
    for kernels in ours burn; do
        echo "== $(date +%T) kernels $kernels" >>"$LOGS/gpu_use.log"
        run 45 "loop_$kernels.log" env NEURAL_BRDF_GPU_LINEAR=$kernels $B/profile_steps \
            /tmp/default spot__blue-acrylic 1400 wgpu SingleMlp
    done
    kill $DMON
fi
if [ "$STAGE" = tiles ]; then
    # After `linear` (same lease): gpu-kernels with the weight gradient's splits chosen to fill
    # the GPU (256 cubes) and the bias gradient in blocks of 128 rows, on both tiles. The wgpu
    # tests on the real GPU (64- and 128-wide tiles), every kind's step on ours back to back
    # with PyTorch eager f32 (one round), the Single MLP's step on 128-wide tiles and with splits
    # of 256 rows, the default run's Single MLP and FMBRDF for 1,400 steps with `nvidia-smi
    # dmon`, then every kind's step on 128-wide tiles. One call:
    # DEVICE_DEADLINE=320 bash benches/device_gpu.sh tiles
    export PYTHONPATH=$PWD/crates/py-neural-brdfs/python${PYTHONPATH:+:$PYTHONPATH}
    export NEURAL_BRDF_GPU_CACHE=/tmp/gpu-cache NEURAL_BRDF_GPU_LINEAR=ours
    for tile in 64 128; do
        step "wgpu against the CPU on this GPU, gpu-kernels, $tile-wide tiles"
        run 40 "gpu_backend_t$tile.log" env NEURAL_BRDF_GPU_TILE=$tile \
            CUBECL_AUTOTUNE_LEVEL=minimal $B/gpu_backend --test-threads=1
    done
    step "the wgpu step, all 9 kinds, on ours, against PyTorch eager f32"
    run 130 step_ours.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_ALL_MODELS=1 \
        BRDF_BENCH_BACKENDS=wgpu BRDF_BENCH_RATES=1 BRDF_BENCH_PYTORCH=python3 \
        BRDF_BENCH_PYTORCH_ROUNDS=1 $B/train_step --bench
    for variant in NEURAL_BRDF_GPU_TILE=128 NEURAL_BRDF_GPU_SPLIT_LEN=256; do
        step "the Single MLP step on ours, $variant"
        run 25 "step_ours_${variant##*_}.log" env "$variant" BRDF_BENCH_QUICK=1 \
            BRDF_BENCH_MODELS=single_mlp BRDF_BENCH_BACKENDS=wgpu BRDF_BENCH_RATES=1 \
            $B/train_step --bench
    done
    export PROFILE_WARMUP_STEPS=50 PROFILE_EVAL=none
    run 30 default_scenes.log $B/profile_steps --prepare default /tmp/default
    nvidia-smi dmon -s u -d 1 -o T >"$LOGS/gpu_use.log" 2>&1 &
    DMON=$!
    run 50 loop_ours.log $B/profile_steps /tmp/default spot__blue-acrylic 1400 wgpu \
        SingleMlp,Fmbrdf
    kill $DMON
    step "the wgpu step, all 9 kinds, on ours with 128-wide tiles"
    run 80 step_ours_t128.log env NEURAL_BRDF_GPU_TILE=128 BRDF_BENCH_QUICK=1 \
        BRDF_BENCH_ALL_MODELS=1 BRDF_BENCH_BACKENDS=wgpu BRDF_BENCH_RATES=1 $B/train_step --bench
fi
if [ "$STAGE" = checks ]; then
    # gpu-kernels launched without CubeCL's index checks and wgpu's loop counters (the default
    # since the H200's products ran at 7 to 8 % of its FP32 rate), and the tiles read from
    # shared memory four floats at a time (NEURAL_BRDF_GPU_TILE=64v, 128v): the wgpu tests on
    # the real GPU with those tilings; one 128-wide layer's three products at 2^15 rows on every
    # variant (the `layer` bench: 64, 64 checked, 128, 64v, 128v); every kind's step back to
    # back with PyTorch eager f32 (one round), then on 64v and 128v; the default run's Single
    # MLP and FMBRDF
    # (its Lambda network dense on a GPU since 7f07314) for 1,400 steps with `nvidia-smi dmon`;
    # its warm-up table gives each model's start-up in a process after the first (fit called
    # to first step done, the persistent GPU cache filled by the earlier processes); last, if
    # time is left, one Single MLP and one FMBRDF step's kernels (benches/kernel_profile.py).
    # One call: DEVICE_DEADLINE=500 bash benches/device_gpu.sh checks
    export PYTHONPATH=$PWD/crates/py-neural-brdfs/python${PYTHONPATH:+:$PYTHONPATH}
    export NEURAL_BRDF_GPU_CACHE=/tmp/gpu-cache NEURAL_BRDF_GPU_LINEAR=ours
    python3 -c "import torch; print('torch', torch.__version__, torch.cuda.get_device_name(0))"
    for tile in 64 64v 128v; do
        step "wgpu against the CPU on this GPU, gpu-kernels unchecked, tiles $tile"
        run 30 "gpu_backend_$tile.log" env NEURAL_BRDF_GPU_TILE=$tile \
            CUBECL_AUTOTUNE_LEVEL=minimal $B/gpu_backend --test-threads=1
    done
    step "one layer's products at 2^15 rows: 64, 64 checked, 128, 64v, 128v"
    run 60 layer.log env GPU_KERNELS_BENCH_ROWS=32768 $B/layer --bench --warm-up-time 1 \
        --measurement-time 1
    step "the wgpu step, all 9 kinds, against PyTorch eager f32"
    run 130 step_ours.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_ALL_MODELS=1 \
        BRDF_BENCH_BACKENDS=wgpu BRDF_BENCH_RATES=1 BRDF_BENCH_PYTORCH=python3 \
        BRDF_BENCH_PYTORCH_ROUNDS=1 $B/train_step --bench
    for tile in 64v 128v; do
        step "the wgpu step, all 9 kinds, tiles $tile"
        run 50 "step_ours_$tile.log" env NEURAL_BRDF_GPU_TILE=$tile BRDF_BENCH_QUICK=1 \
            BRDF_BENCH_ALL_MODELS=1 BRDF_BENCH_BACKENDS=wgpu BRDF_BENCH_RATES=1 \
            $B/train_step --bench
    done
    export PROFILE_WARMUP_STEPS=50 PROFILE_EVAL=none
    run 30 default_scenes.log $B/profile_steps --prepare default /tmp/default
    nvidia-smi dmon -s u -d 1 -o T >"$LOGS/gpu_use.log" 2>&1 &
    DMON=$!
    run 60 loop.log $B/profile_steps /tmp/default spot__blue-acrylic 1400 wgpu SingleMlp,Fmbrdf
    kill $DMON
    for kind in single_mlp fmbrdf; do
        step "kernel profile of one $kind step at 2^15 (benches/kernel_profile.py)"
        printf '[profiling.logger]\nlevel = "basic"\nfile = "/tmp/profile_%s.log"\n' "$kind" >cubecl.toml
        run 40 "step_profiled_$kind.log" env BRDF_BENCH_QUICK=1 BRDF_BENCH_ALL_MODELS=1 \
            BRDF_BENCH_MODELS=$kind BRDF_BENCH_BACKENDS=wgpu BRDF_BENCH_RATES=0 $B/train_step --bench
        rm -f cubecl.toml
        python3 benches/kernel_profile.py "/tmp/profile_$kind.log" --steps 8 |
            tee "$LOGS/kernel_profile_$kind.txt"
    done
fi
if [ "$STAGE" = cuda ]; then
    # CubeCL's CUDA runtime instead of wgpu: its kernels compiled by NVRTC (the image's CUDA
    # toolkit, else the nvidia-cuda-nvrtc wheel PyTorch brings), the same gpu-kernels, burn's
    # fusion on CUDA; and the bf16 products on tensor cores (gpu_kernels::gemm_cmma,
    # matmul_precision = "bf16"). Correctness first (gpu-kernels' tests against the f64
    # reference, f32 on every tiling and bf16; every kind against the CPU), then one layer's
    # products at 2^15 rows on every variant, every kind's step at 2^15 on cuda in f32 and bf16
    # back to back with PyTorch eager f32 and bf16 autocast (one round), the wgpu step for the
    # comparison of runtimes, and the default run's Single MLP and FMBRDF loop on cuda in f32
    # and bf16 with `nvidia-smi dmon`. One call: DEVICE_DEADLINE=500 bash benches/device_gpu.sh cuda
    export PYTHONPATH=$PWD/crates/py-neural-brdfs/python${PYTHONPATH:+:$PYTHONPATH}
    export NEURAL_BRDF_GPU_CACHE=/tmp/gpu-cache NEURAL_BRDF_GPU_LINEAR=ours
    python3 -c "import torch; print('torch', torch.__version__, torch.cuda.get_device_name(0))"
    step "NVRTC for CubeCL's CUDA runtime"
    nvrtc_dirs=$(python3 - <<'PY'
import glob, os, site
dirs = ["/usr/local/cuda/lib64", "/usr/local/cuda/targets/x86_64-linux/lib"]
for root in site.getsitepackages():
    dirs += glob.glob(os.path.join(root, "nvidia", "*", "lib"))
print(":".join(d for d in dirs if glob.glob(os.path.join(d, "libnvrtc.so*"))))
PY
)
    # NVRTC also needs the toolkit's headers (cubecl-cuda passes $CUDA_PATH/include).
    if [ -z "${CUDA_PATH:-}" ]; then
        if [ -d /usr/local/cuda/include ]; then
            export CUDA_PATH=/usr/local/cuda
        elif command -v nvcc >/dev/null; then
            CUDA_PATH=$(dirname "$(dirname "$(readlink -f "$(command -v nvcc)")")")
            export CUDA_PATH
        fi
    fi
    echo "CUDA_PATH=${CUDA_PATH:-unset}"
    ls "${CUDA_PATH:-/nonexistent}/include/cuda_bf16.h"
    for d in "${CUDA_PATH:-/nonexistent}/lib64" "${CUDA_PATH:-/nonexistent}/lib"; do
        ls "$d"/libnvrtc.so* >/dev/null 2>&1 && nvrtc_dirs=$d${nvrtc_dirs:+:$nvrtc_dirs}
    done
    echo "libnvrtc in: ${nvrtc_dirs:-nowhere}"
    export LD_LIBRARY_PATH=${nvrtc_dirs}${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
    step "gpu-kernels on CUDA against the f64 reference: f32 on every tiling, bf16 on tensor cores"
    run 90 kernels_cuda.log env GPU_KERNELS_RUNTIME=cuda $B/kernels --test-threads=1 --nocapture
    step "CUDA against the CPU on this GPU, every kind's values and gradients"
    run 60 gpu_backend_cuda.log env BRDF_GPU_BACKEND=cuda $B/gpu_backend --test-threads=1
    step "one layer's products at 2^15 rows on CUDA: 64, 64 checked, 128, 64v, 128v, bf16"
    run 50 layer_cuda.log env GPU_KERNELS_RUNTIME=cuda GPU_KERNELS_BENCH_ROWS=32768 $B/layer \
        --bench --warm-up-time 1 --measurement-time 1
    step "the cuda step, all 9 kinds, f32 and bf16, against PyTorch eager f32 and bf16 autocast"
    run 150 step_cuda.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_ALL_MODELS=1 \
        BRDF_BENCH_BACKENDS=cuda BRDF_BENCH_PRECISION=f32,bf16 BRDF_BENCH_RATES=0 \
        BRDF_BENCH_PYTORCH=python3 BRDF_BENCH_PYTORCH_ROUNDS=1 $B/train_step --bench
    step "the wgpu step, all 9 kinds (the runtimes side by side)"
    run 60 step_wgpu.log env BRDF_BENCH_QUICK=1 BRDF_BENCH_ALL_MODELS=1 \
        BRDF_BENCH_BACKENDS=wgpu BRDF_BENCH_RATES=0 $B/train_step --bench
    export PROFILE_WARMUP_STEPS=50 PROFILE_EVAL=none
    run 30 default_scenes.log $B/profile_steps --prepare default /tmp/default
    nvidia-smi dmon -s u -d 1 -o T >"$LOGS/gpu_use.log" 2>&1 &
    DMON=$!
    for precision in f32 bf16; do
        echo "== $(date +%T) $precision" >>"$LOGS/gpu_use.log"
        run 50 "loop_cuda_$precision.log" env PROFILE_PRECISION=$precision $B/profile_steps \
            /tmp/default spot__blue-acrylic 1400 cuda SingleMlp,Fmbrdf
    done
    kill $DMON
fi
step "done"
tar -czf "$OUT/$STAGE.tar.gz" -C "$LOGS" .
