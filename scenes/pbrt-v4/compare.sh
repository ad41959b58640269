#!/usr/bin/env bash
# Renders every scene of this folder with pbrt-v4 and with foton, then compares them
# (means and 8x8 blocks): docs/pbrt.md, "Checked against pbrt-v4".
# Usage: scenes/pbrt-v4/compare.sh /path/to/pbrt [foton]
#   pbrt: a pbrt-v4 binary built from its public source (CPU); foton: target/release/foton.
#   compare.py needs Python with numpy and OpenEXR (pip install numpy OpenEXR).
set -euo pipefail
PBRT=${1:?usage: compare.sh /path/to/pbrt [foton]}
HERE=$(cd "$(dirname "$0")" && pwd)
FOTON=${2:-$HERE/../../target/release/foton}
OUT=$HERE/out
mkdir -p "$OUT/pbrt" "$OUT/foton"
cd "$HERE"
for scene in *.pbrt; do
  name=${scene%.pbrt}
  "$PBRT" --nthreads 2 --quiet --outfile "$OUT/pbrt/$name.exr" "$scene"
  case $name in
    # pbrt-v4's simplepath variants of coated-rough: foton renders coated-rough's scene
    # under the environment alone with its own path tracer.
    coated-rough-*-sampling) continue ;;
  esac
  "$FOTON" render "$scene" -o "$OUT/foton/$name.exr" --threads 2 -q
done
# The environment-only variants against foton's path on the same lighting.
sed '/LightSource "distant"/d' coated-rough.pbrt > "$OUT/coated-rough-env.pbrt"
cp *.png "$OUT/"
"$FOTON" render "$OUT/coated-rough-env.pbrt" -o "$OUT/foton/coated-rough-env.exr" --threads 2 -q --spp 2048
for scene in *.pbrt; do
  name=${scene%.pbrt}
  case $name in
    coated-rough-*-sampling) foton=coated-rough-env ;;
    *) foton=$name ;;
  esac
  printf '%-28s ' "$name"
  python3 "$HERE/compare.py" "$OUT/foton/$foton.exr" "$OUT/pbrt/$name.exr"
done
