#!/usr/bin/env bash
# Builds what `benches/device_gpu.sh` runs on a lent GPU machine and puts it in `.devrun/` (and
# the Vulkan loader's packages in `.gl/`), both ignored through .git/info/exclude. Run from the
# checkout's root on the development machine; then carry `.devrun` and `.gl` with the call.
# The binaries hold both GPU runtimes, wgpu (Vulkan) and CubeCL's CUDA (NVRTC; the `cuda` stage).
# `DEVICE_FEATURES=sweep/wgpu DEVICE_BIN=.devrun_old bash benches/device_gpu_prepare.sh` builds
# the same binaries with other features into another folder (carried as `.devrun_old` is, for a
# comparison of two builds).
set -euo pipefail
R=${DEVICE_BIN:-.devrun}
FEATURES=${DEVICE_FEATURES:-sweep/wgpu,sweep/cuda}
grep -qx "/$R/" .git/info/exclude || echo "/$R/" >>.git/info/exclude
grep -qx '/.gl/' .git/info/exclude || echo /.gl/ >>.git/info/exclude
if [ ! -d .gl ]; then
    mkdir -p .gl /tmp/amd64/partial
    o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
    # shellcheck disable=SC2086
    apt-get $o update >/dev/null
    # shellcheck disable=SC2086
    (cd .gl && apt-get $o download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
fi

# The example, the bench and the test in one build, one feature set (their dev-dependencies
# join it; the bench profile is the release profile); the example also makes the scenes there
# (`--prepare`), so no xtask travels.
cargo build --release -p sweep -p brdf-neural --features "$FEATURES" \
    --example profile_steps --bench train_step --test gpu_backend
# One layer's products on gpu-kernels, unchecked and checked (the `checks` stage), and the
# kernels' tests (the `cuda` stage: f32 and bf16 against an f64 reference on CUDA).
cargo build --release -p gpu-kernels --features wgpu,cuda --bench layer --test kernels
# The weight-gradient products alone (the `cpu` stage), without wgpu.
cargo build --release -p cpu-kernels --bench weight_gradient

newest() { find target/release/deps -maxdepth 1 -type f -executable -name "$1-*" -printf '%T@ %p\n' | sort -n | tail -1 | cut -d' ' -f2; }
rm -rf $R && mkdir -p $R/bin
cp target/release/examples/profile_steps $R/bin/
cp "$(newest train_step)" $R/bin/train_step
cp "$(newest gpu_backend)" $R/bin/gpu_backend
cp "$(newest weight_gradient)" $R/bin/weight_gradient
cp "$(newest layer)" $R/bin/layer
cp "$(newest kernels)" $R/bin/kernels
strip $R/bin/*
tar -cJf $R/bin.tar.xz -C $R bin
rm -rf $R/bin
du -sh $R .gl
