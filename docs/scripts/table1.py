#!/usr/bin/env python3
"""The paper's Table 1 (Santos & Bandeira 2018, sec. 8), ours against CalculiX.

For each of the four paper examples (pipelines/parisch.yaml, crossed_beams.yaml,
parallel_beams.yaml, supported_beam.yaml):

1. runs our pipeline with sc-pipeline, once per material form -- `neo_hookean_dev_vol`
   (the model of CalculiX's NEO HOOKE and ANSYS) and `neo_hookean` (Ciarlet-Simo, as
   the paper ran it) -- and, unless --no-facet, once more with `master_kind: facet`
   (dev/vol); each from a copy of the pipeline in the work folder with the material
   model substituted in every solve setup;
2. reads the largest displacement magnitude at the last increment and its node (the
   exported .pvd, via meshio), the Newton iterations per increment (the convergence
   CSV), the wall time;
3. runs CalculiX on the same mesh, supports, loads and contact pair through
   tests/ccx/deck.py: node-to-surface with the stiffest penalty slope that reaches
   the end (augmented Lagrangian pairs: from 100 x eps_n down in steps 1-0.5-0.2;
   penalty pairs: eps_n itself, like for like), checked against the next softer
   slope; surface-to-surface only if no node-to-surface run completes;
4. writes the table, notes and image links into docs/validation.md between
   `<!-- table1:begin -->` and `<!-- table1:end -->` (the section is appended when
   the markers are absent), and renders docs/img/table1_<example>_<field>.png.

Usage (from anywhere; see docs/scripts/README.md for the venv):
    docs/.venv/bin/python docs/scripts/table1.py [--examples parisch,crossed_beams]
        [--work DIR] [--no-facet] [--no-ccx] [--no-images] [--no-doc]
Environment: SC_BIN (folder with sc-pipeline and sc-export, or the sc-pipeline
binary; default: PATH), CCX (ccx binary, default: deck.py's choice), DECK_PYTHON
(interpreter with gmsh for tests/ccx/deck.py; default .venv/bin/python).
"""
import argparse
import contextlib
import copy
import csv
import datetime
import io
import json
import math
import os
import re
import shutil
import subprocess
import sys
import textwrap
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "ccx"))
import deck as ccxdeck  # noqa: E402  (YAML 1.2 loader, stage list)

EXAMPLES = ["parisch", "crossed_beams", "parallel_beams", "supported_beam"]
# the paper's Table 1: max |u| ours / ANSYS (Parisch was not run in ANSYS)
PAPER_RATIO = {"crossed_beams": "97.49 %", "parallel_beams": "97.76 %", "supported_beam": "99.02 %"}
# variants of our run: (tag, material model, master_kind override)
VARIANTS = [("devvol", "neo_hookean_dev_vol", None), ("cs", "neo_hookean", None),
            ("facet", "neo_hookean_dev_vol", "facet")]
# camera (elevation, azimuth) per example for the images
# (elevation, azimuth, zoom, panels side by side or stacked)
VIEW = {"parisch": (22, -55, 1.15, "cols"), "crossed_beams": (24, -35, 1.45, "cols"),
        "parallel_beams": (14, -58, 2.6, "rows"), "supported_beam": (18, -62, 2.6, "rows")}
HEX_FACES0 = [tuple(i - 1 for i in f) for f in ccxdeck.HEX_FACES.values()]  # outward, 0-based
BEGIN, END = "<!-- table1:begin -->", "<!-- table1:end -->"
SECTION = "## The paper's examples (Table 1)"


def log(*a):
    print(*a, file=sys.stderr, flush=True)


# ------------------------------------------------------------------ tools
def sc_tools():
    b = os.environ.get("SC_BIN")
    if b:
        b = Path(b)
        d = b if b.is_dir() else b.parent
        pipe = d / "sc-pipeline" if b.is_dir() else b
        exp = d / "sc-export"
    else:
        pipe, exp = shutil.which("sc-pipeline"), shutil.which("sc-export")
        if not pipe:
            sys.exit("table1.py: sc-pipeline not found: set SC_BIN or put it on PATH")
        pipe, exp = Path(pipe), Path(exp) if exp else None
    if not Path(pipe).exists():
        sys.exit("table1.py: %s does not exist (SC_BIN)" % pipe)
    return Path(pipe), exp


def deck_python():
    p = os.environ.get("DECK_PYTHON")
    if p:
        return p
    v = ROOT / ".venv" / "bin" / "python"
    return str(v) if v.exists() else sys.executable


def first_line(s):
    for l in s.splitlines():
        if l.strip():
            return l.strip()
    return ""


def git_head():
    try:
        h = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                           text=True).stdout.strip()
        return h or "?"
    except OSError:
        return "?"


# --------------------------------------------------------------- variants
def make_variant(src, dst_dir, model, master_kind=None):
    """Copy of pipeline `src` in dst_dir: inputs that no earlier stage writes become
    absolute (the mesh, a .geo, a setup_file), outputs stay relative (so they land in
    dst_dir/out), every solve setup inline with `model` for every body."""
    pipe = ccxdeck.load_yaml(src.read_text())
    stages = ccxdeck.stage_list(pipe)
    produced = set()
    new = []
    for kind, body in stages:
        body = copy.deepcopy(body)
        for key in ("input", "geo"):
            if key in body and os.path.normpath(str(body[key])) not in produced:
                body[key] = str((src.parent / str(body[key])).resolve())
        if kind == "solve":
            if "setup_file" in body:
                setup = ccxdeck.load_yaml((src.parent / body.pop("setup_file")).read_text())
            else:
                setup = body.pop("setup")
            for m in setup.get("materials", []):
                m["model"] = model
            body["setup"] = setup
        if kind == "tag" and master_kind:
            for pr in body.get("pairs", []):
                pr["master_kind"] = master_kind
                pr["orders"] = [2, 2]
        for key in ("output", "csv"):
            if key in body:
                produced.add(os.path.normpath(str(body[key])))
        new.append({kind: body})
    pipe["stages"] = new
    dst_dir.mkdir(parents=True, exist_ok=True)
    out = dst_dir / src.name
    out.write_text("# generated by docs/scripts/table1.py from %s (material %s%s)\n" % (
        src.relative_to(ROOT), model, ", master_kind " + master_kind if master_kind else "")
        + yaml.safe_dump(pipe, sort_keys=False))
    return out


def solve_info(pipeline):
    """(solve stage, its .scres, the .pvd exported from it or None, its CSV)."""
    pipe = ccxdeck.load_yaml(pipeline.read_text())
    stages = ccxdeck.stage_list(pipe)
    solve = [b for k, b in stages if k == "solve"][0]
    res = (pipeline.parent / solve["output"]).resolve()
    pvd = None
    for k, b in stages:
        if k == "export" and (pipeline.parent / b["input"]).resolve() == res and str(b["output"]).endswith(".pvd"):
            pvd = (pipeline.parent / b["output"]).resolve()
    csv_path = (pipeline.parent / solve["csv"]).resolve() if "csv" in solve else res.with_suffix(".convergence.csv")
    return solve, res, pvd, csv_path


# ------------------------------------------------------------------- ours
def read_vtu(path):
    import meshio
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        return meshio.read(str(path))


def last_vtu(pvd):
    ds = list(ET.parse(pvd).getroot().iter("DataSet"))
    last = max(ds, key=lambda d: float(d.get("timestep")))
    return float(last.get("timestep")), pvd.parent / last.get("file"), len(ds) - 1


def newton_steps(csv_path, solve_ok):
    """Per attempt (increment, attempt, load factor) in order: Newton iterations per
    augmentation (rows with iteration >= 1) and whether the attempt converged (a
    failed one is followed by a higher attempt number of the same increment)."""
    groups = []
    with open(csv_path) as f:
        for r in csv.DictReader(f):
            key = (int(r["increment"]), int(r["attempt"]), float(r["load_factor"]))
            if not groups or groups[-1]["key"] != key:
                groups.append(dict(key=key, its={}))
            if int(r["iteration"]) >= 1:
                a = int(r.get("augmentation") or 0)
                groups[-1]["its"][a] = groups[-1]["its"].get(a, 0) + 1
    for i, g in enumerate(groups):
        nxt = groups[i + 1] if i + 1 < len(groups) else None
        if nxt is not None:
            g["converged"] = not (nxt["key"][0] == g["key"][0] and nxt["key"][1] > g["key"][1])
        else:
            g["converged"] = solve_ok
    return groups


def newton_text(groups):
    conv = [g for g in groups if g["converged"]]
    failed = [g for g in groups if not g["converged"]]
    tot = lambda g: sum(g["its"].values())
    parts = ["+".join(str(g["its"][a]) for a in sorted(g["its"])) or "0" for g in conv]
    n_aug = sum(1 for g in conv if len(g["its"]) > 1)
    if len(conv) <= 6:
        s = ", ".join(parts)
    else:
        t = [tot(g) for g in conv]
        s = "%d incr.: %d–%d each, %d in all" % (len(conv), min(t), max(t), sum(t))
        if n_aug:
            s += "; %d with an augmentation" % n_aug
    if failed:
        s += "; %d cut-back%s (%d its lost)" % (len(failed), "s" if len(failed) > 1 else "",
                                                  sum(tot(g) for g in failed))
    return s, sum(tot(g) for g in conv), len(conv)


def run_ours(pipeline, sc_pipeline, sc_export):
    solve, res, pvd, csv_path = solve_info(pipeline)
    t0 = time.perf_counter()
    p = subprocess.run([str(sc_pipeline), "-q", str(pipeline)], capture_output=True, text=True)
    wall = time.perf_counter() - t0
    out = dict(ok=p.returncode == 0, rc=p.returncode, wall=wall, pipeline=pipeline)
    if p.returncode != 0:
        msg = "\n".join(l for l in (p.stderr + p.stdout).splitlines() if l.strip())
        out["error"] = msg
    if csv_path.exists():
        groups = newton_steps(csv_path, out["ok"])
        out["newton"], out["newton_total"], out["n_incr"] = newton_text(groups)
        out["last_factor"] = [g["key"][2] for g in groups if g["converged"]][-1:] or [0.0]
    if out["ok"] and pvd is None and sc_export and res.exists():
        pvd = res.with_suffix(".pvd")
        subprocess.run([str(sc_export), "-q", str(res), "-o", str(pvd)], check=True)
    if out["ok"] and pvd is not None and pvd.exists():
        t, vtu, nsteps = last_vtu(pvd)
        m = read_vtu(vtu)
        u = np.asarray(m.point_data["displacement"], float)
        mag = np.linalg.norm(u, axis=1)
        i = int(np.argmax(mag))
        tags = np.asarray(m.point_data["gmsh_node_tag"]).astype(int)
        out.update(time=t, vtu=vtu, n_steps=nsteps, max_u=float(mag[i]), node=int(tags[i]),
                   X=m.points[i].tolist(), u_at=u[i].tolist())
    return out


# -------------------------------------------------------------------- ccx
def run_deck(pipeline, out_dir, slope, ctype):
    cmd = [deck_python(), str(ROOT / "tests" / "ccx" / "deck.py"), str(pipeline), "--run", "--json",
           "--out", str(out_dir), "--slope", "%g" % slope]
    if ctype == "surface":
        cmd += ["--contact", "surface"]
    if os.environ.get("CCX"):
        cmd += ["--ccx", os.environ["CCX"]]
    p = subprocess.run(cmd, capture_output=True, text=True)
    js = None
    try:
        js = json.loads(p.stdout)
    except ValueError:
        pass
    r = dict(slope=slope, ctype=ctype, dir=out_dir, ok=False, json=js)
    if js is None:
        r["error"] = first_line(p.stderr) or "deck.py exit %d" % p.returncode
        return r
    fin = js.get("final") or {}
    r.update(ok=bool(js.get("ok") and fin.get("reached_end")), max_u=fin.get("max_u"), node=fin.get("max_u_node"),
             time=fin.get("time"), wall=js.get("wall_seconds"), version=js.get("ccx_version"),
             iterations=sum((i.get("iterations") or 0) for i in js.get("increments", [])),
             increments=len(js.get("increments", [])),
             name=Path(js["deck"]).stem if js.get("deck") else None)
    if not r["ok"]:
        err = js.get("error") or []
        r["error"] = "; ".join(e.strip() for e in err) or "stopped at t = %s" % fin.get("time")
        if fin.get("time") is not None:
            r["error"] += " (last converged t = %.4g)" % fin["time"]
    return r


def slope_sequence(k0, k_min):
    seq, d = [], 0
    while True:
        for m in (1.0, 0.5, 0.2):
            k = float("%.6g" % (k0 * m * 10.0 ** -d))
            if k < k_min * 0.999:
                return seq
            seq.append(k)
        d += 1


def ccx_for(ex, pipeline, work):
    """Pick the ccx contact options for this example, run them, check the slope."""
    solve, _, _, _ = solve_info(pipeline)
    contact = solve["setup"].get("contact", [])
    eps = max(float(c["eps_n"]) for c in contact)
    penalty = all(c.get("enforcement", "augmented_lagrangian") == "penalty" for c in contact)
    runs = []
    # penalty pairs: the same slope as ours first (like for like); augmented
    # Lagrangian: 100 x eps_n (deck.py's default), then softer
    seq = slope_sequence(eps if penalty else 100.0 * eps, eps / 100.0)
    chosen = None
    for ctype in ("node", "surface"):
        for i, k in enumerate(seq):
            log("  ccx %s %s, slope %g" % (ex, ctype, k))
            r = run_deck(pipeline, work / ("ccx_%s_%g" % (ctype, k)), k, ctype)
            runs.append(r)
            if r["ok"]:
                chosen = r
                chosen["seq_index"] = i
                break
        if chosen:
            break
    out = dict(runs=runs, chosen=chosen, penalty=penalty, eps=eps)
    if not chosen:
        return out
    # penalty convergence: the next softer slope of the same contact type that completes
    i = chosen["seq_index"]
    out["check_failed"] = []
    for k2 in (seq[i + 1:] if not penalty else []):
        log("  ccx %s %s, slope %g (check)" % (ex, chosen["ctype"], k2))
        r2 = run_deck(pipeline, work / ("ccx_%s_%g" % (chosen["ctype"], k2)), k2, chosen["ctype"])
        if not r2["ok"]:
            out["check_failed"].append(r2)
            continue
        out["check"] = r2
        rr = chosen["slope"] / k2
        u1, u2 = chosen["max_u"], r2["max_u"]
        out["check_rel"] = (u2 - u1) / u1
        out["u_inf"] = u1 - (u2 - u1) / (rr - 1.0)   # u(K) = u_inf + c/K
        break
    # the other contact type at the chosen slope, for information
    other = "surface" if chosen["ctype"] == "node" else "node"
    log("  ccx %s %s, slope %g (cross-check)" % (ex, other, chosen["slope"]))
    out["other"] = run_deck(pipeline, work / ("ccx_%s_%g" % (other, chosen["slope"])), chosen["slope"], other)
    return out


def read_frd(path, want):
    """{name: (time, {node: values})} of the last block of each wanted result."""
    last = {}
    with open(path) as f:
        lines = f.read().splitlines()
    i, n = 0, len(lines)
    while i < n:
        l = lines[i]
        if l.startswith("  100C"):
            t = float(l.split()[2])
            i += 1
            bname = lines[i][5:13].strip()
            i += 1
            while i < n and lines[i].startswith(" -5"):
                i += 1
            vals = {}
            while i < n and lines[i].startswith(" -1"):
                s = lines[i]
                k = (len(s) - 13) // 12
                vals[int(s[3:13])] = [float(s[13 + 12 * j:25 + 12 * j]) for j in range(k)]
                i += 1
            if bname in want:
                last[bname] = (t, vals)
        else:
            i += 1
    return last


def ccx_ip_stress(run_dir, name):
    """ccx's element averages of the Gauss-point Cauchy stresses at the last time:
    the chosen deck rerun in run_dir/ips with *EL PRINT S per element set (the .frd
    has only extrapolated, node-averaged stresses). {element tag: 3x3}."""
    inp = run_dir / (name + ".inp")
    if not inp.exists():
        return None
    text = inp.read_text()
    elsets = re.findall(r"^\*ELEMENT,[^\n]*ELSET=(\S+)", text, re.M)
    a = text.rindex("*END STEP")
    add = "".join("*EL PRINT, ELSET=%s\nS\n" % e for e in elsets)
    d = run_dir / "ips"
    d.mkdir(exist_ok=True)
    (d / inp.name).write_text(text[:a] + add + text[a:])
    env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "1"))
    ccx = os.environ.get("CCX") or shutil.which("ccx") or "/usr/bin/ccx"
    subprocess.run([ccx, "-i", name], cwd=d, env=env, capture_output=True, text=True)
    dat = d / (name + ".dat")
    if not dat.exists():
        return None
    blocks = [b for b in ccxdeck.parse_dat(dat.read_text()) if b[0].startswith("stresses")]
    if not blocks:
        return None
    t_last = max(b[1] for b in blocks)
    acc = {}
    for title, t, rows in blocks:
        if t != t_last:
            continue
        for r in rows:   # elem, ip, sxx, syy, szz, sxy, sxz, syz
            xx, yy, zz, xy, xz, yz = r[2:8]
            acc.setdefault(int(r[0]), []).append(np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]))
    return {e: np.mean(v, axis=0) for e, v in acc.items()}


# ----------------------------------------------------------------- images
def sym(s6):
    """ccx SXX SYY SZZ SXY SYZ SZX -> 3x3."""
    xx, yy, zz, xy, yz, zx = s6
    return np.array([[xx, xy, zx], [xy, yy, yz], [zx, yz, zz]])


def nodal_average(cells, cell_vals, npts):
    acc = np.zeros((npts,) + cell_vals.shape[1:])
    cnt = np.zeros(npts)
    for c, v in zip(cells, cell_vals):
        acc[c] += v
        cnt[c] += 1
    cnt[cnt == 0] = 1
    return acc / cnt.reshape((-1,) + (1,) * (acc.ndim - 1))


def boundary_quads(cells):
    seen = {}
    for c in cells:
        for f in HEX_FACES0:
            q = tuple(int(c[i]) for i in f)
            k = tuple(sorted(q))
            seen[k] = None if k in seen else q
    return [q for q in seen.values() if q is not None]


def nice_scale(s):
    if s <= 1:
        return 1.0
    e = 10.0 ** math.floor(math.log10(s))
    for m in (5, 2, 1):
        if m * e <= s:
            return m * e
    return e


def surface_polys(X, u, vals, quads, scale, sub=4):
    """Deformed boundary quads, each split sub x sub with bilinear positions and values."""
    x = X + scale * u
    polys, cols = [], []
    g = np.linspace(0.0, 1.0, sub + 1)
    for q in quads:
        P, V = x[list(q)], vals[list(q)]
        for a0, a1 in zip(g[:-1], g[1:]):
            for b0, b1 in zip(g[:-1], g[1:]):
                corners = [(a0, b0), (a1, b0), (a1, b1), (a0, b1)]
                pts, vs = [], []
                for a, b in corners:
                    w = np.array([(1 - a) * (1 - b), a * (1 - b), a * b, (1 - a) * b])
                    pts.append(w @ P)
                    vs.append(w @ V)
                polys.append(pts)
                cols.append(np.mean(vs))
    return polys, np.array(cols), x


def render(ex, field, label, panels, scale, out_png, view):
    """panels: list of (title, X, u, nodal values or None, quads, text if failed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import cm, colors
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    good = [p for p in panels if p[3] is not None]
    allv = np.concatenate([p[3] for p in good]) if good else np.array([0.0, 1.0])
    vmin, vmax = float(np.min(allv)), float(np.max(allv))
    if vmax - vmin < 1e-30:
        vmax = vmin + 1.0
    norm = colors.Normalize(vmin, vmax)
    cmap = matplotlib.colormaps["turbo"]
    rows = view[3] == "rows"
    fig = plt.figure(figsize=(8.0, 5.6) if rows else (8.0, 4.0), dpi=100)
    lo = hi = None
    built = []
    for title, X, u, v, quads, text in panels:
        if v is None:
            built.append((title, None, None, text))
            continue
        polys, cols, x = surface_polys(X, u, v, quads, scale)
        lo = x.min(0) if lo is None else np.minimum(lo, x.min(0))
        hi = x.max(0) if hi is None else np.maximum(hi, x.max(0))
        built.append((title, polys, cols, (float(v.min()), float(v.max()))))
    n = len(built)
    for j, (title, polys, cols, extra) in enumerate(built):
        if rows:
            rect = [0.0, 0.13 + (n - 1 - j) * 0.80 / n, 1.0, 0.80 / n]
        else:
            rect = [j / n, 0.13, 1.0 / n, 0.75]
        ax = fig.add_axes(rect, projection="3d")
        ax.set_axis_off()
        lab = dict(x=rect[0] + 0.01, y=rect[1] + rect[3] - 0.005, ha="left", va="top", fontsize=8.5)
        if polys is None:
            ax.text2D(0.5, 0.5, extra, ha="center", va="center", fontsize=8, wrap=True, transform=ax.transAxes)
            fig.text(s=title, **lab)
            continue
        fc = cmap(norm(cols))
        pc = Poly3DCollection(polys, facecolors=fc, edgecolors=fc, linewidths=0.3, shade=True,
                              lightsource=colors.LightSource(azdeg=315, altdeg=45))
        pc.set_clip_on(False)   # the 3D viewport is a square: let a long beam overflow it sideways
        ax.add_collection3d(pc)
        c, r = (lo + hi) / 2, (hi - lo)
        ax.set_xlim(c[0] - r[0] / 2, c[0] + r[0] / 2)
        ax.set_ylim(c[1] - r[1] / 2, c[1] + r[1] / 2)
        ax.set_zlim(c[2] - r[2] / 2, c[2] + r[2] / 2)
        ax.set_box_aspect(np.maximum(r, 1e-3 * r.max()), zoom=view[2])
        ax.view_init(elev=view[0], azim=view[1])
        fig.text(s="%s\nmin %.4g, max %.4g" % (title, extra[0], extra[1]), **lab)
    fig.suptitle("%s: %s, last increment; displacement x %g" % (ex, label, scale), fontsize=10, y=0.99)
    sm = cm.ScalarMappable(norm=norm, cmap=cmap)
    cax = fig.add_axes([0.25, 0.06, 0.5, 0.025])
    fig.colorbar(sm, cax=cax, orientation="horizontal").ax.tick_params(labelsize=7)
    fig.savefig(out_png, dpi=100)
    plt.close(fig)


def stress_diff(vtu, ips):
    """Largest component difference of the element-average Cauchy stress, ours (this
    .vtu) against ccx's Gauss-point average, over the largest |component| of ours."""
    m = read_vtu(vtu)
    et = np.asarray(m.cell_data["gmsh_element_tag"][0]).astype(int)
    so = np.asarray(m.cell_data["stress"][0], float).reshape(-1, 3, 3)
    if any(int(e) not in ips for e in et):
        return None
    sc = np.array([ips[int(e)] for e in et])
    d = np.abs(so - sc).max(axis=(1, 2))
    i = int(np.argmax(d))
    return dict(rel=float(d[i] / np.abs(so).max()), abs=float(d[i]), element=int(et[i]))


def images(ex, ours, ccx, img_dir, ips):
    """docs/img/table1_<ex>_principal_{max,min}.png: ours (dev/vol) beside CalculiX.
    Our nodal stress is the nodal average of the element averages of the Gauss-point
    stresses; ccx's is built the same way from its Gauss-point stresses (see
    ccx_ip_stress), so both sides have the same smoothing."""
    made, info = [], {}
    if not ours.get("vtu"):
        return made, info
    m = read_vtu(ours["vtu"])
    X = np.asarray(m.points, float)
    cells = np.asarray(m.cells_dict["hexahedron"], int)
    quads = boundary_quads(cells)
    tags = np.asarray(m.point_data["gmsh_node_tag"]).astype(int)
    u_ours = np.asarray(m.point_data["displacement"], float)
    # consistency: our point stress = nodal average of our cell stress
    s_cell = np.asarray(m.cell_data["stress"][0], float).reshape(-1, 3, 3)
    s_pt = np.asarray(m.point_data["stress"], float).reshape(-1, 3, 3)
    info["ours_avg_check"] = float(np.abs(nodal_average(cells, s_cell, len(X)) - s_pt).max()
                                   / max(np.abs(s_pt).max(), 1e-300))
    ours_f = {f: np.asarray(m.point_data[f], float) for f in ("principal_max", "principal_min")}
    ccx_u = ccx_f = None
    ccx_title = "CalculiX"
    ch = (ccx or {}).get("chosen")
    text_fail = "CalculiX: no run reached the end"
    if ch and ch.get("name"):
        frd = Path(ch["dir"]) / (ch["name"] + ".frd")
        blocks = read_frd(frd, {"DISP", "STRESS"}) if frd.exists() else {}
        if "DISP" in blocks and ips is not None:
            d = blocks["DISP"][1]
            ccx_u = np.array([d[t][:3] for t in tags])
            etags = np.asarray(m.cell_data["gmsh_element_tag"][0]).astype(int)
            s_el = np.array([ips[t] for t in etags])
            S2 = nodal_average(cells, s_el, len(X))
            ev = np.linalg.eigvalsh(S2)
            ccx_f = {"principal_max": ev[:, 2], "principal_min": ev[:, 0]}
            if "STRESS" in blocks:
                s = blocks["STRESS"][1]
                evr = np.linalg.eigvalsh(np.array([sym(s[t][:6]) for t in tags]))
                info["ccx_raw"] = {"principal_max": float(evr[:, 2].max()), "principal_min": float(evr[:, 0].min())}
            ccx_title = "CalculiX (C3D8, %s-to-surface, K = %s)" % (ch["ctype"], kfmt(ch["slope"]))
        else:
            text_fail = "CalculiX: no stresses read from %s" % ch["dir"]
    umax = max(np.linalg.norm(u_ours, axis=1).max(), np.linalg.norm(ccx_u, axis=1).max() if ccx_u is not None else 0)
    ext = (X.max(0) - X.min(0)).max()
    scale = nice_scale(0.08 * ext / umax) if umax > 0 else 1.0
    info["scale"] = scale
    for f, label in (("principal_max", "max principal Cauchy stress"), ("principal_min", "min principal Cauchy stress")):
        png = img_dir / ("table1_%s_%s.png" % (ex, f))
        panels = [("ours (dev/vol, B-spline master)", X, u_ours, ours_f[f], quads, None),
                  (ccx_title, X, ccx_u, ccx_f[f] if ccx_f else None, quads, text_fail)]
        render(ex, f, label, panels, scale, png, VIEW.get(ex, (25, -60, 1.1, "cols")))
        made.append(png)
        info[f] = (float(ours_f[f].max() if f == "principal_max" else ours_f[f].min()),
                   float(ccx_f[f].max() if f == "principal_max" else ccx_f[f].min()) if ccx_f else None)
    return made, info


# ------------------------------------------------------------------ table
def cell(s):
    return str(s).replace("|", "\\|").replace("\n", " ")


def fail_cell(msg):
    m = first_line(msg)
    m = re.sub(r"^sc-pipeline: error: ", "", m)
    m = re.sub(r"^stage \d+ \(\w+\) failed: ", "", m)
    m = m.split(" (worst element")[0].split("; the ")[0].split(": relative residual")[0]
    return "failed: " + m


def kfmt(k):
    """1e7, 2e6, 5e5, 250000 -> 2.5e5."""
    m, e = ("%e" % k).split("e")
    m = ("%.6g" % float(m))
    return "%se%d" % (m, int(e)) if abs(int(e)) >= 4 else "%g" % k


def fmt_u(r):
    return "%.5f" % r["max_u"]


def ratio(a, b):
    return "%.4f" % (a / b) if a is not None and b else "—"


def where(r):
    X = r.get("X")
    return "node %d (%s)" % (r["node"], ", ".join("%g" % round(v, 4) for v in X)) if X else "node %s" % r.get("node")


def build_doc(results, meta, img_rel, facet):
    L = []
    L.append("Largest displacement magnitude at the last increment (mm, except Parisch: the paper's "
             "consistent units), ours against CalculiX 2.20 on the same mesh, supports, loads and contact "
             "pair (`tests/ccx/deck.py`: C3D8, `*HYPERELASTIC, NEO HOOKE`, NLGEOM). The ratio is ours / "
             "CalculiX, as the paper's ours / ANSYS (its target: ≥ 0.975). `neo_hookean_dev_vol` is the "
             "material CalculiX and ANSYS use (like for like); `neo_hookean` (Ciarlet–Simo) is how the "
             "paper ran its examples. Geometry and loads of the beams are ours (the paper's figures are "
             "lost, see the pipelines' headers), so only the ratios compare with the paper.")
    L.append("")
    hdr = ["example", "ours (dev/vol)", "CalculiX", "ratio", "ours (Ciarlet–Simo)", "ratio",
           "Newton iterations per increment (dev/vol; C–S)", "ccx contact option"]
    if facet:
        hdr[6:6] = ["ours facet master (dev/vol)", "ratio"]
    hdr.append("paper (vs ANSYS)")
    L.append("| " + " | ".join(hdr) + " |")
    L.append("|" + "|".join("---" for _ in hdr) + "|")
    for ex, R in results.items():
        d, c, f = R["ours"].get("devvol", {}), R["ours"].get("cs", {}), R["ours"].get("facet")
        cx = R.get("ccx") or {}
        ch = cx.get("chosen")
        cu = ch["max_u"] if ch else None

        def ours_cell(r):
            if not r:
                return "—"
            if not r.get("ok"):
                return fail_cell(r.get("error", "?"))
            return fmt_u(r)

        def ours_ratio(r):
            return ratio(r["max_u"], cu) if r and r.get("ok") and cu else "—"
        if ch:
            ccx_cell = "%.5f" % cu
        elif cx.get("runs"):
            ccx_cell = "failed: " + cx["runs"][-1].get("error", "?")
        else:
            ccx_cell = "not run"
        nd, nc = d.get("newton", "—"), c.get("newton", "—")
        newton = nd if nd == nc else "%s; %s" % (nd, nc)
        if ch:
            opt = "%s-to-surface, K = %s" % (ch["ctype"], kfmt(ch["slope"]))
            opt += " (= ε_N, penalty as ours)" if cx.get("penalty") and ch["slope"] == cx["eps"] else \
                " (%g ε_N)" % (ch["slope"] / cx["eps"])
        else:
            opt = "—"
        row = [ex, ours_cell(d), ccx_cell, ours_ratio(d), ours_cell(c), ours_ratio(c), newton, opt]
        if facet:
            row[6:6] = [ours_cell(f), ours_ratio(f)]
        row.append(PAPER_RATIO.get(ex, "— (not run in ANSYS)"))
        L.append("| " + " | ".join(cell(x) for x in row) + " |")
    L.append("")
    L.append("Per example (where the maximum is: gmsh node tag and reference coordinates; wall times "
             "of the whole `sc-pipeline` run and of the ccx process):")
    L.append("")
    for ex, R in results.items():
        d, c, f = R["ours"].get("devvol", {}), R["ours"].get("cs", {}), R["ours"].get("facet")
        cx = R.get("ccx") or {}
        ch = cx.get("chosen")
        s = ["**%s**." % ex]
        if d.get("ok"):
            s.append("Ours (dev/vol): %.6f at %s, %d Newton iterations in %d increment(s), %.2f s; "
                     "Ciarlet–Simo: %s, %.2f s." % (d["max_u"], where(d), d["newton_total"], d["n_incr"], d["wall"],
                                                    ("%.6f at node %d" % (c["max_u"], c["node"])) if c.get("ok") else "failed",
                                                    c.get("wall", 0)))
        for tag, r in (("dev/vol", d), ("Ciarlet–Simo", c), ("facet master", f)):
            if r and not r.get("ok"):
                s.append("Ours (%s) failed, verbatim: `%s`." % (tag, r.get("error", "?").replace("`", "'")))
        if f and f.get("ok"):
            s.append("Facet master (dev/vol): %.6f at node %d, Newton: %s." % (f["max_u"], f["node"], f["newton"]))
        if ch:
            s.append("CalculiX: %.7g at %s, %s-to-surface K = %s, %d increment(s), %d iterations, %.2f s." % (
                ch["max_u"], where(dict(node=ch["node"], X=R.get("coords", {}).get(ch["node"]))), ch["ctype"], kfmt(ch["slope"]), ch["increments"], ch["iterations"], ch["wall"] or 0))
            failed = [r for r in cx["runs"] if not r["ok"] and r is not ch]
            if failed:
                s.append("Stiffer slopes that did not reach the end: %s (%s)." % (
                    ", ".join("%s %s" % (r["ctype"], kfmt(r["slope"])) for r in failed),
                    failed[0].get("error", "?")))
            if cx.get("penalty") and ch["slope"] == cx["eps"]:
                s.append("Penalty pair: ccx uses our ε_N (the penalty is part of the problem, no slope check).")
            elif "check_rel" in cx:
                k2 = cx["check"]["slope"]
                s.append("Slope check: K = %s gives %.7g (%+.2g relative); with u(K) = u∞ + c/K the two "
                         "extrapolate to u∞ = %.6g, ratio ours (dev/vol) / u∞ = %s." % (
                             kfmt(k2), cx["check"]["max_u"], cx["check_rel"], cx["u_inf"],
                             ratio(d.get("max_u"), cx["u_inf"]) if d.get("ok") else "—"))
            if cx.get("check_failed"):
                s.append("Softer slopes that did not complete: %s." % ", ".join(kfmt(r["slope"]) for r in cx["check_failed"]))
            if not cx.get("penalty") and "check" not in cx:
                s.append("No softer slope completed: no slope check.")
            o = cx.get("other")
            if o:
                s.append("Cross-check, %s-to-surface at the same K: %s." % (
                    o["ctype"], ("%.6g at node %d" % (o["max_u"], o["node"])) if o["ok"] else "failed (%s)" % o.get("error")))
        elif cx.get("runs"):
            s.append("CalculiX failed at every slope tried: %s." % "; ".join(
                "%s %s: %s" % (r["ctype"], kfmt(r["slope"]), r.get("error")) for r in cx["runs"]))
        im = R.get("img_info") or {}
        if "principal_max" in im and im["principal_max"][1] is not None:
            raw = im.get("ccx_raw")
            s.append("Extremes of the nodal principal stresses (same smoothing both sides): σ_max %.4g ours, %.4g ccx; "
                     "σ_min %.4g ours, %.4g ccx%s." % (
                         im["principal_max"][0], im["principal_max"][1], im["principal_min"][0], im["principal_min"][1],
                         " (ccx's `.frd`, extrapolated: %.4g, %.4g)" % (raw["principal_max"], raw["principal_min"])
                         if raw else ""))
        sd = R.get("stress_diff") or {}
        if sd:
            s.append("Element-average Cauchy stress against ccx's (largest component difference / largest "
                     "component): %s." % ", ".join("%.2g %s" % (v["rel"], {"devvol": "dev/vol", "cs": "Ciarlet–Simo",
                                                                          "facet": "facet master"}[k])
                                                 for k, v in sd.items() if v))
        L.append("- " + " ".join(s))
    L.append("")
    if any(R.get("images") for R in results.values()):
        L.append("Deformed outer surfaces (hexahedron boundary faces, displacement scaled as stated in each "
                 "title), coloured by the principal Cauchy stresses: ours with `neo_hookean_dev_vol` and the "
                 "B-spline master (left or top), CalculiX with the contact option of the table (right or "
                 "bottom), one colour "
                 "scale per image. Both nodal stresses are the nodal average of the element averages of the "
                 "Gauss-point Cauchy stresses (ccx's from a second run of its deck with `*EL PRINT S`; its `.frd` "
                 "values, extrapolated to the nodes, have larger extremes, given in the notes).")
        L.append("")
        for ex, R in results.items():
            for png in R.get("images", []):
                f = "max" if png.stem.endswith("max") else "min"
                L.append("![%s, %s principal stress](%s/%s)" % (ex, f, img_rel, png.name))
            L.append("")
    # the versions that produced the section; when and from which commit is git's to say
    L.append("Produced by `%s`: sc-pipeline %s, CalculiX %s, matplotlib %s, meshio %s." % (
        meta["command"], meta["sc_release"], meta["ccx_version"], meta["mpl"], meta["meshio"]))
    return "\n".join(L)


def wrap(body, width=88):
    """Wrap prose lines and bullets (not table rows, images or headings) to width."""
    out = []
    for line in body.split("\n"):
        if len(line) <= width or line.startswith(("|", "!", "#", "<!--")):
            out.append(line)
        elif line.startswith("- "):
            out.extend(textwrap.wrap(line, width, subsequent_indent="  ", break_long_words=False,
                                     break_on_hyphens=False))
        else:
            out.extend(textwrap.wrap(line, width, break_long_words=False, break_on_hyphens=False))
    return "\n".join(out)


def write_doc(doc_path, body):
    text = doc_path.read_text()
    block = BEGIN + "\n" + wrap(body) + "\n" + END
    if BEGIN in text and END in text:
        a = text.index(BEGIN)
        b = text.index(END, a) + len(END)
        text = text[:a] + block + text[b:]
    else:
        text = text.rstrip("\n") + "\n\n" + SECTION + "\n\n" + block + "\n"
    doc_path.write_text(text)


# ------------------------------------------------------------------- main
def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--examples", default=",".join(EXAMPLES))
    ap.add_argument("--work", default=str(ROOT / "pipelines" / "out" / "table1"),
                    help="work folder (default pipelines/out/table1, git-ignored)")
    ap.add_argument("--doc", default=str(ROOT / "docs" / "validation.md"))
    ap.add_argument("--img", default=str(ROOT / "docs" / "img"))
    ap.add_argument("--no-facet", action="store_true", help="skip the facet-master run of ours")
    ap.add_argument("--no-ccx", action="store_true")
    ap.add_argument("--no-images", action="store_true")
    ap.add_argument("--no-doc", action="store_true", help="print the table instead of writing the doc")
    a = ap.parse_args(argv)
    sc_pipeline, sc_export = sc_tools()
    work = Path(a.work).resolve()
    img_dir = Path(a.img).resolve()
    results = {}
    ccx_version = "?"
    for ex in [e.strip() for e in a.examples.split(",") if e.strip()]:
        src = ROOT / "pipelines" / (ex + ".yaml")
        R = dict(ours={})
        results[ex] = R
        for tag, model, mk in VARIANTS:
            if mk and a.no_facet:
                continue
            d = work / ex / tag
            if d.exists():
                shutil.rmtree(d)
            pipe = make_variant(src, d, model, mk)
            log("ours %s %s" % (ex, tag))
            R["ours"][tag] = r = run_ours(pipe, sc_pipeline, sc_export)
            if r.get("vtu") and "coords" not in R:
                mm = read_vtu(r["vtu"])
                R["coords"] = {int(t): x.tolist() for t, x in zip(mm.point_data["gmsh_node_tag"], mm.points)}
            if not r["ok"]:
                log("  failed: %s" % first_line(r.get("error", "")))
            else:
                log("  max|u| %.6f node %d, %s, %.2f s" % (r["max_u"], r["node"], r.get("newton"), r["wall"]))
        if not a.no_ccx:
            d = work / ex / "ccx"
            if d.exists():
                shutil.rmtree(d)
            R["ccx"] = cx = ccx_for(ex, R["ours"]["devvol"]["pipeline"], d)
            ch = cx.get("chosen")
            if ch:
                ccx_version = ch.get("version") or ccx_version
                log("  ccx: %s K=%g max|u| %.7g node %s" % (ch["ctype"], ch["slope"], ch["max_u"], ch["node"]))
            else:
                log("  ccx failed at every slope")
        ch = (R.get("ccx") or {}).get("chosen")
        ips = ccx_ip_stress(Path(ch["dir"]), ch["name"]) if ch and ch.get("name") else None
        if ips:
            R["stress_diff"] = {tag: stress_diff(r["vtu"], ips) for tag, r in R["ours"].items() if r.get("vtu")}
            log("  element stress vs ccx: %s" % {k: v and "%.2g" % v["rel"] for k, v in R["stress_diff"].items()})
        if not a.no_images and R["ours"]["devvol"].get("ok"):
            img_dir.mkdir(parents=True, exist_ok=True)
            R["images"], R["img_info"] = images(ex, R["ours"]["devvol"], R.get("ccx"), img_dir, ips)
            log("  our point stress vs nodal average of our cell stress: %.1e relative"
                % R["img_info"].get("ours_avg_check", float("nan")))
            for p in R["images"]:
                log("  %s: %d kB" % (p.relative_to(ROOT) if p.is_relative_to(ROOT) else p, p.stat().st_size // 1024))
    import matplotlib
    import meshio
    ver = subprocess.run([str(sc_pipeline), "--version"], capture_output=True, text=True).stdout.split()
    built = datetime.datetime.fromtimestamp(sc_pipeline.stat().st_mtime, datetime.timezone.utc)
    meta = dict(command="docs/.venv/bin/python docs/scripts/table1.py"
                + (" " + " ".join(argv if argv is not None else sys.argv[1:])).rstrip(),
                date=datetime.date.today().isoformat(),
                sc_version="%s (release build of %s)" % (ver[-1] if ver else "?", built.strftime("%Y-%m-%d %H:%M UTC")),
                sc_release=ver[-1] if ver else "?",
                git=git_head(),
                ccx_version=ccx_version, mpl=matplotlib.__version__, meshio=meshio.__version__)
    doc = Path(a.doc).resolve()
    try:
        img_rel = os.path.relpath(img_dir, doc.parent)
    except ValueError:
        img_rel = str(img_dir)
    body = build_doc(results, meta, img_rel, not a.no_facet)
    if a.no_doc:
        print(body)
    else:
        write_doc(doc, body)
        log("wrote %s" % doc)
    (work / "table1.json").parent.mkdir(parents=True, exist_ok=True)
    (work / "table1.json").write_text(json.dumps(results, default=str, indent=1))


if __name__ == "__main__":
    main()
