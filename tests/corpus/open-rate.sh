#!/usr/bin/env bash
# Open rate of a folder of Mitsuba scene files with `foton check`, per Mitsuba version, and
# the histogram of what refused them. Usage and details: open_rate.py's top comment.
#   tests/corpus/open-rate.sh /work/corpus target/release/foton [--timeout 60] [--jobs 2] [--tsv out.tsv]
exec python3 "$(dirname "$0")/open_rate.py" "$@"
