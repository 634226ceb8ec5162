#!/usr/bin/env bash
# The Python package in CI: a virtual environment with pytest,
# NumPy, matplotlib and h5py; `pip install ./crates/cosserat-py` as the
# README says; the pytest suite (tests/, the quickstart example included).
# Builds into the workspace's target directory, so that after the
# workspace's own release builds only this crate is compiled.
set -euo pipefail
cd "$(dirname "$0")/../.."

VENV=target/python-ci
if ! python3 -c 'import venv, ensurepip' 2>/dev/null; then
  echo "== installing python3-venv and python3-dev"
  SUDO=""
  if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends python3-venv python3-dev python3-pip
fi
echo "== Python virtual environment ($VENV)"
python3 -m venv "$VENV"
"$VENV/bin/python" -m pip install -q --upgrade pip
"$VENV/bin/python" -m pip install -q pytest numpy matplotlib h5py

echo "== pip install ./crates/cosserat-py"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
"$VENV/bin/python" -m pip install -q ./crates/cosserat-py

echo "== pytest crates/cosserat-py/tests"
cd crates/cosserat-py
MPLBACKEND=Agg "../../$VENV/bin/python" -m pytest -q tests
