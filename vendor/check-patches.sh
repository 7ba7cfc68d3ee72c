#!/usr/bin/env bash
# Checks that a vendored crate is its published crates.io package plus the patch file kept for
# it, and nothing else: downloads (or takes from cargo's cache) the package, verifies its
# SHA-256 against the checksum crates.io publishes (Cargo.lock's, before the crate was
# patched), applies `patches/<name>-<version>.patch` with `git apply` and compares the trees.
# CI runs it (`.ci/run`). To change a patch: edit the vendored copy, then regenerate the file
# with `bash vendor/check-patches.sh --write`.
#
# Covered: every vendored crate (burn-flex, cubecl-cuda).
set -euo pipefail
cd "$(dirname "$0")"
write=${1:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

check() {
    local name=$1 version=$2 sha256=$3
    local crate="$tmp/$name-$version.crate" patch="patches/$name-$version.patch"
    local cached
    cached=$(ls "${CARGO_HOME:-$HOME/.cargo}"/registry/cache/*/"$name-$version.crate" 2>/dev/null |
        head -1 || true)
    if [ -n "$cached" ]; then
        cp "$cached" "$crate"
    else
        local url="https://static.crates.io/crates/$name/$name-$version.crate"
        if command -v curl >/dev/null; then
            curl -sSfL --retry 3 -o "$crate" "$url"
        else
            python3 -c 'import sys, urllib.request; urllib.request.urlretrieve(sys.argv[1], sys.argv[2])' \
                "$url" "$crate"
        fi
    fi
    echo "$sha256  $crate" | sha256sum --check --quiet
    local work="$tmp/$name"
    mkdir -p "$work/a"
    tar -xzf "$crate" -C "$work/a"
    if [ "$write" = --write ]; then
        mkdir -p "$work/pair"
        mv "$work/a/$name-$version" "$work/pair/a"
        cp -r "$name" "$work/pair/b"
        (cd "$work/pair" && diff -ruN a b >"$OLDPWD/$patch" || true)
        sed -i -E 's/^(---|\+\+\+) ([^\t]+)\t.*/\1 \2/' "$patch"
        echo "vendor: wrote $patch ($(wc -l <"$patch") lines)"
        return
    fi
    (cd "$work/a/$name-$version" && git apply -p1 "$OLDPWD/$patch")
    if ! diff -r "$work/a/$name-$version" "$name"; then
        echo "vendor: $name differs from $name $version plus $patch (above)" >&2
        return 1
    fi
    echo "vendor: $name is $name $version plus $patch ($(grep -c '^[-+][^-+]' "$patch") changed lines)"
}

# Aligned output buffers, element-wise work on both cores, strided unary and scalar ops (the
# linear layers' kernels live in crates/cpu-kernels, reached through a backend extension).
check burn-flex 0.22.1 7e05d08ef48d738fadf13f8689b634f8b396d5a8cbb27d0a87f61e163d241846
# Without its LLVM backend (`cubecl-llvm`, whose build script downloads an LLVM bundle from
# GitHub), so that `--features cuda` builds offline; kernels compile through NVRTC.
check cubecl-cuda 0.11.3 dacd0c047f781b468d094705ef042f28d68944bf862c049f5cf0b7396f730bb5
