#!/usr/bin/env python3
"""The frictional crossed beams from 10k to 1M dofs: faer direct against PETSc's
algebraic multigrid on 1 and 2 MPI ranks (docs/performance.md, "PETSc and
algebraic multigrid").

For each variant, runs docs/scripts/ccx_compare.py crossed_beams --no-ccx at every
level (gmsh meshes meshes/crossed_beams.geo at level n: n x n x 15n hex8 per beam),
which times sc-solve as a whole process (wall time, peak RSS) and reads the time
per phase from its convergence CSV (contact search, assembly, factor = matrix
insertion + multigrid setup for PETSc, solve = Krylov), the Newton iterations and
the Krylov iterations per solve from its log. Then prints a Markdown table and,
with --plot, draws time against dofs, log-log (needs matplotlib in the venv).

Usage (from the repository root, after
`CARGO_TARGET_DIR=target/petsc cargo build --release --features petsc`):
    SC_BIN_DIR=$PWD/target/petsc/release .venv/bin/python docs/scripts/petsc_scaling.py \\
        --levels 4 8 12 16 22 --direct-max-level 12 --plot docs/img/petsc_scaling.png
Variants: direct (faer, 2 threads), petsc on 1 rank (2 threads for assembly),
petsc on 2 ranks (1 thread each). --skip VARIANT leaves one out.
"""
import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent
VARIANTS = {
    "direct": (["--linear-solver", "direct"], 1),
    "petsc-1": (["--linear-solver", "petsc"], 1),
    "petsc-2": (["--linear-solver", "petsc", "--mpi-ranks", "2"], 2),
}


def run_variant(name, levels, out):
    args, _ = VARIANTS[name]
    cmd = [sys.executable, str(ROOT / "docs/scripts/ccx_compare.py"), "crossed_beams", "--no-ccx", "--json",
           "--threads", "2", "--out", str(out / name), "--levels", *map(str, levels), *args]
    p = subprocess.run(cmd, capture_output=True, text=True)
    try:
        return json.loads(p.stdout)
    except json.JSONDecodeError:
        sys.exit("petsc_scaling.py: %s failed:\n%s" % (name, p.stderr[-3000:]))


def table(results):
    out = ["| variant | level | dofs | total s | contact s | assembly s | factor/setup s | solve s | peak RSS MB | Newton its | Krylov its/solve |",
           "|" + "---|" * 11]
    for name, rows in results.items():
        for r in rows:
            o = r.get("ours", {})
            g = lambda k, fmt="%.1f": (fmt % o[k]) if o.get(k) is not None else "–"
            out.append("| %s | %d | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                name, r["level"], f"{r['dofs']:,}" if r.get("dofs") else "–", g("wall_s") if o.get("ok") else "failed",
                g("contact_s"), g("assembly_s"), g("factor_s"), g("solve_s"), g("peak_rss_mb", "%.0f"),
                g("newton_iterations", "%d"), g("krylov_per_solve")))
    return "\n".join(out)


def plot(results, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for name, rows in results.items():
        pts = [(r["dofs"], r["ours"]["wall_s"]) for r in rows if r.get("dofs") and r.get("ours", {}).get("ok")]
        if pts:
            ax.loglog(*zip(*pts), "o-", label={"direct": "faer direct (2 threads)", "petsc-1": "PETSc GAMG, 1 rank",
                                                "petsc-2": "PETSc GAMG, 2 ranks"}[name])
    ax.set_xlabel("dofs")
    ax.set_ylabel("sc-solve wall time, s (3 increments)")
    ax.set_title("Frictional crossed beams, B-spline master, 2 cores")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(png, dpi=110)


def report(results, add, png):
    """Print the table of `results` (with the rows of the JSON file `add`) and plot it to `png`."""
    if add:
        for name, rows in json.loads(Path(add).read_text()).items():
            results.setdefault(name, []).extend(rows)
    print(table(results))
    if png:
        plot(results, png)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n", 2)[2])
    ap.add_argument("--levels", type=int, nargs="+", default=[4, 8, 12, 16, 22])
    ap.add_argument("--direct-max-level", type=int, default=12)
    ap.add_argument("--out", default=str(ROOT / "pipelines" / "out" / "petsc_scaling"))
    ap.add_argument("--skip", action="append", default=[], choices=sorted(VARIANTS))
    ap.add_argument("--plot", default=None)
    ap.add_argument("--add", default=None, metavar="JSON",
                    help="rows run by hand (e.g. level 22 under mpirun), {variant: [row, ...]} in the script's "
                         "row format, added to the table and the plot")
    ap.add_argument("--replot", default=None, metavar="JSON",
                    help="do not run: read a scaling.json written before (plus --add) and print and plot it")
    a = ap.parse_args()
    if a.replot:
        report(json.loads(Path(a.replot).read_text()), a.add, a.plot)
        return
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    results = {}
    for name in VARIANTS:
        if name in a.skip:
            continue
        levels = [n for n in a.levels if name != "direct" or n <= a.direct_max_level]
        results[name] = run_variant(name, levels, out)
        print("%s done" % name, file=sys.stderr)
    (out / "scaling.json").write_text(json.dumps(results, indent=1) + "\n")
    report(results, a.add, a.plot)


if __name__ == "__main__":
    main()
