#!/usr/bin/env python3
"""Hertz (plane-strain cylinder on a block): convergence of the pressure profile,
node-to-surface against mortar integration (issue 25).

For refine in (1, 2, 3, 4), integration in (node, mortar), master in (B-spline [2, 3],
facet):
1. meshes meshes/hertz.geo with gmsh at that refinement into the work folder (the
   committed meshes/hertz.msh is not touched);
2. writes a copy of pipelines/hertz.yaml there with both bodies `linear_elastic`
   (Hertz's theory is linear: the shipped neo-Hookean runs have a ~1 % finite-strain
   floor, docs/validation/hertz.md), `integration: <node|mortar>` on the pair and the
   mesh as an absolute path; one pipeline solves both masters;
3. runs sc-pipeline on it and tests/py/hertz.py on both results (.pvd);
4. collects p0_err, b_fit_err, the profile errors (profile_rms_err, profile_l2_err,
   profile_max_err: |p_fe - p_hertz| / p0_hertz on the slave line's reference x),
   Newton corrections, solve time (the convergence CSV's seconds) and the pipeline's
   wall time into docs/scripts/data/hertz_convergence.json;
5. plots the profile RMS error, the max and the max away from the edge (x <= 0.8 b)
   against the slave element size h at x = 0, log-log, both integrations, both
   masters (and mortar's force per tributary area): docs/img/hertz_convergence.png.

Usage (from anywhere):
    .venv/bin/python docs/scripts/hertz_convergence.py [--refine 1,2,4] [--work DIR]
    .venv/bin/python docs/scripts/hertz_convergence.py --replot   # plot from the JSON
Environment: SC_BIN (folder with sc-pipeline and sc-export; default target/release),
GMSH (default: the gmsh beside this Python, else PATH). Needs meshio, numpy,
matplotlib (the test venv .venv plus `pip install matplotlib`, or docs/.venv).
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "docs/scripts/data/hertz_convergence.json"
PNG = ROOT / "docs/img/hertz_convergence.png"
INTEGRATIONS = ["node", "mortar"]
# (label, pvd stem of pipelines/hertz.yaml)
MASTERS = [("bspline", "hertz"), ("facet", "hertz-facet")]
KEYS = ["nodes", "h_slave", "h_master", "P", "b_hertz", "p0_hertz", "b_bracket", "b_hertz_in_bracket",
        "b_fit", "b_fit_err", "p0_fe", "p0_err", "profile_rms_err", "profile_l2_err", "profile_max_err",
        "profile_max_x", "profile_nodes", "profile_interior_max_err", "integration", "profile_force_rms_err", "profile_force_l2_err",
        "profile_force_max_err", "profile_force_max_x", "active_nodes_line", "max_penetration", "newton",
        "newton_per_increment", "augmentations", "cutbacks", "solver_seconds"]


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def edit(text, old, new, count):
    n = text.count(old)
    if n != count:
        sys.exit("hertz_convergence.py: pipelines/hertz.yaml has %d x %r, expected %d" % (n, old, count))
    return text.replace(old, new)


def pipeline_text(mesh, integration):
    """pipelines/hertz.yaml, linear elastic, `integration`, the mesh's absolute path."""
    y = (ROOT / "pipelines/hertz.yaml").read_text()
    y = edit(y, "input: ../meshes/hertz.msh", "input: %s" % mesh, 1)
    y = edit(y, "model: neo_hookean,", "model: linear_elastic,", 2)
    y = edit(y, "max_augmentations: 20}", "max_augmentations: 20, integration: %s}" % integration, 1)
    return y


def gmsh_exe():
    g = os.environ.get("GMSH")
    if g:
        return g
    here = Path(sys.executable).parent / "gmsh"
    return str(here) if here.exists() else (shutil.which("gmsh") or sys.exit("hertz_convergence.py: no gmsh"))


def run_case(work, refine, integration, sc_bin, env, reuse=None):
    d = work / ("r%d-%s" % (refine, integration))
    d.mkdir(parents=True, exist_ok=True)
    mesh = work / ("hertz-r%d.msh" % refine)
    pipe = d / "hertz.yaml"
    done = reuse is not None and all((d / "out" / (stem + ".pvd")).exists() for _, stem in MASTERS)
    if not mesh.exists() and not done:
        subprocess.run([gmsh_exe(), str(ROOT / "meshes/hertz.geo"), "-3", "-format", "msh41", "-setnumber",
                        "refine", str(refine), "-o", str(mesh)], check=True, capture_output=True, env=env)
    if done:  # --reuse: the solved work folder, the wall time of the run that solved it
        wall = reuse.get((refine, integration))
        p = subprocess.CompletedProcess([], 0, "", "")
    else:
        pipe.write_text(pipeline_text(mesh, integration))
        t0 = time.perf_counter()
        p = subprocess.run([str(sc_bin / "sc-pipeline"), "-q", str(pipe)], capture_output=True, text=True)
        wall = round(time.perf_counter() - t0, 2)
    if p.returncode != 0:
        log(p.stderr)
        return [dict(refine=refine, integration=integration, master=m, ok=False, rc=p.returncode,
                     error=p.stderr.strip().splitlines()[-1:] or [""]) for m, _ in MASTERS]
    rows = []
    for master, stem in MASTERS:
        q = subprocess.run([sys.executable, str(ROOT / "tests/py/hertz.py"), str(d / "out" / (stem + ".pvd"))],
                           capture_output=True, text=True, env=env)
        if q.returncode != 0:
            sys.exit("hertz.py failed on %s:\n%s" % (d, q.stderr))
        j = json.loads([l for l in q.stdout.splitlines() if l.startswith("{")][0])
        row = dict(refine=refine, integration=integration, master=master, ok=True, pipeline_wall_s=wall)
        row.update({k: j[k] for k in KEYS})
        rows.append(row)
        log("refine %d %-6s %-7s: p0 %+.3f %%, b_fit %+.3f %%, profile rms %.4f l2 %.4f max %.4f (x %.3f), "
            "newton %s, solve %.1f s" % (refine, integration, master, 100 * j["p0_err"], 100 * j["b_fit_err"],
                                          j["profile_rms_err"], j["profile_l2_err"], j["profile_max_err"],
                                          j["profile_max_x"], j["newton"], j["solver_seconds"]))
    return rows


def plot(data):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in data["runs"] if r.get("ok")]
    panels = [("profile_rms_err", "RMS over x ≤ 2b"), ("profile_max_err", "max over the line"),
              ("profile_interior_max_err", "max over x ≤ 0.8 b")]
    panels = [(k, t) for k, t in panels if all(k in r for r in rows)]
    fig, axes = plt.subplots(1, len(panels), figsize=(5 * len(panels), 4.2), squeeze=False)
    axes = axes[0]
    style = {("node", "bspline"): ("C0", "o", "-"), ("node", "facet"): ("C0", "s", "--"),
             ("mortar", "bspline"): ("C3", "o", "-"), ("mortar", "facet"): ("C3", "s", "--")}
    for ax, (key, title) in zip(axes, panels):
        for (integ, master), (c, mk, ls) in style.items():
            rs = sorted((r for r in rows if r["integration"] == integ and r["master"] == master), key=lambda r: r["h_slave"])
            if not rs:
                continue
            h = [r["h_slave"] for r in rs]
            e = [r[key] for r in rs]
            ax.loglog(h, e, color=c, marker=mk, ls=ls, label="%s, %s" % (integ, "B-spline [2,3]" if master == "bspline" else "facet"))
            fkey = key.replace("profile_", "profile_force_")
            if integ == "mortar" and master == "bspline" and all(fkey in r for r in rs):
                # mortar's nodal force per tributary area (node-to-surface: the same as its pressure)
                ax.loglog(h, [r[fkey] for r in rs], color="C1", marker="^", ls=":",
                          label="mortar, B-spline, force / area")
        # reference slopes through the node/B-spline coarsest point
        ref = sorted((r for r in rows if r["integration"] == "node" and r["master"] == "bspline"), key=lambda r: -r["h_slave"])
        if ref:
            h0, e0 = ref[0]["h_slave"], ref[0][key]
            hs = [h0, h0 / 4.0]
            for k, lab in [(0.5, "h^0.5"), (1.0, "h^1"), (2.0, "h^2")]:
                ax.loglog(hs, [0.7 * e0 * (x / h0) ** k for x in hs], color="0.6", lw=0.8, ls=":")
                ax.annotate(lab, (hs[1], 0.7 * e0 * (hs[1] / h0) ** k), fontsize=8, color="0.4")
        ax.set_xlabel("slave element size h at x = 0")
        ax.set_ylabel("|p_fe − p_Hertz| / p0")
        ax.set_title("Hertz profile error, %s" % title, fontsize=10)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    PNG.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(PNG, dpi=120)
    log("wrote", PNG)


def table(data):
    rows = [r for r in data["runs"] if r.get("ok")]
    print("| refine | h slave | integration | master | P | p0 err | b_fit err | profile RMS | profile L2 | profile max (x) | Newton | solve s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in sorted(rows, key=lambda r: (r["refine"], r["master"] != "bspline", r["integration"] != "node")):
        print("| %d | %.4f | %s | %s | %.3f | %+.2f %% | %+.2f %% | %.4f | %.4f | %.4f (%.3f) | %d | %.1f |" % (
            r["refine"], r["h_slave"], r["integration"], "B-spline" if r["master"] == "bspline" else "facet", r["P"],
            100 * r["p0_err"], 100 * r["b_fit_err"], r["profile_rms_err"], r["profile_l2_err"], r["profile_max_err"],
            r["profile_max_x"], r["newton"], r["solver_seconds"]))
    for r in data["runs"]:
        if not r.get("ok"):
            print("failed: refine %d %s %s: %s" % (r["refine"], r["integration"], r["master"], r.get("error")))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--refine", default="1,2,3,4")
    ap.add_argument("--work", help="work folder (default: a temporary one, removed)")
    ap.add_argument("--replot", action="store_true", help="only the plot and table, from the JSON")
    ap.add_argument("--reuse", action="store_true",
                    help="with --work: do not solve again where the work folder has the results (re-runs hertz.py; "
                         "wall times from the JSON)")
    a = ap.parse_args()
    if a.replot:
        data = json.loads(DATA.read_text())
        plot(data)
        table(data)
        return
    sc_bin = Path(os.environ.get("SC_BIN", ROOT / "target/release"))
    if not (sc_bin / "sc-pipeline").exists():
        sys.exit("hertz_convergence.py: no %s (build with cargo build --release, or set SC_BIN)" % (sc_bin / "sc-pipeline"))
    env = dict(os.environ)
    env["SC_EXPORT"] = str(sc_bin / "sc-export")
    env["PATH"] = "%s:%s" % (Path(sys.executable).parent, env.get("PATH", ""))  # the PyPI gmsh script
    tmp = None
    if a.work:
        work = Path(a.work).resolve()
        work.mkdir(parents=True, exist_ok=True)
    else:
        tmp = tempfile.TemporaryDirectory(prefix="hertz_convergence")
        work = Path(tmp.name)
    reuse = None
    if a.reuse:
        old = json.loads(DATA.read_text())["runs"] if DATA.exists() else []
        reuse = {(r["refine"], r["integration"]): r.get("pipeline_wall_s") for r in old}
    runs = []
    for refine in [int(r) for r in a.refine.split(",")]:
        for integration in INTEGRATIONS:
            runs += run_case(work, refine, integration, sc_bin, env, reuse)
            DATA.parent.mkdir(parents=True, exist_ok=True)
            data = dict(
                description="Hertz plane-strain cylinder (meshes/hertz.geo, pipelines/hertz.yaml), linear_elastic "
                            "both bodies, node-to-surface vs mortar, B-spline [2,3] and facet master; "
                            "errors from tests/py/hertz.py (reference x; profile errors / p0_hertz)",
                git=subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                                   text=True).stdout.strip(),
                runs=runs)
            DATA.write_text(json.dumps(data, indent=1) + "\n")
    plot(data)
    table(data)
    if tmp:
        tmp.cleanup()


if __name__ == "__main__":
    main()
