#!/usr/bin/env python3
"""CalculiX (ccx) reference for the Parisch two-block contact example.

Reads the committed gmsh mesh meshes/parisch.msh with meshio and writes a ccx
deck (tests/ccx/parisch.inp by default).  With --run it runs ccx on the deck in
a temporary directory and prints a JSON summary (load-node displacement, final
z, total contact force, reactions, per-slave-node contact pressure, Newton
iteration counts).  With --sweep it runs the penalty slopes 1e5 ... 1e9 and
prints the load-node uz for each.

Usage (from the repository root):
    .venv/bin/python tests/ccx/parisch.py                 # regenerate parisch.inp
    .venv/bin/python tests/ccx/parisch.py --run           # + run ccx, print JSON
    .venv/bin/python tests/ccx/parisch.py --sweep         # slopes 1e5..1e9
Options: --slope K, --force F, --tension S (ccx sigma_inf), --model devvol,
         --out PATH, --ccx PATH, --keep DIR (keep the ccx run directory).

Problem (see meshes/parisch.geo): both blocks compressible neo-Hookean in
deviatoric/volumetric form (ccx *HYPERELASTIC, NEO HOOKE, C10 = mu/2,
D1 = 2/K), C3D8, NLGEOM; lower_base fixed; upper_axis fixed in x,y;
upper_twist fixed in x; Fz = F on load_node; frictionless node-to-surface
penalty contact, slave = upper_bottom, master = lower_top, linear
pressure-overclosure with slope K.
"""
import argparse
import contextlib
import io
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import meshio
import numpy as np

# the ccx face table, the (f20.0) float field, the number pattern and the .cvg
# reader are the general deck generator's (this script is its Parisch special case)
from deck import HEX_FACES, NUM, fmt, parse_cvg

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
MESH = ROOT / "meshes" / "parisch.msh"
DEFAULT_OUT = HERE / "parisch.inp"

E_UPPER, E_LOWER, NU = 1.0e9, 1.0e10, 0.3
DEFAULT_SLOPE = 1.0e5
DEFAULT_FORCE = -2.0e6
# ccx's sigma_inf: tension at large clearance; it also sets the width
# eps = pi*sigma_inf/K of ccx's arctan regularisation of the linear law at g = 0.
# The contact pressure is shifted by about -sigma_inf (relative 2e-10 here).
DEFAULT_TENSION = 1.0e-6
# ccx *CONTROLS, PARAMETERS=FIELD: R_n (residual / mean force) and C_n
# (correction / increment).  ccx's round-off floor here is ~2e-9 relative;
# 1e-8 is about as tight as it converges (1e-10 never converges).
DEFAULT_RAN = 1.0e-8
SWEEP_SLOPES = [1e5, 1e6, 1e7, 1e8, 1e9]


def neo_hooke(E, nu):
    mu = E / (2.0 * (1.0 + nu))
    K = E / (3.0 * (1.0 - 2.0 * nu))
    return mu / 2.0, 2.0 / K  # C10, D1


def cells_of(mesh, name, ctype):
    """All cells of type ctype in physical group `name` (meshio cell_sets)."""
    out = []
    for block, idx in zip(mesh.cells, mesh.cell_sets[name]):
        if block.type == ctype and idx is not None and len(idx):
            out.append(block.data[np.asarray(idx)])
    return np.concatenate(out) if out else np.zeros((0,), int)


def hex_volume_sign(x):
    """Sign of the Jacobian at the centre of an 8-node hex (x: 8x3)."""
    d_xi = (x[1] + x[2] + x[5] + x[6] - x[0] - x[3] - x[4] - x[7]) / 4
    d_et = (x[2] + x[3] + x[6] + x[7] - x[0] - x[1] - x[4] - x[5]) / 4
    d_ze = (x[4] + x[5] + x[6] + x[7] - x[0] - x[1] - x[2] - x[3]) / 4
    return np.sign(np.dot(np.cross(d_xi, d_et), d_ze))


def build_model(mesh_path=MESH):
    with contextlib.redirect_stdout(io.StringIO()):  # meshio prints a blank line
        mesh = meshio.read(str(mesh_path))
    pts = np.asarray(mesh.points, float)
    lower = cells_of(mesh, "lower", "hexahedron")
    upper = cells_of(mesh, "upper", "hexahedron")
    hexes = np.concatenate([lower, upper])  # ccx element ids 1..n, lower first
    for h in hexes:
        assert hex_volume_sign(pts[h]) > 0, "inverted hex"
    elem_block = ["lower"] * len(lower) + ["upper"] * len(upper)

    # element faces keyed by their node set
    face_index = {}
    for e, h in enumerate(hexes):
        for f, loc in HEX_FACES.items():
            key = frozenset(int(h[i - 1]) for i in loc)
            face_index.setdefault(key, []).append((e + 1, f))

    def surface(name, block):
        faces = []
        for q in cells_of(mesh, name, "quad"):
            hits = [ef for ef in face_index[frozenset(int(n) for n in q)]
                    if elem_block[ef[0] - 1] == block]
            assert len(hits) == 1, (name, q, hits)
            faces.append(hits[0])
        return sorted(faces)

    def nodes(name, ctype):
        c = cells_of(mesh, name, ctype)
        return sorted({int(n) + 1 for n in np.ravel(c)})

    model = dict(
        points=pts,
        hexes=hexes + 1,
        n_lower=len(lower),
        master=surface("lower_top", "lower"),
        slave=surface("upper_bottom", "upper"),
        base=nodes("lower_base", "quad"),
        slave_nodes=nodes("upper_bottom", "quad"),
        load=nodes("load_node", "vertex"),
        axis=nodes("upper_axis", "vertex"),
        twist=nodes("upper_twist", "vertex"),
    )
    assert len(model["load"]) == 1 and len(model["axis"]) == 2 and len(model["twist"]) == 1
    return model


def write_deck(model, path, slope, force, tension, ran=DEFAULT_RAN):
    pts, hexes, nl = model["points"], model["hexes"], model["n_lower"]
    c10u, d1u = neo_hooke(E_UPPER, NU)
    c10l, d1l = neo_hooke(E_LOWER, NU)
    L = []
    w = L.append
    w("** GENERATED by tests/ccx/parisch.py from meshes/parisch.msh -- do not edit;")
    w("** regenerate with: .venv/bin/python tests/ccx/parisch.py")
    w("** Parisch two-block contact: C3D8, neo-Hookean (dev/vol), NLGEOM,")
    w("** frictionless node-to-surface penalty contact (ccx 2.20).")
    w("** slope K = %s, tension sigma_inf = %s, Fz = %s on the load node" % (fmt(slope), fmt(tension), fmt(force)))
    w("*HEADING")
    w("Parisch two-block contact (splinecontact reference)")
    w("*NODE, NSET=NALL")
    for i, p in enumerate(pts):
        w("%d, %s, %s, %s" % (i + 1, fmt(p[0]), fmt(p[1]), fmt(p[2])))
    for name, rng in (("ELOWER", range(0, nl)), ("EUPPER", range(nl, len(hexes)))):
        w("*ELEMENT, TYPE=C3D8, ELSET=%s" % name)
        for e in rng:
            w("%d, %s" % (e + 1, ", ".join(str(int(n)) for n in hexes[e])))
    for name, key in (("NBASE", "base"), ("NLOAD", "load"), ("NAXIS", "axis"),
                      ("NTWIST", "twist"), ("NSLAVE", "slave_nodes")):
        w("*NSET, NSET=%s" % name)
        ids = model[key]
        for k in range(0, len(ids), 8):
            w(", ".join(str(n) for n in ids[k:k + 8]))
    w("*SURFACE, NAME=SMASTER, TYPE=ELEMENT")
    for e, f in model["master"]:
        w("%d, S%d" % (e, f))
    w("*SURFACE, NAME=SSLAVE, TYPE=ELEMENT")
    for e, f in model["slave"]:
        w("%d, S%d" % (e, f))
    w("** C10 = mu/2, D1 = 2/K; E = %s (lower), %s (upper), nu = %s" % (fmt(E_LOWER), fmt(E_UPPER), fmt(NU)))
    w("*MATERIAL, NAME=MLOWER")
    w("*HYPERELASTIC, NEO HOOKE")
    w("%s, %s" % (fmt(c10l), fmt(d1l)))
    w("*MATERIAL, NAME=MUPPER")
    w("*HYPERELASTIC, NEO HOOKE")
    w("%s, %s" % (fmt(c10u), fmt(d1u)))
    w("*SOLID SECTION, ELSET=ELOWER, MATERIAL=MLOWER")
    w("*SOLID SECTION, ELSET=EUPPER, MATERIAL=MUPPER")
    w("*SURFACE INTERACTION, NAME=SI")
    w("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR")
    w("%s, %s" % (fmt(slope), fmt(tension)))
    w("*CONTACT PAIR, INTERACTION=SI, TYPE=NODE TO SURFACE")
    w("SSLAVE, SMASTER")
    w("*BOUNDARY")
    w("NBASE, 1, 3")
    w("NAXIS, 1, 2")
    w("NTWIST, 1, 1")
    w("*STEP, NLGEOM, INC=1000")
    w("*STATIC")
    w("1., 1.")
    w("*CONTROLS, PARAMETERS=FIELD")
    w("%s, %s, , , , 1.e-14" % (fmt(ran), fmt(ran)))
    w("*CLOAD")
    w("NLOAD, 3, %s" % fmt(force))
    w("*NODE PRINT, NSET=NLOAD")
    w("U")
    w("*NODE PRINT, NSET=NSLAVE")
    w("U")
    w("*NODE PRINT, NSET=NBASE, TOTALS=ONLY")
    w("RF")
    w("*NODE PRINT, NSET=NAXIS")
    w("RF")
    w("*NODE PRINT, NSET=NTWIST")
    w("RF")
    w("*CONTACT PRINT")
    w("CSTR")
    w("*END STEP")
    Path(path).write_text("\n".join(L) + "\n")


# ---------------------------------------------------------------- .dat parsing


def parse_dat(text):
    """Blocks of a ccx .dat: {header line: [rows of floats]}.  Every text line
    starts a new block; a header with a time stamp names the result set, other
    text lines (e.g. under contact statistics) get it as prefix."""
    blocks, cur, main = {}, None, ""
    for line in text.splitlines():
        s = line.strip()
        if not s:
            continue
        if re.fullmatch(r"(%s\s*)+" % NUM, s):
            if cur is not None:
                blocks[cur].append([float(t.replace("D", "E")) for t in s.split()])
            continue
        if " time " in s:
            main = s
            cur = s
        else:
            cur = main + " / " + s
        blocks[cur] = []
    return blocks


def find(blocks, *words):
    hits = [k for k in blocks if all(wd.lower() in k.lower() for wd in words)]
    return blocks[hits[-1]] if hits else None


def parse_sta(text):
    """(increments, total iterations, per-increment iterations) from .sta."""
    incs, iters = 0, []
    for line in text.splitlines():
        t = line.split()
        if len(t) >= 7 and t[0].isdigit() and t[1].isdigit():
            incs += 1
            iters.append(int(t[3]))
    return incs, iters


def slave_areas(model, disp=None):
    """Tributary area of each slave node: a quarter of each adjacent slave face
    (ccx gencontelem_n2f: areaslav/number of face nodes), with the faces in the
    configuration X + disp (ccx evaluates them in the current configuration)."""
    pts, hexes = model["points"], model["hexes"]
    area = {}
    for e, f in model["slave"]:
        ids = [int(hexes[e - 1][i - 1]) for i in HEX_FACES[f]]
        x = np.array([pts[n - 1] + (disp[n] if disp else 0.0) for n in ids])
        # bilinear quad area, 2x2 Gauss
        a = 0.0
        g = 1.0 / np.sqrt(3.0)
        for xi in (-g, g):
            for et in (-g, g):
                dxi = 0.25 * (-(1 - et) * x[0] + (1 - et) * x[1] + (1 + et) * x[2] - (1 + et) * x[3])
                det = 0.25 * (-(1 - xi) * x[0] - (1 + xi) * x[1] + (1 + xi) * x[2] + (1 - xi) * x[3])
                a += np.linalg.norm(np.cross(dxi, det))
        for n in ids:
            area[n] = area.get(n, 0.0) + a / 4.0
    return area


def run_ccx(model, slope, force, tension, ccx="ccx", keep=None, ran=DEFAULT_RAN):
    work = Path(tempfile.mkdtemp(prefix="parisch_ccx_"))
    failed = False
    try:
        job = work / "parisch"
        write_deck(model, str(job) + ".inp", slope, force, tension, ran)
        env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "1"))
        p = subprocess.run([ccx, "-i", "parisch"], cwd=work, env=env,
                           capture_output=True, text=True)
        log = p.stdout + p.stderr
        if p.returncode != 0 or "*ERROR" in log or "Job finished" not in log:
            sys.stderr.write(log[-4000:])
            failed = True
            raise RuntimeError("ccx failed (rc=%d), see %s" % (p.returncode, work))
        dat = (work / "parisch.dat").read_text()
        sta = (work / "parisch.sta").read_text() if (work / "parisch.sta").exists() else ""
        cvg = (work / "parisch.cvg").read_text() if (work / "parisch.cvg").exists() else ""
        if keep:
            shutil.copytree(work, keep, dirs_exist_ok=True)
    finally:
        if not keep and not failed:
            shutil.rmtree(work, ignore_errors=True)

    b = parse_dat(dat)
    (load_id,) = model["load"]
    u_load = [r for r in find(b, "displacements", "NLOAD") if int(r[0]) == load_id][0][1:4]
    z0 = float(model["points"][load_id - 1][2])
    base_tot = find(b, "total force", "NBASE")
    slave_u = {int(r[0]): np.array(r[1:4]) for r in find(b, "displacements", "NSLAVE")}
    # RF in ccx is the internal nodal force: at an unconstrained dof it equals
    # the applied load (node 20, z), at a constrained dof it is the reaction.
    axis = {int(r[0]): r[1:3] for r in find(b, "forces", "NAXIS")}
    twist = {int(r[0]): r[1:2] for r in find(b, "forces", "NTWIST")}
    press = {int(r[0]): r[1] for r in find(b, "contact stress")}
    a_cur = slave_areas(model, slave_u)
    a_ref = slave_areas(model)
    incs, iters = parse_sta(sta)
    cvg_rows = parse_cvg(cvg)
    m = re.search(r"Version\s+([0-9][0-9.]*[0-9])", log)
    res = dict(
        ccx_version=m.group(1) if m else "?",
        slope=slope, force=force, tension=tension, field_ran=ran,
        load_node=dict(id=load_id, ux=u_load[0], uy=u_load[1], uz=u_load[2], z=z0 + u_load[2]),
        # sum of p_i * A_i, A_i from the deformed slave faces (what ccx uses)
        contact_force_total=sum(press[n] * a_cur[n] for n in press),
        # the same pressures times reference tributary areas
        contact_force_total_ref_area=sum(press[n] * a_ref[n] for n in press),
        base_reaction_total=base_tot[-1] if base_tot else None,
        axis_reactions_xy={n: v for n, v in sorted(axis.items())},
        twist_reaction_x={n: v[0] for n, v in twist.items()},
        slave_pressure={n: press[n] for n in sorted(press)},
        slave_uz={n: float(v[2]) for n, v in sorted(slave_u.items())},
        increments=incs, iterations_per_increment=iters,
        cvg=[dict(inc=int(r[1]), att=int(r[2]), it=int(r[3]), contel=int(r[4]),
                  resid_pct=r[5], corr_pct=r[6]) for r in cvg_rows],
    )
    return res, dat


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--slope", type=float, default=DEFAULT_SLOPE)
    ap.add_argument("--force", type=float, default=DEFAULT_FORCE)
    ap.add_argument("--tension", type=float, default=DEFAULT_TENSION)
    ap.add_argument("--model", choices=["devvol"], default="devvol",
                    help="only the dev/vol neo-Hookean exists in ccx")
    ap.add_argument("--ran", type=float, default=DEFAULT_RAN,
                    help="*CONTROLS FIELD R_n = C_n (default %(default)g)")
    ap.add_argument("--out", default=str(DEFAULT_OUT))
    ap.add_argument("--ccx", default=shutil.which("ccx") or "/usr/bin/ccx")
    ap.add_argument("--keep", default=None, help="copy the ccx run directory here")
    ap.add_argument("--run", action="store_true")
    ap.add_argument("--sweep", action="store_true")
    ap.add_argument("--dat", action="store_true", help="with --run: also print the .dat")
    a = ap.parse_args(argv)

    model = build_model()
    write_deck(model, a.out, a.slope, a.force, a.tension, a.ran)
    if a.run:
        res, dat = run_ccx(model, a.slope, a.force, a.tension, a.ccx, a.keep, a.ran)
        print(json.dumps(res, indent=1))
        if a.dat:
            print(dat)
    if a.sweep:
        rows = []
        for k in SWEEP_SLOPES:
            res, _ = run_ccx(model, k, a.force, a.tension, a.ccx, ran=a.ran)
            rows.append(dict(slope=k, uz=res["load_node"]["uz"],
                             contact_force_total=res["contact_force_total"],
                             base_reaction_z=res["base_reaction_total"][2],
                             increments=res["increments"],
                             iterations=res["iterations_per_increment"]))
        print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
