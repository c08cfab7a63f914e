#!/usr/bin/env bash
# Runs every test of splinecontact from a fresh machine: creates .venv with gmsh,
# meshio and pyyaml (PyPI; pyyaml is for tests/ccx/deck.py) when any is missing, puts
# it first on PATH (tests call `gmsh` and python's meshio), installs CalculiX (Debian's
# calculix-ccx, for the side-by-side test of docs/scripts/ccx_compare.py) when it is
# missing and we are root, then runs the Rust unit and integration tests in release
# mode.
set -euo pipefail
cd "$(dirname "$0")"
if ! .venv/bin/python -c "import meshio, gmsh, yaml" >/dev/null 2>&1; then
    echo "test.sh: creating .venv with gmsh, meshio and pyyaml" >&2
    python3 -m venv .venv
    .venv/bin/pip install --quiet --disable-pip-version-check gmsh meshio pyyaml
fi
if ! command -v ccx >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "test.sh: installing calculix-ccx (apt-get)" >&2
        apt-get update -qq >/dev/null
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq calculix-ccx >/dev/null
    else
        echo "test.sh: ccx (CalculiX) is missing: install Debian's calculix-ccx (sudo apt-get install calculix-ccx)" >&2
        exit 1
    fi
fi
export PATH="$PWD/.venv/bin:$PATH"
export SC_PYTHON="$PWD/.venv/bin/python"
cargo test --release --locked "$@"
