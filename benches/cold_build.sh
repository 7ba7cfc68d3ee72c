#!/usr/bin/env bash
# Cold release build of `cargo xtask reproduce-tables` (that is `cargo build --release -p xtask`)
# at a commit, in a fresh worktree and an empty target folder: what a user's first
# `cargo xtask reproduce-tables` waits for before it starts. Run it for two commits back to back
# on an otherwise idle machine to compare them; the crates.io sources must be in the local cargo
# registry already (nothing is downloaded twice).
#
#   bash benches/cold_build.sh 99acee0 /tmp/cold-before
#   bash benches/cold_build.sh HEAD /tmp/cold-after
#
# Prints the wall time and the binary's path; the worktree stays for a later run of the binary
# (remove it with `git worktree remove --force DIR`).
set -euo pipefail
rev=$1
dir=$2
cd "$(dirname "$0")/.."
rm -rf "$dir"
git worktree prune
git worktree add --detach "$dir" "$rev" >/dev/null
cd "$dir"
start=$(date +%s.%N)
CARGO_TARGET_DIR="$dir/target" cargo build --release -p xtask --quiet
end=$(date +%s.%N)
printf 'cold release build of %s (%s): %.0f s -> %s\n' "$rev" "$(git rev-parse --short HEAD)" \
    "$(echo "$end - $start" | bc)" "$dir/target/release/xtask"
