#!/usr/bin/env bash
# Runs every test of splinecontact from a fresh machine: creates .venv with gmsh,
# meshio, pyyaml and vtk (PyPI; pyyaml is for tests/ccx/deck.py, vtk is VTK's own
# reader for tests/py/check_vtk.py) when any is missing, puts it first on PATH (tests
# call `gmsh` and python's meshio), installs CalculiX (Debian's calculix-ccx, for the
# side-by-side test of docs/scripts/ccx_compare.py) and headless ParaView (paraview,
# python3-paraview, xvfb, for tests/cli/paraview.rs) when they are missing and we are
# root (without root and ParaView it says loudly that it skips the ParaView test), then runs the Rust unit and integration tests in release
# mode. Then the PETSc backend: installs PETSc and Open MPI (Debian's
# libpetsc-real-dev, openmpi-bin) when they are missing and we are root, builds with
# --features petsc (in target/petsc, beside the default build) and runs its tests,
# the two-rank mpirun one included. Without PETSc and without root it says loudly
# that it skips them (CI runs as root, so there they always run).
set -euo pipefail
cd "$(dirname "$0")"
if ! .venv/bin/python -c "import meshio, gmsh, yaml, vtk" >/dev/null 2>&1; then
    echo "test.sh: creating .venv with gmsh, meshio, pyyaml and vtk" >&2
    python3 -m venv .venv
    .venv/bin/pip install --quiet --disable-pip-version-check gmsh meshio pyyaml vtk
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
# ParaView, headless (tests/cli/paraview.rs runs docs/scripts/render.py under xvfb-run)
if ! { command -v pvbatch && command -v xvfb-run; } >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "test.sh: installing ParaView and Xvfb (apt-get)" >&2
        apt-get update -qq >/dev/null
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends paraview python3-paraview xvfb xauth >/dev/null
    else
        echo "test.sh: SKIPPING the ParaView test: pvbatch or xvfb-run is missing and we are not root (sudo apt-get install --no-install-recommends paraview python3-paraview xvfb xauth)" >&2
        export SC_SKIP_PARAVIEW=1
    fi
fi
export PATH="$PWD/.venv/bin:$PATH"
export SC_PYTHON="$PWD/.venv/bin/python"
cargo test --release --locked "$@"

have_petsc() { pkg-config --exists PETSc 2>/dev/null && command -v mpirun >/dev/null 2>&1; }
if ! have_petsc; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "test.sh: installing PETSc and Open MPI (apt-get) for the petsc feature's tests" >&2
        apt-get update -qq >/dev/null
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libpetsc-real-dev libopenblas0-serial libopenmpi-dev openmpi-bin pkg-config >/dev/null
    else
        echo "test.sh: SKIPPING the PETSc backend's tests: PETSc and MPI are missing and we are not root (sudo apt-get install libpetsc-real-dev libopenmpi-dev openmpi-bin pkg-config)" >&2
        exit 0
    fi
fi
# Open MPI refuses to run as root unless told (CI runs as root)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
CARGO_TARGET_DIR="$PWD/target/petsc" cargo test --release --locked --features petsc petsc
