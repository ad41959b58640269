#!/usr/bin/env bash
# Build a CPU-only pbrt-v4 binary (reference "peer" renderer for foton comparisons).
#
# Usage: build.sh SOURCES OUT_DIR
#   SOURCES  either a directory of bare mirrors laid out as SOURCES/<owner>+<name>/repo
#            (the layout the search tool's `fetch` produces, e.g. /work/.mirror),
#            or a git URL prefix such that SOURCES/<owner>/<name>.git is clonable
#            (e.g. https://github.com).
#   OUT_DIR  work directory; source tree goes to OUT_DIR/src, build to OUT_DIR/build,
#            the binary ends up at OUT_DIR/build/pbrt.
# Environment:
#   PBRT_COMMIT   pbrt-v4 commit to build (default 5f7a606)
#   INSTALL_DEPS  1 = apt-get install the Debian build dependencies first (default 1 if root)
#   JOBS          make parallelism (default 2)
#   PBRT_NATIVE   ON/OFF: -march=native (pbrt's default ON)
set -euo pipefail

SOURCES=${1:?usage: build.sh SOURCES OUT_DIR}
OUT=${2:?usage: build.sh SOURCES OUT_DIR}
PBRT_COMMIT=${PBRT_COMMIT:-5f7a606}
JOBS=${JOBS:-2}
PBRT_NATIVE=${PBRT_NATIVE:-ON}
if [ "$(id -u)" = 0 ]; then INSTALL_DEPS=${INSTALL_DEPS:-1}; else INSTALL_DEPS=${INSTALL_DEPS:-0}; fi

# Fallbacks used only when a mirror lacks the commit pbrt-v4 pins for a submodule
# (path -> commit/tag). double-conversion: the pin before pbrt's 2025 cmake bump.
# zlib: last release in the mirror (the system zlib is used anyway, see below).
declare -A FALLBACK=( [double-conversion]=cc1f75a114aca8d2af69f73a5a959aecbab0e87a [zlib]=v1.3.1 )

START=$(date +%s)
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
SRC=$OUT/src/pbrt-v4
BUILD=$OUT/build
GITDIRS=$OUT/gitdirs   # only used when SOURCES is a URL prefix

if [ "$INSTALL_DEPS" = 1 ]; then
  apt-get update -qq
  # cmake/compilers; system zlib and OpenEXR (3.1.5 in Debian 12; pbrt needs >= 3.1.1
  # and then skips its bundled OpenEXR, whose mirror lacks the >4 MiB generated
  # src/lib/OpenEXRCore/dwaLookups.h); X11/GL headers for glfw/glad, which
  # pbrt-v4 always links (its CMakeLists has find_package(OpenGL REQUIRED)).
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
    build-essential cmake git pkg-config python3 zlib1g-dev libopenexr-dev \
    libgl-dev libx11-dev libxrandr-dev libxinerama-dev libxcursor-dev libxi-dev libxext-dev
fi

# gitdir_for OWNER/NAME -> path of a bare git dir holding that repository
gitdir_for() {
  local on=$1
  if [ -d "$SOURCES" ]; then
    local d="$SOURCES/${on/\//+}/repo"
    [ -d "$d" ] || { echo "missing mirror $d" >&2; return 1; }
    echo "$d"
  else
    local d="$GITDIRS/${on/\//+}.git"
    [ -d "$d" ] || git clone -q --bare "$SOURCES/$on.git" "$d"
    echo "$d"
  fi
}

# export_tree GITDIR COMMIT DEST: extract COMMIT into DEST, leaving out blobs the
# mirror does not have (snapshots lack files of 4 MiB and more); prints their paths.
export_tree() {
  local gd=$1 c=$2 dest=$3 missing
  local list; list=$(mktemp)
  git --git-dir="$gd" ls-tree -r "$c" | awk -F'\t' '{split($1,a," "); if (a[2]=="blob") print a[3] "\t" $2}' > "$list"
  missing=$(cut -f1 "$list" | git --git-dir="$gd" cat-file --batch-check | awk '$2=="missing"{print $1}' |
            awk -F'\t' 'NR==FNR{m[$1]=1; next} ($1 in m){print $2}' - "$list")
  rm -f "$list"
  local excl=()
  while IFS= read -r p; do [ -n "$p" ] && excl+=(":(exclude)$p"); done <<< "$missing"
  mkdir -p "$dest"
  git --git-dir="$gd" archive "$c" -- . "${excl[@]}" | tar -x -C "$dest"
  printf '%s' "$missing"
}

rm -rf "$OUT/src"
mkdir -p "$SRC"
PG=$(gitdir_for mmp/pbrt-v4)
PBRT_FULL=$(git --git-dir="$PG" rev-parse "$PBRT_COMMIT^{commit}")
MANIFEST=$OUT/src/COMMITS.txt
echo "pbrt-v4 mmp/pbrt-v4 $PBRT_FULL" > "$MANIFEST"
PMISS=$(export_tree "$PG" "$PBRT_FULL" "$SRC")
if [ -n "$PMISS" ]; then echo "  missing from mirror: $(echo $PMISS)" >> "$MANIFEST"; fi

# The two >4 MiB generated tables of pbrt-v4 are not in the mirror; write stand-ins.
for p in $PMISS; do
  case "$p" in
    src/pbrt/util/bluenoise.cpp|src/pbrt/util/pmj02tables.cpp) ;;
    *) echo "ERROR: $p missing from the pbrt-v4 mirror and no stand-in known" >&2; exit 1 ;;
  esac
done
python3 - "$SRC/src/pbrt/util" <<'PYGEN'
# Stand-ins written for this build (not pbrt's data):
#  bluenoise.cpp: 48 128x128 textures of WHITE noise (uniform uint16), used only by
#    the pmj02bn sampler's Cranley-Patterson shifts and 8-bit output dithering.
#  pmj02tables.cpp: 5 sets of 65536 points of the 2-D Sobol' (0,2)-sequence, each set
#    digitally shifted (XOR) by a random constant: a (0,16,2)-net in base 2, so the
#    pmj02bn sampler's per-pixel stratification checks hold, but it is NOT pmj02bn.
import os, random, sys
d = sys.argv[1]
rng = random.Random(20240601)
def write(path, head, decl, vals, fmt):
    if os.path.exists(path):
        return
    with open(path, 'w') as f:
        f.write(head + '\nnamespace pbrt {\n\n' + decl + ' = {\n')
        for i in range(0, len(vals), 12):
            f.write(', '.join(fmt % v for v in vals[i:i+12]) + ',\n')
        f.write('};\n\n}  // namespace pbrt\n')
note = '// STAND-IN generated by foton deploy/peers/pbrt-v4/build.sh (the original file was not available).\n'
bn = [rng.getrandbits(16) for _ in range(48 * 128 * 128)]
write(os.path.join(d, 'bluenoise.cpp'), note + '#include <pbrt/util/bluenoise.h>\n',
      'PBRT_CONST uint16_t BlueNoiseTextures[NumBlueNoiseTextures][BlueNoiseResolution][BlueNoiseResolution]',
      bn, '%d')
def rev32(x):
    return int('{:032b}'.format(x)[::-1], 2)
v = [1 << 31]
for _ in range(31):
    v.append(v[-1] ^ (v[-1] >> 1))
vals = []
for s in range(5):
    sx, sy = rng.getrandbits(32), rng.getrandbits(32)
    for i in range(65536):
        y, j, k = 0, 0, i
        while k:
            if k & 1:
                y ^= v[j]
            k >>= 1; j += 1
        vals += [rev32(i) ^ sx, y ^ sy]
write(os.path.join(d, 'pmj02tables.cpp'), note + '#include <pbrt/util/pmj02tables.h>\n',
      'PBRT_CONST uint32_t pmj02bnSamples[nPMJ02bnSets][nPMJ02bnSamples][2]', vals, '0x%08xu')
PYGEN

# Submodules: every gitlink under src/ext, repository taken from .gitmodules.
git --git-dir="$PG" ls-tree "$PBRT_FULL" src/ext/ | awk '$2=="commit"{print $3, $4}' |
while read -r pin path; do
  name=${path#src/ext/}
  url=$(git config -f "$SRC/.gitmodules" "submodule.$path.url")
  on=$(echo "$url" | sed -E 's#^.*github\.com[:/]##; s#\.git$##')
  gd=$(gitdir_for "$on")
  if git --git-dir="$gd" cat-file -e "$pin^{commit}" 2>/dev/null; then
    use=$pin; note=pinned
  else
    fb=${FALLBACK[$name]:-HEAD}
    use=$(git --git-dir="$gd" rev-parse "$fb^{commit}")
    note="FALLBACK (pinned $pin not in mirror; used $fb)"
    echo "WARNING: $name: $note" >&2
  fi
  miss=$(export_tree "$gd" "$use" "$SRC/$path")
  echo "$name $on $use $note" >> "$MANIFEST"
  if [ -n "$miss" ]; then echo "  missing from mirror (left out): $(echo $miss)" >> "$MANIFEST"; fi
done
cat "$MANIFEST"

# Configure. Notes:
#  - the tree has no .git, so pbrt's submodule-commit check (which needs git) is
#    skipped by hiding git from find_package; COMMITS.txt records what was used.
#  - CMAKE_CUDA_COMPILER= (defined, empty) skips CUDA detection: CPU-only build,
#    and PBRT_OPTIX7_PATH is left unset.
#  - glfw: X11 backend only (Wayland would need extra packages). The GUI cannot be
#    compiled out of pbrt-v4, it's just never opened unless --interactive is given.
#  - FETCHCONTENT_FULLY_DISCONNECTED: never download anything at configure time.
rm -rf "$BUILD"
mkdir -p "$BUILD"
cmake -S "$SRC" -B "$BUILD" \
  -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_DISABLE_FIND_PACKAGE_Git=ON \
  -DCMAKE_CUDA_COMPILER= \
  -DPBRT_BUILD_NATIVE_EXECUTABLE="$PBRT_NATIVE" \
  -DGLFW_BUILD_WAYLAND=OFF -DGLFW_BUILD_X11=ON \
  -DFETCHCONTENT_FULLY_DISCONNECTED=ON \
  -DBUILD_TESTING=OFF

if ! grep -q '^OpenEXR_DIR:PATH=/usr' "$BUILD/CMakeCache.txt"; then
  echo "ERROR: system OpenEXR not found (install libopenexr-dev); the bundled one cannot build from the mirror" >&2
  exit 1
fi

# Only the renderer (target pbrt_exe, output name "pbrt") and what it needs.
make -C "$BUILD" -j"$JOBS" pbrt_exe

test -x "$BUILD/pbrt"
END=$(date +%s)
echo "built $BUILD/pbrt in $(( (END-START)/60 )) min $(( (END-START)%60 )) s"
