#!/usr/bin/env bash
# The phase profile (`foton bench --json`) of every integrator on the workloads of the scaling
# table in docs/PERFORMANCE.md: each loaded and rendered on one thread and on all, and a table
# of wall seconds, speed-up, the serial fraction, Amdahl's predictions and peak memory. The
# JSON files stay in the folder given (default: a temporary one, removed).
#
#   tests/benches/profiles.sh [--threads N] [OUT_DIR]
set -euo pipefail
FOTON=${FOTON:-target/release/foton}
THREADS=()
if [[ ${1:-} == --threads ]]; then
    THREADS=(--threads "$2")
    shift 2
fi
OUT=${1:-}
if [[ -z $OUT ]]; then
    OUT=$(mktemp -d)
    trap 'rm -rf "$OUT"' EXIT
fi
mkdir -p "$OUT"

# name | scene | options
ROWS=(
    "path|scenes/cornell-box.toml|--integrator path --spp 128"
    "bdpt|scenes/bitterli/veach-bidir/scene_v0.6_bdpt.xml|--integrator bdpt --spp 8 --set film.width=256 --set film.height=256"
    "photon|scenes/caustics.toml|--integrator photon --spp 16"
    "vpm|scenes/fog_box.toml|--integrator vpm --set film.width=128 --set film.height=128"
    "sppm|scenes/caustics.toml|--integrator sppm"
    "vcm|scenes/caustics.toml|--integrator vcm --set integrators.vcm.iterations=16"
    "ppb|scenes/bitterli/volumetric-caustic/scene_v0.6.xml|--integrator ppb --set film.width=128 --set film.height=128"
)

printf '| integrator | 1 thread s | all threads s | speed-up | serial fraction | Amdahl 16 | Amdahl 64 | peak RSS MB |\n'
printf '|---|---|---|---|---|---|---|---|\n'
for row in "${ROWS[@]}"; do
    IFS='|' read -r name scene opts <<<"$row"
    # shellcheck disable=SC2086
    "$FOTON" bench "$scene" $opts "${THREADS[@]}" --json "$OUT/$name.json" >/dev/null 2>&1
    python3 - "$OUT/$name.json" "$name" <<'PY'
import json, sys
p = json.load(open(sys.argv[1]))
t1, tn = p["total"]["wall_1"], p["total"]["wall_all"]
f = p["serial_fraction"]
fmt = lambda x: "-" if x is None else f"{x:.3f}"
print(f"| {sys.argv[2]} | {t1:.2f} | {tn:.2f} | {t1 / tn:.2f}x | {fmt(f)} | "
      f"{fmt(p['predicted_speedup_16'])} | {fmt(p['predicted_speedup_64'])} | "
      f"{p['peak_rss_bytes'] / 1e6:.0f} |")
PY
done
