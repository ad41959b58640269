#!/usr/bin/env bash
# The foton image's entrypoint. Kubernetes Indexed Jobs give each pod its index in
# JOB_COMPLETION_INDEX; this maps it to the share of work the pod renders:
#
#   part N OUTDIR SCENE [foton render option]...
#       foton render SCENE --part I/N -o OUTDIR/part_I.exr [option]...   (I = JOB_COMPLETION_INDEX)
#   merge-parts N OUTDIR OUTPUT
#       foton merge OUTDIR/part_0.exr ... OUTDIR/part_(N-1).exr -o OUTPUT
#   cell CELLSDIR SCENE [foton sweep option]...
#       foton sweep SCENE [option]... --cell I --cells-dir CELLSDIR      (I = JOB_COMPLETION_INDEX)
#   anything else
#       foton ARGS... (e.g. sweep SCENE --set ... --assemble --cells-dir DIR -o grid.png, plugins)
#
# FOTON names the executable (default: foton on PATH, /opt/foton/foton in the image, with its
# plugins beside it). FOTON_THREADS, if set, is passed as --threads; otherwise foton uses the
# CPUs the container may use.
set -euo pipefail

foton=${FOTON:-foton}

die() {
    echo "foton-entrypoint: error: $*" >&2
    exit 2
}

# The pod's index, checked against the number of shares: a pod that is not part of an Indexed
# Job must not render share 0 (every pod would render the same share and the merge would
# refuse the duplicates only at the end).
index() {
    local count=$1 what=$2
    [[ -n ${JOB_COMPLETION_INDEX:-} ]] ||
        die "JOB_COMPLETION_INDEX is not set: run '$what' as a pod of an Indexed Job (completionMode: Indexed), which sets it to the pod's index"
    [[ $JOB_COMPLETION_INDEX =~ ^(0|[1-9][0-9]*)$ ]] ||
        die "JOB_COMPLETION_INDEX is '$JOB_COMPLETION_INDEX', not an index 0, 1, 2, ..."
    if [[ -n $count ]] && ((JOB_COMPLETION_INDEX >= count)); then
        die "JOB_COMPLETION_INDEX $JOB_COMPLETION_INDEX is outside the $count shares: the Job's completions must be $count"
    fi
    echo "$JOB_COMPLETION_INDEX"
}

count() {
    [[ $1 =~ ^[1-9][0-9]*$ ]] || die "N must be a positive integer, not '$1'"
    echo "$1"
}

threads=()
if [[ -n ${FOTON_THREADS:-} ]]; then
    threads=(--threads "$FOTON_THREADS")
fi

case ${1:-} in
part)
    [[ $# -ge 4 ]] || die "usage: part N OUTDIR SCENE [foton render option]..."
    parts=$(count "$2")
    outdir=$3 scene=$4
    shift 4
    i=$(index "$parts" part)
    mkdir -p "$outdir"
    exec "$foton" render "$scene" --part "$i/$parts" -o "$outdir/part_$i.exr" "${threads[@]}" "$@"
    ;;
merge-parts)
    [[ $# -eq 4 ]] || die "usage: merge-parts N OUTDIR OUTPUT"
    parts=$(count "$2")
    outdir=$3 output=$4
    # Every part by name, not a glob: a missing part is then an error of foton merge's, and a
    # part left over from another run is not picked up.
    files=()
    for ((i = 0; i < parts; i++)); do
        files+=("$outdir/part_$i.exr")
    done
    exec "$foton" merge "${files[@]}" -o "$output"
    ;;
cell)
    [[ $# -ge 3 ]] || die "usage: cell CELLSDIR SCENE [foton sweep option]..."
    cells_dir=$2 scene=$3
    shift 3
    i=$(index "" cell)
    mkdir -p "$cells_dir"
    exec "$foton" sweep "$scene" "$@" --cell "$i" --cells-dir "$cells_dir" "${threads[@]}"
    ;;
"")
    exec "$foton" --help
    ;;
*)
    exec "$foton" "$@"
    ;;
esac
