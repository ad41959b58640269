#!/usr/bin/env bash
# CPU seconds (user + system) of one foton render, less those of the same render at 1 spp
# (loading the scene and writing the image), as docs/PERFORMANCE.md compares renderers on a
# shared machine: CPU time moves far less with the load than wall time.
#
#   tests/benches/cpu-seconds.sh SCENE SPP [foton render options...]
#   tests/benches/cpu-seconds.sh scenes/cornell_point.toml 64 --threads 2 --set render.max_depth=16
set -euo pipefail
FOTON=${FOTON:-target/release/foton}
SCENE=$1 SPP=$2
shift 2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

cpu() {
    local spp=$1
    shift
    /usr/bin/time -f "%U %S" -o "$tmp/time" \
        "$FOTON" render "$SCENE" --spp "$spp" "$@" -o "$tmp/out.exr" >/dev/null
    awk '{ print $1 + $2 }' "$tmp/time"
}

full=$(cpu "$SPP" "$@")
base=$(cpu 1 "$@")
awk -v f="$full" -v b="$base" 'BEGIN { printf "%.2f\n", f - b }'
