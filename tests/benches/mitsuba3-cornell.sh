#!/usr/bin/env bash
# foton's path tracer beside Mitsuba 3's LLVM variant on the issue's scene: the Cornell box of
# scenes/cornell_point.toml (docs/cornell_point-mitsuba3.xml for Mitsuba), 256x256, 64 spp,
# max_depth 16 (Mitsuba's 17), 2 threads. Prints the CPU seconds of ROUNDS interleaved rounds
# (foton sobol, foton independent, Mitsuba independent) and their medians, then the RMSE at
# equal spp and at foton's time against a foton `path` reference of 4096 spp.
#
#   python -m venv /tmp/mi && /tmp/mi/bin/pip install mitsuba==3.9.1 numpy
#   export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so   # libLLVM 19 (apt: libllvm19); Dr.Jit refuses 14, and 15 fails
#   cargo build --release && MI_PYTHON=/tmp/mi/bin/python tests/benches/mitsuba3-cornell.sh
#
# ROUNDS (default 7); OUT (default /tmp/foton-mitsuba3) keeps the images and the reference.
set -euo pipefail
FOTON=${FOTON:-target/release/foton}
MI=${MI_PYTHON:?set MI_PYTHON to a python with mitsuba 3.9.1 and numpy}
ROUNDS=${ROUNDS:-7}
OUT=${OUT:-/tmp/foton-mitsuba3}
HERE=$(dirname "$0")
mkdir -p "$OUT"
SCENE=scenes/cornell_point.toml
ARGS=(--threads 2 --set render.max_depth=16)

median() { sort -n | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }

: >"$OUT/sobol" ; : >"$OUT/independent" ; : >"$OUT/mitsuba"
for r in $(seq "$ROUNDS"); do
    "$HERE/cpu-seconds.sh" $SCENE 64 "${ARGS[@]}" --set render.sampler='"sobol"' >>"$OUT/sobol"
    "$HERE/cpu-seconds.sh" $SCENE 64 "${ARGS[@]}" --set render.sampler='"independent"' >>"$OUT/independent"
    "$MI" "$HERE/mitsuba3_cornell.py" time 64 independent 1 >>"$OUT/mitsuba"
    echo "round $r: foton sobol $(tail -1 "$OUT/sobol") s, independent $(tail -1 "$OUT/independent") s, Mitsuba $(tail -1 "$OUT/mitsuba") s"
done
s=$(median <"$OUT/sobol"); i=$(median <"$OUT/independent"); m=$(median <"$OUT/mitsuba")
echo "medians: foton sobol $s s ($(awk -v a="$s" -v b="$m" 'BEGIN{printf "%.2f", a/b}')x), independent $i s ($(awk -v a="$i" -v b="$m" 'BEGIN{printf "%.2f", a/b}')x), Mitsuba LLVM $m s"

# Error: a foton reference (independent, 4096 spp, seed 12345; about 80 s on 2 cores), made once.
[ -f "$OUT/ref-4096.exr" ] || "$FOTON" render $SCENE "${ARGS[@]}" --spp 4096 --seed 12345 \
    --set render.sampler='"independent"' -o "$OUT/ref-4096.exr" >/dev/null
at_foton=$(awk -v s="$s" -v m="$m" 'BEGIN { printf "%d", 64 * s / m + 0.5 }')
for seed in 1 2; do
    for sampler in sobol stratified independent; do
        "$FOTON" render $SCENE "${ARGS[@]}" --spp 64 --seed $seed --set render.sampler="\"$sampler\"" \
            -o "$OUT/foton-$sampler-$seed.exr" >/dev/null
    done
    for sampler in independent stratified multijitter ldsampler; do
        "$MI" "$HERE/mitsuba3_cornell.py" time 64 $sampler $seed "$OUT/mi-$sampler-64-$seed.exr" >/dev/null
    done
    # At foton's time; Mitsuba rounds orthogonal's count up (to 121 for 68).
    for sampler in independent orthogonal; do
        "$MI" "$HERE/mitsuba3_cornell.py" time "$at_foton" $sampler $seed "$OUT/mi-$sampler-$at_foton-$seed.exr" >/dev/null
    done
done
echo "Mitsuba at foton's sobol time: $at_foton spp"
"$MI" "$HERE/mitsuba3_cornell.py" rmse "$OUT/ref-4096.exr" "$OUT"/foton-*.exr "$OUT"/mi-*.exr
