#!/usr/bin/env bash
# Instructions per sample per pixel of a render, loading and start-up left out: callgrind on
# `foton bench` with one thread at 4 spp and at 1 spp, (I(4) - I(1)) / 3. Instruction counts do
# not depend on the machine's load, which is why docs/PERFORMANCE.md compares builds by them.
#
#   tests/benches/instructions.sh [SCENE] [foton bench options...]
#   tests/benches/instructions.sh scenes/cornell_point.toml --set render.sampler='"independent"'
#
# SCENE defaults to scenes/cornell_point.toml; FOTON to target/release/foton (build it with
# `cargo build --release`). Needs valgrind.
set -euo pipefail
FOTON=${FOTON:-target/release/foton}
SCENE=${1:-scenes/cornell_point.toml}
[ $# -gt 0 ] && shift
extra=("$@")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

count() {
    valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.$1" \
        "$FOTON" bench "$SCENE" --threads 1 --repeat 1 --spp "$1" "${extra[@]}" \
        >/dev/null 2>"$tmp/log.$1"
    sed -n 's/.*Collected : \([0-9]*\).*/\1/p' "$tmp/log.$1"
}

i4=$(count 4)
i1=$(count 1)
echo "$SCENE ${extra[*]}: $(( (i4 - i1) / 3 )) instructions per spp (4 spp: $i4, 1 spp: $i1)"
