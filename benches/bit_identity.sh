#!/usr/bin/env bash
# Trains benches/profiles/bit_identity.toml (all nine kinds, 40 steps at batch 8,192) in f32, in
# bf16 and, where the CPU has AVX512-FP16 (f16 is emulated, far too slowly, elsewhere), in f16
# with the given xtask binary and prints one SHA-256 per run of its weights
# (model.safetensors) and its training log (losses), sorted: two builds train bit-identically
# when their outputs are equal. Usage:
#   bash benches/bit_identity.sh target/release/xtask out/bits-before > before.txt
#   ... rebuild ...
#   bash benches/bit_identity.sh target/release/xtask out/bits-after > after.txt
#   diff before.txt after.txt
set -euo pipefail
exe=${1:?xtask binary}
out=${2:?output folder}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
precisions="f32 bf16"
if grep -qw avx512_fp16 /proc/cpuinfo 2>/dev/null; then
    precisions="$precisions f16"
fi
for precision in $precisions; do
    profile="$out/bit_identity_$precision.toml"
    sed "s/^matmul_precision = .*/matmul_precision = \"$precision\"/" \
        "$here/profiles/bit_identity.toml" >"$profile"
    "$exe" reproduce-tables --profile "$profile" --out "$out/$precision" --jobs 1 >/dev/null 2>&1
    for run in "$out/$precision"/runs/*/; do
        kind=$(sed -n 's/^kind = "\(.*\)"/\1/p' "$run/config.toml" | head -1)
        w=$(sha256sum "$run/model.safetensors" | cut -c1-16)
        log="$run/curve.csv"
        l=$(cut -d, -f1-4 "$log" | sha256sum | cut -c1-16)
        echo "$precision $kind weights $w losses $l"
    done
done | sort
