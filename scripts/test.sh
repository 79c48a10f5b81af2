#!/usr/bin/env bash
# Every test of the repository: a check that the power function's tables are their
# generator's, the Rust workspace, then the Python package built from the same crates
# (installed into a fresh virtual environment with the README's pip command).
# Needs Rust and a CPython >= 3.9 with venv; PyPI and crates.io must be reachable.
#
#   bash scripts/test.sh
#
# PYTHON picks the interpreter (default python3); the environment is made anew in
# .venv-test/ at the repository's top (ignored by git) on every run.
set -euo pipefail
cd "$(dirname "$0")/.."

# A one-off build gains nothing from incremental state, which would add 0.7 GB to the
# target folder (1.1 GB in all without it).
export CARGO_INCREMENTAL=0

echo "== the power function's tables are the generator's"
"${PYTHON:-python3}" scripts/gen-pow-tables.py | diff - crates/core/src/model/pow_tables.rs

echo "== cargo test --workspace"
cargo test --workspace

echo "== Python package"
venv=.venv-test
rm -rf "$venv"
"${PYTHON:-python3}" -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet maturin numpy pytest
"$venv/bin/python" -m pip install ./crates/python
"$venv/bin/python" -m pytest -q crates/python/tests
