#!/bin/sh
# Runs the plot tests when PYTHON has matplotlib; otherwise says why and exits 77, which
# ctest reports as skipped (SKIP_RETURN_CODE), never as passed. Usage: run_if_matplotlib.sh PYTHON ARGS...
python=$1
shift
if ! "$python" -c 'import matplotlib' 2>/dev/null; then
  echo "SKIP: $python has no matplotlib (Debian: apt install python3-matplotlib; scripts/setup.sh installs it)"
  exit 77
fi
exec "$python" "$@"
