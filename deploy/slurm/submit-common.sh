# shellcheck shell=bash
# Sourced by submit-frame.sh and submit-sweep.sh: the options they share and the sbatch call.
# The variables set here are read by those scripts, which shellcheck cannot see from this file.
# shellcheck disable=SC2034

# Defaults from the environment, so that a site can set them once in a profile.
foton=${FOTON:-}
plugin_dirs=()
cpus=${FOTON_CPUS:-1}
output=
max_running=
sbatch_args=()
positional=()
foton_args=()

die() {
    echo "$(basename "$0"): error: $*" >&2
    exit 2
}

# Parses the shared options into the variables above; positional arguments go to
# `positional`, everything after `--` to `foton_args`.
parse_options() {
    while [[ $# -gt 0 ]]; do
        case $1 in
        --foton) foton=${2:?--foton needs a path}; shift 2 ;;
        --foton=*) foton=${1#*=}; shift ;;
        --plugin-dir) plugin_dirs+=("${2:?--plugin-dir needs a folder}"); shift 2 ;;
        --plugin-dir=*) plugin_dirs+=("${1#*=}"); shift ;;
        --cpus) cpus=${2:?--cpus needs a number}; shift 2 ;;
        --cpus=*) cpus=${1#*=}; shift ;;
        -o | --output) output=${2:?--output needs a file}; shift 2 ;;
        --output=*) output=${1#*=}; shift ;;
        --max-running) max_running=${2:?--max-running needs a number}; shift 2 ;;
        --max-running=*) max_running=${1#*=}; shift ;;
        --sbatch) sbatch_args+=("${2:?--sbatch needs an argument}"); shift 2 ;;
        --sbatch=*) sbatch_args+=("${1#*=}"); shift ;;
        -h | --help) usage; exit 0 ;;
        --) shift; foton_args+=("$@"); break ;;
        -*) die "unknown option $1 (see --help)" ;;
        *) positional+=("$1"); shift ;;
        esac
    done
    [[ $cpus =~ ^[1-9][0-9]*$ ]] || die "--cpus must be a positive integer, not '$cpus'"
    [[ -z $max_running || $max_running =~ ^[1-9][0-9]*$ ]] ||
        die "--max-running must be a positive integer, not '$max_running'"
}

# The jobs run on other machines, in other folders: every path they get must be absolute
# (and on the shared filesystem).
absolute() {
    realpath -m -- "$1"
}

# Resolves the foton executable to the absolute path the jobs will run and exports it (the
# jobs get the submitter's environment, --export=ALL).
resolve_foton() {
    local found
    if [[ -z $foton ]]; then
        found=$(command -v foton) || die "no foton on PATH: give --foton PATH or set FOTON"
        foton=$found
    elif [[ $foton != */* ]]; then
        found=$(command -v "$foton") || die "$foton is not on PATH"
        foton=$found
    fi
    foton=$(absolute "$foton")
    [[ -x $foton ]] || die "$foton is not an executable file"
    export FOTON=$foton
}

# The --plugin-dir options for foton, absolute, into `plugins`.
plugin_options() {
    local d
    plugins=()
    for d in "${plugin_dirs[@]}"; do
        [[ -d $d ]] || die "plugin folder $d does not exist"
        plugins+=(--plugin-dir "$(absolute "$d")")
    done
}

# sbatch ARGS...: submits and prints the job id (sbatch --parsable prints ID or ID;CLUSTER).
submit() {
    local id
    id=$(sbatch --parsable --export=ALL "${sbatch_args[@]}" "$@") || die "sbatch failed"
    echo "${id%%;*}"
}
