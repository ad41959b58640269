#!/usr/bin/env bash
# Submits a sweep (foton sweep) to Slurm as one job per cell and an assemble: a job array of
# one task per cell of the grid (sweep-cell.sbatch) and a job (sweep-assemble.sbatch) that
# starts when every cell succeeded (afterok) and lays them out in the labelled grid. See
# docs/scale.md.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=submit-common.sh source-path=SCRIPTDIR
source "$here/submit-common.sh"

usage() {
    cat <<USAGE
usage: $(basename "$0") [OPTION]... SCENE OUTDIR -- --set KEY=V1,V2 [FOTON_SWEEP_OPTION]...

Renders each cell of \`foton sweep SCENE --set ...\` as one task of a Slurm job array into
OUTDIR/cells/cell-I.exr, then assembles the labelled grid into OUTDIR/sweep.png (or --output).
The options after -- are those of foton sweep (--set, --spp, --integrator, --seed, ...),
the same for every cell and the assemble job; --cell, --cells-dir, -o and --threads are set
here. foton must also run on this machine: it counts the cells.

  --foton PATH        the foton executable (env FOTON; default: foton on PATH)
  --plugin-dir DIR    also look for plugins in DIR (repeatable; FOTON_PLUGIN_PATH is passed on)
  --cpus C            CPUs and threads of each cell (env FOTON_CPUS; default 1)
  -o, --output FILE   the grid, .png or .exr (default OUTDIR/sweep.png)
  --max-running M     at most M cells rendering at once
  --sbatch ARG        an extra sbatch argument for every job (repeatable)

Prints the two job ids, "CELLS_JOB ASSEMBLE_JOB", on standard output; the jobs' logs go to
OUTDIR/logs/.
USAGE
}

parse_options "$@"
[[ ${#positional[@]} -eq 2 ]] || { usage >&2; exit 2; }
scene=$(absolute "${positional[0]}")
outdir=$(absolute "${positional[1]}")
[[ -f $scene ]] || die "scene $scene does not exist"
[[ ${#foton_args[@]} -gt 0 ]] || die "no sweep: give the --set KEY=V1,V2 options after --"
output=$(absolute "${output:-$outdir/sweep.png}")
resolve_foton
plugin_options
sweep_args=("${plugins[@]}" "${foton_args[@]}")

# The array's size is the number of cells, which only foton knows (the product of the value
# lists, as it splits them): ask it, and let it reject a bad sweep before anything is queued.
cells=$("$foton" sweep "$scene" "${sweep_args[@]}" --cells) || die "foton sweep --cells failed"
[[ $cells =~ ^[1-9][0-9]*$ ]] || die "foton sweep --cells printed '$cells', not a number of cells"

cells_dir=$outdir/cells
mkdir -p "$outdir/logs" "$cells_dir" "$(dirname "$output")"

array="0-$((cells - 1))${max_running:+%$max_running}"
cells_job=$(submit --array="$array" --cpus-per-task="$cpus" --chdir="$outdir" \
    --output="$outdir/logs/cell-%A_%a.out" \
    "$here/sweep-cell.sbatch" "$cells_dir" "$scene" "${sweep_args[@]}")
assemble_job=$(submit --dependency="afterok:$cells_job" --kill-on-invalid-dep=yes --chdir="$outdir" \
    --output="$outdir/logs/assemble-%j.out" \
    "$here/sweep-assemble.sbatch" "$cells_dir" "$output" "$scene" "${sweep_args[@]}")

echo "$(basename "$0"): $scene, $cells cells: job $cells_job (array $array), assemble job $assemble_job -> $output" >&2
echo "$cells_job $assemble_job"
