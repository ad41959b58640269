#!/usr/bin/env bash
# Submits a frame to Slurm as N parts and a merge: a job array of N tasks (frame-part.sbatch),
# each rendering one share of the work, and a job (frame-merge.sbatch) that starts when every
# part succeeded (afterok) and merges them into one image. See docs/scale.md.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=submit-common.sh source-path=SCRIPTDIR
source "$here/submit-common.sh"

usage() {
    cat <<USAGE
usage: $(basename "$0") [OPTION]... SCENE N OUTDIR [-- FOTON_RENDER_OPTION...]

Renders SCENE as N parts (a Slurm job array, one task per part) into OUTDIR/part_I.exr, then
merges them into OUTDIR/frame.exr (or --output). SCENE, OUTDIR and foton must be on a
filesystem that every node mounts at the same path. Options after -- go to every
\`foton render\` (e.g. -- --spp 1024 --set film.width=1920); --part, -o and --threads are set
here.

  --foton PATH        the foton executable (env FOTON; default: foton on PATH)
  --plugin-dir DIR    also look for plugins in DIR (repeatable; FOTON_PLUGIN_PATH is passed on)
  --cpus C            CPUs and threads of each part (env FOTON_CPUS; default 1)
  -o, --output FILE   the merged image, .exr or .png (default OUTDIR/frame.exr)
  --max-running M     at most M parts running at once
  --sbatch ARG        an extra sbatch argument for every job (repeatable), e.g.
                      --sbatch=--partition=long --sbatch=--time=2:00:00

Prints the two job ids, "PARTS_JOB MERGE_JOB", on standard output; the jobs' logs go to
OUTDIR/logs/.
USAGE
}

parse_options "$@"
[[ ${#positional[@]} -eq 3 ]] || { usage >&2; exit 2; }
scene=$(absolute "${positional[0]}")
parts=${positional[1]}
outdir=$(absolute "${positional[2]}")
[[ -f $scene ]] || die "scene $scene does not exist"
[[ $parts =~ ^[1-9][0-9]*$ ]] || die "N must be a positive integer, not '$parts'"
output=$(absolute "${output:-$outdir/frame.exr}")
resolve_foton
plugin_options

# Slurm does not create the folders of --output files: a missing logs folder fails the job
# before it starts, with no log to say why.
mkdir -p "$outdir/logs" "$(dirname "$output")"

array="0-$((parts - 1))${max_running:+%$max_running}"
parts_job=$(submit --array="$array" --cpus-per-task="$cpus" --chdir="$outdir" \
    --output="$outdir/logs/part-%A_%a.out" \
    "$here/frame-part.sbatch" "$parts" "$outdir" "$scene" "${plugins[@]}" "${foton_args[@]}")
merge_job=$(submit --dependency="afterok:$parts_job" --kill-on-invalid-dep=yes --chdir="$outdir" \
    --output="$outdir/logs/merge-%j.out" \
    "$here/frame-merge.sbatch" "$parts" "$outdir" "$output")

echo "$(basename "$0"): $scene in $parts parts: job $parts_job (array $array), merge job $merge_job -> $output" >&2
echo "$parts_job $merge_job"
