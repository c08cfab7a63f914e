#!/usr/bin/env bash
# Runs every test of splinecontact from a fresh machine. What the tests need is
# installed when it is missing, in the background while cargo builds:
# - .venv with gmsh, meshio, pyyaml and vtk (PyPI; pyyaml is for tests/ccx/deck.py,
#   vtk is VTK's own reader for tests/py/check_vtk.py), put first on PATH (tests call
#   `gmsh` and python's meshio);
# - when we are root: CalculiX (Debian's calculix-ccx, for the side-by-side test of
#   docs/scripts/ccx_compare.py, and GNU time, through which it reads each program's
#   peak RSS), headless ParaView (paraview, python3-paraview, xvfb,
#   for tests/cli/paraview.rs), PETSc and Open MPI (libpetsc-real-dev, openmpi-bin,
#   for the petsc feature). Without root, a missing CalculiX is an error; a missing
#   ParaView or PETSc skips their tests, and says so loudly (CI runs as root, so there
#   they always run).
# Then the Rust unit and integration tests in release mode, in ONE build: with
# --features petsc when PETSc and MPI are there (or being installed), so the PETSc
# backend's tests (the two-rank mpirun one included) run beside the others; the
# default build otherwise, or with SC_TEST_DEFAULT_BUILD=1 (it also runs the two
# tests of what a build without PETSc says). When PETSc is being installed, the
# heavy dependencies build meanwhile, and the crate waits for PETSc's headers.
set -euo pipefail
cd "$(dirname "$0")"

as_root() { [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; }
have_venv() { .venv/bin/python -c "import meshio, gmsh, yaml, vtk" >/dev/null 2>&1; }
have_paraview() { command -v pvbatch >/dev/null 2>&1 && command -v xvfb-run >/dev/null 2>&1; }
have_petsc() { pkg-config --exists PETSc 2>/dev/null && command -v mpirun >/dev/null 2>&1; }

# What to install (each apt-get line keeps its own flags: ParaView without its
# recommends, which pull in a desktop)
apt_lines=()
if ! command -v ccx >/dev/null 2>&1; then
    as_root || { echo "test.sh: ccx (CalculiX) is missing: install Debian's calculix-ccx (sudo apt-get install calculix-ccx)" >&2; exit 1; }
    apt_lines+=("calculix-ccx")
fi
if [ ! -x /usr/bin/time ] && as_root; then
    # GNU time: ccx_compare.py reads each program's own peak RSS through it
    apt_lines+=("time")
fi
if ! have_paraview; then
    if as_root; then
        apt_lines+=("--no-install-recommends paraview python3-paraview xvfb xauth")
    else
        echo "test.sh: SKIPPING the ParaView test: pvbatch or xvfb-run is missing and we are not root (sudo apt-get install --no-install-recommends paraview python3-paraview xvfb xauth)" >&2
        export SC_SKIP_PARAVIEW=1
    fi
fi
petsc=1
if [ "${SC_TEST_DEFAULT_BUILD:-0}" = 1 ]; then
    echo "test.sh: the default build (SC_TEST_DEFAULT_BUILD=1): the PETSc backend's tests do not run" >&2
    petsc=0
elif ! have_petsc; then
    if as_root; then
        # first: the crate's build waits for it (the others only for the tests)
        apt_lines=("libpetsc-real-dev libopenblas0-serial libopenmpi-dev openmpi-bin pkg-config" "${apt_lines[@]}")
        petsc_marker=target/test-apt.petsc-done
    else
        echo "test.sh: SKIPPING the PETSc backend's tests: PETSc and MPI are missing and we are not root (sudo apt-get install libpetsc-real-dev libopenmpi-dev openmpi-bin pkg-config)" >&2
        petsc=0
    fi
fi

# The installs, in the background while cargo builds the tests
mkdir -p target
jobs_=()
if ! have_venv; then
    echo "test.sh: creating .venv with gmsh, meshio, pyyaml and vtk (log: target/test-venv.log)" >&2
    { python3 -m venv .venv && .venv/bin/pip install --quiet --disable-pip-version-check gmsh meshio pyyaml vtk; } >target/test-venv.log 2>&1 &
    jobs_+=("$!:target/test-venv.log")
fi
petsc_marker=${petsc_marker:-}
rm -f target/test-apt.petsc-done
if [ ${#apt_lines[@]} -gt 0 ]; then
    echo "test.sh: installing with apt-get: ${apt_lines[*]} (log: target/test-apt.log)" >&2
    {
        apt-get update -qq
        for line in "${apt_lines[@]}"; do
            # shellcheck disable=SC2086 # each line is a list of flags and packages
            DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $line
            case "$line" in libpetsc*) touch target/test-apt.petsc-done ;; esac
        done
    } >target/test-apt.log 2>&1 &
    jobs_+=("$!:target/test-apt.log")
fi
# A failed install prints its log and stops the run
wait_for() {
    if ! wait "${1%%:*}"; then
        echo "test.sh: an install failed; its log, ${1#*:}:" >&2
        cat "${1#*:}" >&2
        exit 1
    fi
}

features=()
if [ "$petsc" = 1 ]; then
    features=(--features petsc)
    if [ -n "$petsc_marker" ]; then
        # PETSc is being installed: build the heavy dependencies meanwhile (the same
        # features as the crate's build, so none is built twice), then wait for it
        cargo build --release --locked -p faer -p nalgebra -p vtkio -p metis-sys -p serde_yaml -p rayon
        apt_job=${jobs_[-1]}
        while [ ! -e "$petsc_marker" ] && kill -0 "${apt_job%%:*}" 2>/dev/null; do sleep 2; done
        [ -e "$petsc_marker" ] || wait_for "$apt_job"
    fi
fi
cargo test --release --locked "${features[@]}" --no-run "$@"
for job in "${jobs_[@]}"; do wait_for "$job"; done

export PATH="$PWD/.venv/bin:$PATH"
export SC_PYTHON="$PWD/.venv/bin/python"
# Open MPI refuses to run as root unless told (CI runs as root)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
cargo test --release --locked "${features[@]}" "$@"
