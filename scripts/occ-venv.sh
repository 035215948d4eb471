#!/usr/bin/env bash
# Creates a Python virtual environment with OpenCASCADE's bindings (the cadquery-ocp-novtk
# wheel, about 65 MB), the independent CAD kernel that the B-rep tests check STEP files with
# (scripts/check_step.py). Idempotent: does nothing when the environment already imports OCP.
#
# Usage: scripts/occ-venv.sh [DIR]   (default: target/occ-venv)
set -euo pipefail
cd "$(dirname "$0")/.."
venv=${1:-target/occ-venv}
if "$venv/bin/python" -c "import OCP" >/dev/null 2>&1; then
  exit 0
fi
if ! python3 -m venv --help >/dev/null 2>&1; then
  echo "python3 with the venv module is needed (Debian: apt-get install python3-venv)" >&2
  exit 1
fi
rm -rf "$venv"
python3 -m venv "$venv"
"$venv/bin/pip" install --quiet --disable-pip-version-check "cadquery-ocp-novtk==8.0.1.1.0"
"$venv/bin/python" -c "import OCP"
