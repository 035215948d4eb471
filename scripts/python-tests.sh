#!/usr/bin/env bash
# The Python package's tests (python/, issue 32): from a clone with ../shared beside it, makes a
# virtual environment in python/target/py-venv, installs maturin, numpy and pytest, builds and
# installs the package with `pip install ./python` (as a user would), builds the CLI if needed
# and runs pytest, which compares every function with the CLI's output on the same files.
# Everything the package builds goes to python/target (its own cargo project, not a member of
# the workspace). Called by .ci/run.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! python3 -m venv --help >/dev/null 2>&1; then
  sudo -n apt-get install -y python3-venv >/dev/null 2>&1 || apt-get install -y python3-venv
fi
venv=python/target/py-venv
if [ ! -x "$venv/bin/python" ]; then
  mkdir -p python/target
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet maturin numpy pytest "dask[distributed]" tqdm
# Builds the extension in release mode into python/target (the lock file python/Cargo.lock
# holds the library's dependencies at the workspace's versions).
"$venv/bin/python" -m pip install --quiet --force-reinstall --no-deps ./python

# The CLI the tests compare against, built from this checkout: the dev profile, which
# `cargo test --workspace` has built already in CI (a no-op then); it gives the same answers bit
# for bit as the release build. CREASE_BIN=path/to/crease to use another build.
if [ -z "${CREASE_BIN:-}" ]; then
  cargo build --quiet -p crease-cli
  export CREASE_BIN="$PWD/target/debug/crease"
fi
# From the tests' folder, so that the installed package is imported, not the source folder
# python/crease (which has no native module).
cd python/tests
exec "../../$venv/bin/python" -m pytest -q "$@"
