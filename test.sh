#!/usr/bin/env bash
# Runs every test of splinecontact from a fresh machine: creates .venv with gmsh,
# meshio and pyyaml (PyPI; pyyaml is for tests/ccx/deck.py) when any is missing, puts
# it first on PATH (tests call `gmsh` and python's meshio), then runs the Rust unit and
# integration tests in release mode.
set -euo pipefail
cd "$(dirname "$0")"
if ! .venv/bin/python -c "import meshio, gmsh, yaml" >/dev/null 2>&1; then
    echo "test.sh: creating .venv with gmsh, meshio and pyyaml" >&2
    python3 -m venv .venv
    .venv/bin/pip install --quiet --disable-pip-version-check gmsh meshio pyyaml
fi
export PATH="$PWD/.venv/bin:$PATH"
export SC_PYTHON="$PWD/.venv/bin/python"
cargo test --release --locked "$@"
