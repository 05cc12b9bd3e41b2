#!/usr/bin/env bash
# Every test: the Rust workspace (cargo test), the API docs (cargo doc, a warning fails), a smoke
# run of every fuzz target, then the Python package built from crates/biotet-py into a virtual
# environment under target/ and its pytest suite (which compares with the CLI binary cargo test
# just built).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --workspace --locked
# The API docs build without a warning (a broken or private link fails here).
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --locked
# Every fuzz target for a few seconds (libFuzzer on stable; seeds, then mutations): a smoke run,
# the long runs are scripts/fuzz.sh's. BIOTET_FUZZ_SECONDS=0 skips it.
if [ "${BIOTET_FUZZ_SECONDS:-3}" != 0 ]; then
  scripts/fuzz.sh run "${BIOTET_FUZZ_SECONDS:-3}"
fi
# The CLI the Python tests compare with is cargo's, wherever CARGO_TARGET_DIR puts it.
target_dir=$(realpath -m "${CARGO_TARGET_DIR:-target}")
venv="$target_dir/pyenv"
if [ ! -x "$venv/bin/python" ]; then
  "${PYTHON:-python3}" -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q ./crates/biotet-py pytest meshio pyvista "dask[distributed]"
BIOTET_CLI="$target_dir/debug/biotet" "$venv/bin/python" -m pytest -q crates/biotet-py/tests
