#!/bin/sh
# The pytest example as ctest runs it: its tests with --l6470emu-coverage (the program run under
# the preload and the driver class on an in-process Board both merge into FILE), then the report
# of the interface coverage they met (docs/guide/python.md shows the tests).
# Usage: run_with_coverage.sh PYTHON L6470EMU FILE [PYTEST ARGS...]
set -e
python=$1 program=$2 file=$3
shift 3
rm -f "$file"  # coverage is merged into the file: start from none
"$python" -m pytest -q -p no:cacheprovider --l6470emu-coverage="$file" "$(dirname "$0")" "$@"
"$program" coverage report "$file"
