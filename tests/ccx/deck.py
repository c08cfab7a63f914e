#!/usr/bin/env python3
"""CalculiX (ccx 2.20) deck from one of our pipelines: same mesh, loads, supports,
material and contact, for an independent reference solution.

Reads PIPELINE.yaml, follows its chosen `solve` stage back through `tag` (contact
pairs) and `import` (the gmsh .msh), reads the mesh with the gmsh Python API (node
and element tags, physical groups), and writes DIR/<name>.inp, <name> being the stem
of the solve stage's `output`.  ccx node numbers are the gmsh node tags and ccx
element numbers the gmsh element tags, so results map 1:1 onto our .scres/.vtu
(point data `gmsh_node_tag`).  With --run it runs ccx in DIR, writes
DIR/<name>_u.csv (tag, ux, uy, uz at the last increment) and DIR/<name>.json, and
prints a summary (the JSON with --json).

Usage (from the repository root):
    .venv/bin/python tests/ccx/deck.py pipelines/parisch.yaml --run
    .venv/bin/python tests/ccx/deck.py pipelines/curved.yaml --solve 1 --run --json
    .venv/bin/python tests/ccx/deck.py pipelines/cantilever.yaml --run --compare
Options: --out DIR (default: <pipeline folder>/out/ccx), --solve N (which solve
stage, 0-based, default 0), --msh FILE (instead of the pipeline's mesh), --slope K (contact penalty slope for every pair; default
eps_n for penalty, 100 x eps_n for augmented_lagrangian), --tension S (ccx sigma_inf,
1e-6), --ran R (*CONTROLS FIELD R_n = C_n, default the setup's
newton.residual_tolerance), --direct (fixed increments, no ccx cutbacks), --contact
node|surface (NODE TO SURFACE, default, or SURFACE TO SURFACE), --compare
[PVD|VTU] (our result at the last increment; without a file, the .pvd the pipeline
exports from this solve), --ccx PATH, --json.

How each feature maps, and the limits: tests/ccx/README.md, "deck.py".
"""
import argparse
import contextlib
import csv
import io
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import yaml

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent

DEFAULT_TENSION = 1.0e-6   # ccx sigma_inf (see README: regularised linear law)
AL_SLOPE_FACTOR = 100.0    # augmented Lagrangian -> penalty slope = this x eps_n

# ccx C3D8 faces (ccx source, array ifaceq; 1-based local nodes), each ordered so the
# right-hand rule gives the outward normal.  gmsh hex8 order == ccx C3D8 order.
HEX_FACES = {
    1: (4, 3, 2, 1),
    2: (5, 6, 7, 8),
    3: (1, 2, 6, 5),
    4: (2, 3, 7, 6),
    5: (3, 4, 8, 7),
    6: (4, 1, 5, 8),
}
GMSH_HEX8, GMSH_QUAD4 = 5, 3
DOF = {"x": 1, "y": 2, "z": 3}


class DeckError(Exception):
    pass


class Yaml12Loader(yaml.SafeLoader):
    """PyYAML reads YAML 1.1, where 1.0e9 (no sign in the exponent) is a string;
    serde_yaml (ours) reads it as a number.  Resolve floats the YAML 1.2 way."""


Yaml12Loader.yaml_implicit_resolvers = {k: [r for r in v if r[0] != "tag:yaml.org,2002:float"]
                                        for k, v in yaml.SafeLoader.yaml_implicit_resolvers.items()}
Yaml12Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"""^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?
                 |[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$""", re.X),
    list("-+0123456789."))


def load_yaml(text):
    return yaml.load(text, Loader=Yaml12Loader)


def fmt(x):
    """A float field ccx reads with (f20.0): at most 20 characters."""
    s = repr(float(x))
    if len(s) > 20:
        s = "%.13e" % x
    assert len(s) <= 20, s
    return s


def shown(path):
    """A path for messages and the deck header: relative to the repository when
    inside it (so the deck does not depend on where the repository lives)."""
    p = Path(path).resolve()
    try:
        return str(p.relative_to(ROOT))
    except ValueError:
        return str(p)


# ------------------------------------------------------------------ pipeline
def stage_list(pipe):
    out = []
    for st in pipe.get("stages", []):
        if not isinstance(st, dict) or len(st) != 1:
            raise DeckError("a stage must be a map with one key, found %r" % (st,))
        (kind, body), = st.items()
        out.append((kind, body or {}))
    return out


def resolve_pipeline(path, solve_index=0, msh_override=None):
    """(pipeline, solve stage, setup, msh path, contact pairs, pvd of our result)."""
    path = Path(path).resolve()
    base = path.parent
    pipe = load_yaml(path.read_text())
    stages = stage_list(pipe)
    rel = lambda p: (base / p).resolve()
    solves = [b for k, b in stages if k == "solve"]
    if not solves:
        raise DeckError("%s has no solve stage" % shown(path))
    if not 0 <= solve_index < len(solves):
        raise DeckError("%s has %d solve stage(s); --solve %d is out of range" % (shown(path), len(solves), solve_index))
    solve = solves[solve_index]
    if ("setup" in solve) == ("setup_file" in solve):
        raise DeckError("solve stage %d: give exactly one of setup, setup_file" % solve_index)
    setup = solve["setup"] if "setup" in solve else load_yaml(rel(solve["setup_file"]).read_text())
    producers = {rel(b["output"]): (k, b) for k, b in stages if "output" in b}
    src = rel(solve["input"])
    pairs = []
    if src.suffix == ".sccontact":
        k, tag = producers.get(src, (None, None))
        if k != "tag":
            raise DeckError("no tag stage writes %s" % shown(src))
        pairs = tag["pairs"]
        src = rel(tag["input"])
    k, imp = producers.get(src, (None, None))
    if k != "import":
        raise DeckError("no import stage writes %s" % shown(src))
    msh = Path(msh_override).resolve() if msh_override else rel(imp["input"])
    if not msh.exists():
        k, _ = producers.get(msh, (None, None))
        hint = " (it is written by the pipeline's %s stage: run the pipeline first)" % k if k else ""
        raise DeckError("mesh %s does not exist%s" % (shown(msh), hint))
    res = rel(solve["output"])
    pvd = None
    for k, b in stages:
        if k == "export" and rel(b["input"]) == res and str(b["output"]).endswith((".pvd", ".vtu")):
            pvd = rel(b["output"])
    name = Path(solve["output"]).stem
    return dict(pipeline=path, pipe=pipe, solve_index=solve_index, n_solves=len(solves),
                solve=solve, setup=setup, msh=msh, pairs=pairs, pvd=pvd, name=name)


# ---------------------------------------------------------------------- mesh
def corner_jacobians(x):
    """Jacobian determinant at the 8 corners of a hex8 (x: 8x3, gmsh order)."""
    nb = {0: (1, 3, 4), 1: (2, 0, 5), 2: (3, 1, 6), 3: (0, 2, 7),
          4: (7, 5, 0), 5: (4, 6, 1), 6: (5, 7, 2), 7: (6, 4, 3)}
    return [float(np.dot(np.cross(x[a] - x[i], x[b] - x[i]), x[c] - x[i])) for i, (a, b, c) in nb.items()]


def read_mesh(msh):
    """The .msh as sc-import sees it: hexes (tag, nodes, body), node sets per physical
    group (hex nodes only), face sets per physical surface (quads)."""
    import gmsh
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(str(msh))
        ntags, coords, _ = gmsh.model.mesh.getNodes()
        coords = np.asarray(coords, float).reshape(-1, 3)
        xyz = {int(t): coords[i] for i, t in enumerate(ntags)}
        names = {}
        for dim, tag in gmsh.model.getPhysicalGroups():
            names[(dim, tag)] = gmsh.model.getPhysicalName(dim, tag) or "physical_%d_%d" % (dim, tag)
        hexes, hex_body = [], []
        other3d = {}
        for _, ent in gmsh.model.getEntities(3):
            phys = [t for t in gmsh.model.getPhysicalGroupsForEntity(3, ent)]
            body = names[(3, phys[0])] if phys else "unnamed_volume"
            types, etags, enodes = gmsh.model.mesh.getElements(3, ent)
            for ty, et, en in zip(types, etags, enodes):
                if ty != GMSH_HEX8:
                    other3d[ty] = other3d.get(ty, 0) + len(et)
                    continue
                en = np.asarray(en, np.int64).reshape(-1, 8)
                for t, row in zip(et, en):
                    hexes.append((int(t), [int(n) for n in row]))
                    hex_body.append(body)
        if other3d:
            raise DeckError("%s: only 8-node hexahedra are volume elements; found gmsh types %s" % (shown(msh), other3d))
        groups = {}
        for (dim, tag), name in sorted(names.items()):
            nodes, quads = set(), []
            for ent in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                types, etags, enodes = gmsh.model.mesh.getElements(dim, ent)
                for ty, et, en in zip(types, etags, enodes):
                    nodes.update(int(n) for n in en)
                    if dim == 2:
                        if ty != GMSH_QUAD4:
                            raise DeckError("physical surface %s holds gmsh element type %d (only quads make face sets)" % (name, ty))
                        en = np.asarray(en, np.int64).reshape(-1, 4)
                        quads += [(int(t), [int(n) for n in row]) for t, row in zip(et, en)]
            groups[name] = dict(dim=dim, tag=tag, nodes=nodes, quads=quads)
    finally:
        gmsh.finalize()
    # mirrored hexes: swap bottom and top (as sc-import does); twisted: refuse
    flipped = []
    for k, (t, h) in enumerate(hexes):
        j = corner_jacobians(np.array([xyz[n] for n in h]))
        if all(v < 0 for v in j):
            hexes[k] = (t, h[4:] + h[:4])
            flipped.append(t)
        elif not all(v > 0 for v in j):
            raise DeckError("hexahedron %d is twisted (corner Jacobians of mixed sign)" % t)
    used = sorted({n for _, h in hexes for n in h})
    used_set = set(used)
    node_sets = {name: sorted(g["nodes"] & used_set) for name, g in groups.items()}
    # face sets: each quad to the hex face with the same 4 nodes
    by_node = {}
    for e, (t, h) in enumerate(hexes):
        for n in h:
            by_node.setdefault(n, []).append(e)
    face_sets = {}
    for name, g in groups.items():
        if g["dim"] != 2:
            continue
        faces = []
        for qt, q in g["quads"]:
            cands = []
            for e in by_node.get(q[0], []):
                h = hexes[e][1]
                for f, loc in HEX_FACES.items():
                    fn = [h[i - 1] for i in loc]
                    if set(fn) == set(q):
                        cands.append((e, f, fn))
            if not cands:
                raise DeckError("physical surface %s: quad %d is no hexahedron face" % (name, qt))
            chosen = cands[0]
            if len(cands) > 1:  # interior face: the hex whose outward face runs like the quad
                agree = [c for c in cands if same_cycle(c[2], q)]
                if len(agree) == 1:
                    chosen = agree[0]
            e, f, fn = chosen
            faces.append((hexes[e][0], f, fn))
        face_sets[name] = faces
    return dict(xyz=xyz, hexes=hexes, hex_body=hex_body, used=used, node_sets=node_sets,
                face_sets=face_sets, groups=groups, flipped=flipped)


def same_cycle(face, quad):
    if quad[0] not in face:
        return False
    p = face.index(quad[0])
    return all(quad[k] == face[(p + k) % 4] for k in range(4))


def quad_area(x):
    """Bilinear quad area, 2x2 Gauss (x: 4x3)."""
    a, g = 0.0, 1.0 / math.sqrt(3.0)
    for xi in (-g, g):
        for et in (-g, g):
            dxi = 0.25 * (-(1 - et) * x[0] + (1 - et) * x[1] + (1 + et) * x[2] - (1 + et) * x[3])
            det = 0.25 * (-(1 - xi) * x[0] - (1 + xi) * x[1] + (1 + xi) * x[2] + (1 - xi) * x[3])
            a += np.linalg.norm(np.cross(dxi, det))
    return a


def tributary_areas(faces, xyz, U=None):
    """Node -> a quarter of the area of each adjacent face (ccx gencontelem_n2f:
    areaslav / nodes per face); faces are node lists, taken at X + U."""
    U, area = U or {}, {}
    for fn in faces:
        a = quad_area(np.array([xyz[n] + U.get(n, 0.0) for n in fn]))
        for n in fn:
            area[n] = area.get(n, 0.0) + a / 4
    return area


# --------------------------------------------------------------------- setup
def lame(m):
    """(E, nu, mu, K) of a material entry given as E, nu or lambda, mu."""
    if m.get("E") is not None and m.get("nu") is not None:
        E, nu = float(m["E"]), float(m["nu"])
        mu, lam = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    elif m.get("lambda") is not None and m.get("mu") is not None:
        lam, mu = float(m["lambda"]), float(m["mu"])
        E, nu = mu * (3 * lam + 2 * mu) / (lam + mu), lam / (2 * (lam + mu))
    else:
        raise DeckError("material of body %s: give E and nu, or lambda and mu" % m.get("body"))
    return E, nu, mu, lam + 2 * mu / 3


def load_factors(inc):
    inc = inc or {}
    if inc.get("factors") is not None:
        if inc.get("count") is not None:
            raise DeckError("increments: give count or factors, not both")
        f = [float(x) for x in inc["factors"]]
        if not f or any(x <= 0 for x in f) or any(b <= a for a, b in zip(f, f[1:])):
            raise DeckError("increments.factors must be positive and increasing: %r" % f)
        return f
    n = int(inc.get("count", 1))
    end = float(inc.get("end", 1.0))
    if n < 1 or not end > 0:
        raise DeckError("increments: count >= 1 and end > 0 needed")
    return [end * i / n for i in range(1, n + 1)]


class Names:
    """ccx names (uppercase letters, digits, _; at most 80 characters), unique."""

    def __init__(self):
        self.taken = {}

    def get(self, prefix, name):
        key = (prefix, name)
        if key in self.taken:
            return self.taken[key]
        base = (prefix + re.sub(r"[^A-Za-z0-9_]", "_", name)).upper()[:70]
        out, k = base, 1
        while out in self.taken.values():
            k += 1
            out = "%s_%d" % (base, k)
        self.taken[key] = out
        return out


def ids_lines(ids, per=8):
    ids = list(ids)
    return [", ".join(str(n) for n in ids[k:k + per]) for k in range(0, len(ids), per)]


# ---------------------------------------------------------------------- deck
def build_deck(P, mesh, slope_override=None, tension=DEFAULT_TENSION, ran=None, direct=False, ctype="node"):
    """The deck text and a description of the model (for running and parsing)."""
    setup = P["setup"]
    names = Names()
    L, notes = [], []
    w = L.append
    factors = load_factors(setup.get("increments"))
    T = factors[-1]
    max_cut = int((setup.get("increments") or {}).get("max_cutbacks", 5))
    newton = setup.get("newton") or {}
    max_it = int(newton.get("max_iterations", 25))
    ran = float(ran if ran is not None else newton.get("residual_tolerance", 1e-8))
    xyz, hexes = mesh["xyz"], mesh["hexes"]
    node_sets, face_sets = mesh["node_sets"], mesh["face_sets"]

    def nset(name):
        if name not in node_sets:
            raise DeckError("unknown node set %r (the mesh has: %s)" % (name, ", ".join(sorted(node_sets))))
        if not node_sets[name]:
            raise DeckError("node set %r has no hexahedron nodes" % name)
        return node_sets[name]

    def fset(name):
        if name not in face_sets:
            raise DeckError("unknown face set %r (the mesh has: %s)" % (name, ", ".join(sorted(face_sets))))
        return face_sets[name]

    # ---- materials
    mats = {m["body"]: m for m in setup.get("materials", [])}
    bodies = sorted(set(mesh["hex_body"]), key=lambda b: mesh["hex_body"].index(b))
    for b in bodies:
        if b not in mats:
            raise DeckError("body %s has no material" % b)
    for b in mats:
        if b not in bodies:
            raise DeckError("material for unknown body %s (the mesh has: %s)" % (b, ", ".join(bodies)))
    models = {mats[b]["model"] for b in bodies}
    nlgeom = models != {"linear_elastic"}
    mat_lines, mat_desc = [], []
    for b in bodies:
        m = mats[b]
        E, nu, mu, K = lame(m)
        eset, mname = names.get("E_", b), names.get("M_", b)
        mat_lines += ["*MATERIAL, NAME=%s" % mname]
        if m["model"] in ("neo_hookean", "neo_hookean_dev_vol"):
            c10, d1 = mu / 2, 2 / K
            mat_lines += ["*HYPERELASTIC, NEO HOOKE", "%s, %s" % (fmt(c10), fmt(d1))]
            how = ("*HYPERELASTIC, NEO HOOKE" if m["model"] == "neo_hookean_dev_vol" else
                   "*HYPERELASTIC, NEO HOOKE (dev/vol; ccx has no Ciarlet-Simo form: the closest,"
                   " same small-strain E and nu, different volumetric response at finite strain)")
            mat_desc.append("%s: %s E = %s, nu = %s -> %s, C10 = mu/2 = %s, D1 = 2/K = %s"
                            % (b, m["model"], fmt(E), fmt(nu), how, fmt(c10), fmt(d1)))
        elif m["model"] == "linear_elastic":
            mat_lines += ["*ELASTIC", "%s, %s" % (fmt(E), fmt(nu))]
            how = "*ELASTIC" + (" (NLGEOM is on for the other bodies: here St Venant-Kirchhoff, not"
                                " small-strain)" if nlgeom else ", no NLGEOM")
            mat_desc.append("%s: linear_elastic E = %s, nu = %s -> %s" % (b, fmt(E), fmt(nu), how))
            if nlgeom:
                notes.append("body %s is linear_elastic but NLGEOM is on (other bodies are hyperelastic)" % b)
        else:
            raise DeckError("unknown material model %r" % m["model"])
        mat_lines += ["*SOLID SECTION, ELSET=%s, MATERIAL=%s" % (eset, mname)]

    # ---- amplitudes: a(t) over the load factor t = ccx total time
    amp_lines, amp_used, amp_tables = [], {}, {}

    def amplitude(curve):
        if curve is None:
            key, pts = "ramp", [[0.0, 0.0], [T, T]]
        else:
            cs = [c for c in setup.get("curves", []) if c["name"] == curve]
            if len(cs) != 1:
                raise DeckError("curve %r is not defined (once) under curves" % curve)
            key, pts = curve, [[float(a), float(b)] for a, b in cs[0]["points"]]
            # constant beyond the ends, as ours; make [0, T] explicit
            if pts[0][0] > 0:
                pts = [[0.0, pts[0][1]]] + pts
            if pts[-1][0] < T:
                pts = pts + [[T, pts[-1][1]]]
        if key not in amp_used:
            an = names.get("A_", key)
            amp_used[key] = an
            amp_tables[an] = pts
            amp_lines.append("*AMPLITUDE, NAME=%s, TIME=TOTAL TIME" % an)
            amp_lines.extend("%s, %s" % (fmt(t), fmt(a)) for t, a in pts)
        return amp_used[key]

    # ---- constraints: last one wins per dof (as ours)
    state, cons_desc, reaction_sets = {}, [], []
    for ci, c in enumerate(setup.get("constraints", [])):
        nodes = nset(c["set"])
        disp = c.get("displacement") or {}
        fix = c.get("fix") or []
        if not fix and not disp:
            raise DeckError("constraint on %s fixes nothing" % c["set"])
        amp = amplitude(c.get("curve")) if disp else None
        for n in nodes:
            for comp in fix:
                state[(n, DOF[comp])] = (ci, "fix", 0.0, None)
            for comp, v in disp.items():
                if v is not None:
                    state[(n, DOF[comp])] = (ci, "disp", float(v), amp)
        desc = []
        if fix:
            desc.append("fix %s" % ",".join(fix))
        if disp:
            desc.append("u = %s, amplitude %s" % (dict(disp), amp))
        cons_desc.append("%s (%d nodes): %s" % (c["set"], len(nodes), "; ".join(desc)))
        if c["set"] not in [r[0] for r in reaction_sets]:
            reaction_sets.append((c["set"], names.get("N_", c["set"])))
    bnd_fix, bnd_amp = [], {}
    for ci, c in enumerate(setup.get("constraints", [])):
        nodes = node_sets[c["set"]]
        sn = names.get("N_", c["set"])
        for kind in ("fix", "disp"):
            comps = sorted({d for (n, d), s in state.items() if s[0] == ci and s[1] == kind})
            for d in comps:
                owned = [n for n in nodes if state[(n, d)][0] == ci and state[(n, d)][1] == kind]
                vals = {state[(n, d)][2:] for n in owned}
                if kind == "fix":
                    fixed_everywhere = all(state[(n, d)][1] == "fix" for n in nodes)
                    if fixed_everywhere:
                        bnd_fix.append("%s, %d, %d" % (sn, d, d))
                    else:
                        bnd_fix += ["%d, %d, %d" % (n, d, d) for n in owned]
                else:
                    ((v, amp),) = vals
                    lines = bnd_amp.setdefault(amp, [])
                    if len(owned) == len(nodes):
                        lines.append("%s, %d, %d, %s" % (sn, d, d, fmt(v)))
                    else:
                        lines += ["%d, %d, %d, %s" % (n, d, d, fmt(v)) for n in owned]

    # ---- loads
    cload, dload, dload_nodes, load_desc = {}, {}, {}, []
    for li, l in enumerate(setup.get("loads", [])):
        if l.get("set") is not None and l.get("force") is not None:
            nodes = nset(l["set"])
            amp = amplitude(l.get("curve"))
            share = 1.0 if l.get("per_node") else 1.0 / len(nodes)
            for n in nodes:
                for k, f in enumerate(l["force"]):
                    if f != 0:
                        cload.setdefault((n, k + 1), {}).setdefault(amp, 0.0)
                        cload[(n, k + 1)][amp] += float(f) * share
            load_desc.append("load %d: force %s on %s (%s, %d nodes) -> *CLOAD per node, amplitude %s"
                             % (li + 1, l["force"], l["set"], "per node" if l.get("per_node") else "total, spread evenly",
                                len(nodes), amp))
        elif l.get("face_set") is not None and l.get("pressure") is not None:
            amp = amplitude(l.get("curve"))
            faces = fset(l["face_set"])
            for e, f, fn in faces:
                dload_nodes[(e, f)] = fn
                dload.setdefault((e, f), {}).setdefault(amp, 0.0)
                dload[(e, f)][amp] += float(l["pressure"])
            load_desc.append("load %d: pressure %s on %s (%d faces) -> *DLOAD Pn (follower under NLGEOM), amplitude %s"
                             % (li + 1, fmt(l["pressure"]), l["face_set"], len(faces), amp))
        else:
            raise DeckError("load %d: give set + force, or face_set + pressure" % (li + 1))
    for key, by_amp in list(cload.items()) + list(dload.items()):
        if len(by_amp) > 1:
            raise DeckError("node/face %s is loaded under two amplitudes %s: ccx keeps one load per dof" % (key, sorted(by_amp)))

    # ---- contact
    contact_lines, contact_desc, pairs_out = [], [], []
    entries = {c["pair"]: c for c in setup.get("contact", [])}
    for p in P["pairs"]:
        if p["name"] not in entries:
            raise DeckError("contact pair %s has no entry under contact" % p["name"])
    for name in entries:
        if name not in [p["name"] for p in P["pairs"]]:
            raise DeckError("contact entry for unknown pair %s" % name)
    for p in P["pairs"]:
        c = entries[p["name"]]
        eps_n = float(c["eps_n"])
        enf = c.get("enforcement", "augmented_lagrangian")
        mu = float(c.get("mu", 0.0) or 0.0)
        master = fset(p["master"])
        sname, mname, iname = names.get("S_", p["name"] + "_slave"), names.get("S_", p["name"] + "_master"), names.get("I_", p["name"])
        slave_faces = face_sets.get(p["slave"])
        if slave_faces is not None:
            contact_lines.append("*SURFACE, NAME=%s, TYPE=ELEMENT" % sname)
            contact_lines += ["%d, S%d" % (e, f) for e, f, _ in slave_faces]
            slave_nodes = sorted({n for _, _, fn in slave_faces for n in fn})
            area_note = "tributary area: a quarter of each adjacent slave face (ccx: current configuration; ours: reference)"
            slope_scale = 1.0
        else:
            slave_nodes = nset(p["slave"])
            contact_lines.append("*SURFACE, NAME=%s, TYPE=NODE" % sname)
            contact_lines += [str(n) for n in slave_nodes]  # one node per line (ccx)
            # ours: A_s = 1 (eps_n is force per penetration per node); ccx: a node of no
            # slave face gets the area of the master face it hits -> divide by the mean.
            a_m = float(np.mean([quad_area(np.array([xyz[n] for n in fn])) for _, _, fn in master]))
            slope_scale = 1.0 / a_m
            area_note = ("node-set slave: ours A_s = 1, ccx uses the master face's area; slope divided by the"
                         " mean master face area %s (exact only for equal master faces)" % fmt(a_m))
            notes.append("pair %s: node-set slave, slope scaled by 1/mean master face area (approximate)" % p["name"])
        contact_lines.append("*SURFACE, NAME=%s, TYPE=ELEMENT" % mname)
        contact_lines += ["%d, S%d" % (e, f) for e, f, _ in master]
        if slope_override is not None:
            K, why = float(slope_override), "--slope"
        elif enf == "penalty":
            K, why = eps_n, "eps_n (penalty)"
        else:
            K, why = AL_SLOPE_FACTOR * eps_n, "%g x eps_n: ccx has no augmented Lagrangian; a stiff penalty stands in" % AL_SLOPE_FACTOR
        K *= slope_scale
        contact_lines += ["*SURFACE INTERACTION, NAME=%s" % iname,
                          "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR", "%s, %s" % (fmt(K), fmt(tension))]
        fric = ""
        if mu > 0:
            if c.get("eps_t") is None:
                raise DeckError("contact pair %s: mu > 0 needs eps_t" % p["name"])
            kt = float(c["eps_t"]) * slope_scale
            contact_lines += ["*FRICTION", "%s, %s" % (fmt(mu), fmt(kt))]
            fric = "; *FRICTION mu = %s, stick slope = eps_t = %s (times the slave area, as ours)" % (fmt(mu), fmt(kt))
        if ctype == "surface" and slave_faces is None:
            raise DeckError("pair %s: SURFACE TO SURFACE needs a face-set slave" % p["name"])
        contact_lines += ["*CONTACT PAIR, INTERACTION=%s, TYPE=%s" % (iname, "NODE TO SURFACE" if ctype == "node" else "SURFACE TO SURFACE"),
                          "%s, %s" % (sname, mname)]
        kind = p.get("master_kind", "bspline")
        contact_desc.append(
            ("" if ctype == "node" else "SURFACE TO SURFACE (--contact surface: ccx face-to-face penalty, pressure at the"
             " slave faces' integration points, not per node as ours); ") +
            "pair %s: slave %s (%d nodes), master %s (%d faces; ours %s%s -> ccx bilinear facets of the same faces);"
            " %s eps_n = %s -> PRESSURE-OVERCLOSURE=LINEAR slope %s (%s), sigma_inf %s; %s%s"
            % (p["name"], p["slave"], len(slave_nodes), p["master"], len(master), kind,
               " %s" % p.get("orders") if kind == "bspline" and p.get("orders") else "",
               enf, fmt(eps_n), fmt(K), why, fmt(tension), area_note, fric))
        if kind == "bspline":
            notes.append("pair %s: B-spline master becomes facets in ccx (same on a flat master; differs on a curved one)" % p["name"])
        if enf != "penalty":
            notes.append("pair %s: augmented Lagrangian -> penalty slope %s (penetration ~ p/K)" % (p["name"], fmt(K)))
        pairs_out.append(dict(name=p["name"], slave_nodes=slave_nodes,
                              slave_faces=[fn for _, _, fn in slave_faces] if slave_faces is not None else None,
                              slave_elems=[e for e, _, _ in slave_faces] if slave_faces is not None else [],
                              slope=K))

    # ---- steps: t = ccx total time; count -> one step, factors -> one step per factor
    if (setup.get("increments") or {}).get("factors") is not None:
        steps = [(b - a, b - a) for a, b in zip([0.0] + factors[:-1], factors)]
        inc_desc = "factors %s -> one *STEP per factor (period = its step in t, one increment each)" % factors
    else:
        dt = factors[0]
        steps = [(dt, T)]
        inc_desc = "count %d, end %s -> one *STEP, period %s, increment %s" % (len(factors), fmt(T), fmt(T), fmt(dt))
    inc_desc += (", DIRECT (fixed, no cutbacks)" if direct else
                 ", automatic with max increment = it and min = it / 2^max_cutbacks (%d) (ccx may cut back like ours)" % max_cut)

    # ---- write
    src_msh = shown(P["msh"])
    w("** GENERATED by tests/ccx/deck.py from %s -- do not edit;" % shown(P["pipeline"]))
    w("** regenerate: .venv/bin/python tests/ccx/deck.py %s%s" % (shown(P["pipeline"]), P.get("options", "")))
    w("** solve stage %d of %d (output %s), mesh %s." % (P["solve_index"], P["n_solves"], P["solve"]["output"], src_msh))
    w("** Mapping of our setup (ccx 2.20):")
    w("** - mesh: C3D8 (full integration hex8, like ours); ccx node/element numbers = gmsh")
    w("**   node/element tags; only nodes of hexahedra; node sets = physical groups'")
    w("**   nodes (N_*), face sets -> element-face surfaces (S_*), bodies -> ELSETs (E_*).")
    if mesh["flipped"]:
        w("**   mirrored hexahedra reordered (bottom/top swapped, as sc-import): %s" % mesh["flipped"][:20])
    w("** - analysis: %s." % ("NLGEOM (total Lagrangian in ccx; our formulation %s)" % setup.get("formulation", "total_lagrangian")
                              if nlgeom else "geometrically linear (no NLGEOM), as our linear_elastic"))
    for d in mat_desc:
        w("** - material %s" % d)
    for d in cons_desc:
        w("** - constraint %s -> *BOUNDARY" % d)
    for d in load_desc:
        w("** - %s" % d)
    w("** - load factor t = ccx total time; amplitudes A_* (TIME=TOTAL TIME): our default")
    w("**   a(t) = t is A_RAMP [[0,0],[T,T]], curves are copied (constant beyond their ends).")
    w("** - increments: %s." % inc_desc)
    w("** - Newton: *CONTROLS FIELD R_n = C_n = %s; at most %d iterations (I_C)," % (fmt(ran), max_it))
    w("**   %d cutbacks per increment (I_A)." % max_cut)
    for d in contact_desc:
        w("** - contact %s" % d)
    for n in notes:
        w("** NOTE: %s" % n)
    w("*HEADING")
    w("%s: ccx reference of %s" % (P["name"], shown(P["pipeline"])))
    w("*NODE, NSET=NALL")
    for n in mesh["used"]:
        p = xyz[n]
        w("%d, %s, %s, %s" % (n, fmt(p[0]), fmt(p[1]), fmt(p[2])))
    for b in bodies:
        w("*ELEMENT, TYPE=C3D8, ELSET=%s" % names.get("E_", b))
        for (t, h), hb in zip(hexes, mesh["hex_body"]):
            if hb == b:
                w("%d, %s" % (t, ", ".join(str(n) for n in h)))
    for s in sorted(node_sets):
        if node_sets[s]:
            w("*NSET, NSET=%s" % names.get("N_", s))
            L.extend(ids_lines(node_sets[s]))
    L.extend(mat_lines)
    L.extend(amp_lines)
    L.extend(contact_lines)

    def step_body(first, dt, period):
        w("*STEP%s, INC=100000" % (", NLGEOM" if nlgeom else ""))
        if direct:
            w("*STATIC, DIRECT")
            w("%s, %s" % (fmt(dt), fmt(period)))
        else:
            w("*STATIC")
            w("%s, %s, %s, %s" % (fmt(dt), fmt(period), fmt(dt / 2 ** max_cut), fmt(dt)))
        w("*CONTROLS, PARAMETERS=FIELD")
        w("%s, %s, , , , 1.e-14" % (fmt(ran), fmt(ran)))
        w("*CONTROLS, PARAMETERS=TIME INCREMENTATION")
        w("4, 8, 9, %d, 10, 4, 0, %d" % (max_it, max(max_cut, 1)))
        if first:
            if bnd_fix:
                w("*BOUNDARY")
                L.extend(bnd_fix)
            for amp in sorted(bnd_amp):
                w("*BOUNDARY, AMPLITUDE=%s" % amp)
                L.extend(bnd_amp[amp])
            for amp in sorted({a for v in cload.values() for a in v}):
                w("*CLOAD, AMPLITUDE=%s" % amp)
                for (n, d) in sorted(cload):
                    if amp in cload[(n, d)]:
                        w("%d, %d, %s" % (n, d, fmt(cload[(n, d)][amp])))
            for amp in sorted({a for v in dload.values() for a in v}):
                w("*DLOAD, AMPLITUDE=%s" % amp)
                for (e, f) in sorted(dload):
                    if amp in dload[(e, f)]:
                        w("%d, P%d, %s" % (e, f, fmt(dload[(e, f)][amp])))
        w("*NODE PRINT, NSET=NALL")
        w("U")
        for s, sn in reaction_sets:
            w("*NODE PRINT, NSET=%s, TOTALS=ONLY" % sn)
            w("RF")
        w("*NODE FILE")
        w("U")
        w("*EL FILE")
        w("S")
        if pairs_out:
            w("*CONTACT PRINT")
            w("CSTR")
        w("*END STEP")

    for k, (dt, period) in enumerate(steps):
        step_body(k == 0, dt, period)
    set_nodes = {sn: node_sets[s] for s, sn in reaction_sets}
    model = dict(name=P["name"], factors=factors, reaction_sets=reaction_sets, pairs=pairs_out,
                 cload=cload, dload=dload, dload_nodes=dload_nodes, amp_tables=amp_tables, set_nodes=set_nodes,
                 notes=notes, used=mesh["used"], xyz=xyz, n_steps=len(steps), nlgeom=nlgeom, ctype=ctype)
    return "\n".join(L) + "\n", model


# ------------------------------------------------------------------ parsing
NUM = r"[-+]?\d+\.?\d*(?:[EeDd][-+]?\d+)?"


def parse_dat(text):
    """Result blocks of a ccx .dat in order: (title, time, rows of floats)."""
    blocks, cur = [], None
    for line in text.splitlines():
        s = line.strip()
        if not s:
            continue
        if re.fullmatch(r"(%s\s*)+" % NUM, s):
            if cur is not None:
                cur[2].append([float(t.replace("D", "E")) for t in s.split()])
            continue
        m = re.search(r"\btime\s+(%s)\s*$" % NUM, s)
        cur = (s, float(m.group(1)) if m else None, [])
        blocks.append(cur)
    return blocks


def parse_sta(text):
    """Rows (step, inc, attempts, iterations, total time) of the .sta file."""
    rows = []
    for line in text.splitlines():
        t = line.split()
        if len(t) >= 7 and t[0].isdigit() and t[1].isdigit():
            # ATT ends in U for an attempt that did not converge (then cut back)
            rows.append(dict(step=int(t[0]), inc=int(t[1]), attempts=int(re.sub(r"\D", "", t[2]) or 0),
                             converged=not t[2].endswith("U"), iterations=int(t[3]), time=float(t[4])))
    return rows


def parse_cvg(text):
    rows = []
    for line in text.splitlines():
        t = line.split()
        if len(t) >= 8 and all(re.fullmatch(NUM, x) for x in t[:8]):
            rows.append([float(x) for x in t[:8]])
    return rows


def amp_at(pts, t):
    """Piecewise linear through pts, constant beyond the ends (ours and ccx)."""
    if t <= pts[0][0]:
        return pts[0][1]
    for (t0, a0), (t1, a1) in zip(pts, pts[1:]):
        if t <= t1:
            return a0 + (a1 - a0) * (t - t0) / (t1 - t0)
    return pts[-1][1]


def pressure_forces(x, p):
    """Consistent nodal forces of a pressure p on a bilinear quad x (4x3, outward
    order): f_a = -p * integral N_a n dA (2x2 Gauss is exact here)."""
    f, g = np.zeros((4, 3)), 1.0 / math.sqrt(3.0)
    for xi in (-g, g):
        for et in (-g, g):
            N = 0.25 * np.array([(1 - xi) * (1 - et), (1 + xi) * (1 - et), (1 + xi) * (1 + et), (1 - xi) * (1 + et)])
            dxi = 0.25 * (-(1 - et) * x[0] + (1 - et) * x[1] + (1 + et) * x[2] - (1 + et) * x[3])
            det = 0.25 * (-(1 - xi) * x[0] - (1 + xi) * x[1] + (1 + xi) * x[2] + (1 - xi) * x[3])
            f -= p * np.outer(N, np.cross(dxi, det))
    return f


def applied(model, set_name, t, U):
    """Sum of the applied forces on a node set at time t: the *CLOADs, and the
    *DLOAD pressures' nodal forces on the faces' current positions X + U."""
    f = np.zeros(3)
    nodes = set(model["set_nodes"][set_name])
    for (n, d), by_amp in model["cload"].items():
        if n in nodes:
            for amp, v in by_amp.items():
                f[d - 1] += v * amp_at(model["amp_tables"][amp], t)
    for (e, face), by_amp in model["dload"].items():
        fn = model["dload_nodes"][(e, face)]
        if nodes.isdisjoint(fn):
            continue
        x = np.array([model["xyz"][n] + (U.get(n, 0.0) if model["nlgeom"] else 0.0) for n in fn])
        for amp, v in by_amp.items():
            fa = pressure_forces(x, v * amp_at(model["amp_tables"][amp], t))
            for k, n in enumerate(fn):
                if n in nodes:
                    f += fa[k]
    return f


def _gnu_time():
    """/usr/bin/time when it is GNU time (its -f and -o), else None."""
    exe = "/usr/bin/time"
    try:
        ok = subprocess.run([exe, "-f", "%M", "-o", os.devnull, "true"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode == 0
    except OSError:
        ok = False
    return exe if ok else None


GNU_TIME = _gnu_time()


def run_with_peak(cmd, cwd, env, stdout):
    """Run cmd as a whole process: (returncode, wall seconds, its peak RSS in MB, exact).

    wait4's ru_maxrss of a child of this Python process is no measure of the child:
    the kernel records the memory's high-water mark at exec, and a child started by
    vfork (subprocess) or fork holds this interpreter's memory until then, so the
    figure starts at Python's own peak (measured: /bin/true "peaks" at 208-211 MB
    under a Python holding 200 MB; 30-55 MB under the comparison script). GNU time
    forks the command from its own small process (1 MB for /bin/true), so with it
    the peak is the command's; it adds about 1 ms to the wall time. Without GNU time
    (Debian's `time` package) the inherited bound is returned, exact = False."""
    import tempfile
    if GNU_TIME:
        with tempfile.NamedTemporaryFile("r", suffix=".peak") as peak:
            # the clock starts once GNU time's output file exists (not the programs' time)
            t0 = time.perf_counter()
            p = subprocess.Popen([GNU_TIME, "-f", "%M", "-o", peak.name, *cmd], cwd=cwd, env=env, stdout=stdout, stderr=subprocess.STDOUT)
            p.wait()
            wall = time.perf_counter() - t0
            # "Command exited with non-zero status N" may come first
            lines = [l for l in open(peak.name).read().split("\n") if l.strip()]
            try:
                kb = float(lines[-1])
            except (IndexError, ValueError):
                kb = float("nan")
        return p.returncode, wall, kb / 1024.0, True
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=stdout, stderr=subprocess.STDOUT)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    return os.waitstatus_to_exitcode(status), wall, usage.ru_maxrss / 1024.0, False


def ccx_job(ccx, cwd, name):
    """Run ccx on cwd/<name>.inp (OMP_NUM_THREADS=1 unless set).  Returns ok, rc, log,
    wall (seconds), peak RSS (MB), version and the .dat, .sta, .cvg texts ('' if absent)."""
    env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "1"))
    with open(cwd / (name + ".stdout"), "w+") as out:
        rc, wall, peak_mb, exact = run_with_peak([ccx, "-i", name], cwd, env, out)   # this process's own peak RSS
        out.seek(0)
        log = out.read()
    m = re.search(r"Version\s+([0-9][0-9.]*[0-9])", log)
    rd = lambda ext: (cwd / (name + ext)).read_text() if (cwd / (name + ext)).exists() else ""
    return dict(ok=rc == 0 and "*ERROR" not in log and "Job finished" in log, rc=rc,
                log=log, wall=wall, peak_rss_mb=peak_mb, peak_exact=exact, version=m.group(1) if m else "?", dat=rd(".dat"), sta=rd(".sta"), cvg=rd(".cvg"))


def run_ccx(deck, model, out, ccx):
    name = model["name"]
    out.mkdir(parents=True, exist_ok=True)
    for ext in (".dat", ".sta", ".cvg", ".frd"):
        (out / (name + ext)).unlink(missing_ok=True)
    job = ccx_job(ccx, out, name)
    log, ok = job["log"], job["ok"]
    (out / (name + ".log")).write_text(log)
    blocks = parse_dat(job["dat"])
    res = dict(pipeline=None, deck=shown(out / (name + ".inp")), ccx_version=job["version"],
               ok=ok, wall_seconds=round(job["wall"], 4), peak_rss_mb=round(job["peak_rss_mb"], 1), notes=model["notes"])
    if not ok:
        err = [l for l in log.splitlines() if "ERROR" in l or "error" in l]
        res["error"] = err[-5:] or log.splitlines()[-5:]
    # per increment: displacement of NALL, reaction totals
    disp = [(t, rows) for s, t, rows in blocks if s.startswith("displacements") and "NALL" in s]
    rf = {}
    for s, t, rows in blocks:
        if s.startswith("total force") or s.startswith("total forces"):
            mset = re.search(r"set\s+(\S+)", s)
            if mset and rows:
                rf.setdefault(t, {})[mset.group(1).upper()] = rows[-1][-3:]
    sta_rows = parse_sta(job["sta"])

    def reaction(total_rf, sn, t, U):
        # ccx RF is the internal nodal force: at a loaded free dof it equals the load.
        # Subtract the applied loads so that the figure is the support reaction (ours:
        # the residual f_int - f_ext summed over the set).
        if total_rf is None:
            return None
        return [float(v) for v in np.array(total_rf) - applied(model, sn, t, U)]
    conv = [r for r in sta_rows if r["converged"]]
    # .sta prints 6 significant digits, .dat 7


    def sta_row(t):
        near = [r for r in conv if abs(r["time"] - t) <= 1e-5 * abs(t)]
        return near[0] if near else {}

    incs = []
    for t, rows in disp:
        u = np.array([r[1:4] for r in rows])
        mag = np.linalg.norm(u, axis=1)
        i = int(np.argmax(mag))
        s = sta_row(t)
        incs.append(dict(time=t, max_u=float(mag[i]), max_u_node=int(rows[i][0]),
                         u_at_max=[float(v) for v in u[i]],
                         converged=bool(s), attempts=s.get("attempts"), iterations=s.get("iterations"),
                         reactions={sname: reaction(rf.get(t, {}).get(sn.upper()), sn, t,
                                                    {int(r[0]): np.array(r[1:4]) for r in rows})
                                    for sname, sn in model["reaction_sets"]}))
    res["increments"] = incs
    res["target_factors"] = model["factors"]
    res["cvg_iterations_total"] = len(parse_cvg(job["cvg"]))
    if disp:
        t, rows = disp[-1]
        U = {int(r[0]): np.array(r[1:4]) for r in rows}
        csv_path = out / (name + "_u.csv")
        with open(csv_path, "w", newline="") as f:
            wr = csv.writer(f)
            wr.writerow(["tag", "ux", "uy", "uz"])
            for n in sorted(U):
                wr.writerow([n] + ["%.7e" % v for v in U[n]])
        res["final"] = dict(time=t, reached_end=abs(t - model["factors"][-1]) < 1e-9 * max(1.0, abs(t)),
                            max_u=incs[-1]["max_u"], max_u_node=incs[-1]["max_u_node"],
                            u_at_max=incs[-1]["u_at_max"], reactions=incs[-1]["reactions"], u_csv=shown(csv_path))
        # contact at the last increment: CSTR rows of the last block, per slave node
        # (node, p, t1, t2) for NODE TO SURFACE, per slave face integration point
        # (element, face, p, t1, t2) for SURFACE TO SURFACE
        cst = [(s, tt, r) for s, tt, r in blocks if s.startswith("contact stress") and tt == t]
        if model["pairs"] and cst:
            rows = cst[-1][2]
            res["contact"] = {}
            for p in model["pairs"]:
                info = dict(slope=p["slope"], slave_nodes=len(p["slave_nodes"]))
                if model["ctype"] == "node":
                    ps = {int(r[0]): r[1] for r in rows if int(r[0]) in set(p["slave_nodes"])}
                    info.update(active=sum(1 for v in ps.values() if v > 0),
                                max_pressure=max(ps.values()) if ps else 0.0)
                    if p["slave_faces"] is not None:
                        area = tributary_areas(p["slave_faces"], model["xyz"], U)
                        # sum of p_i A_i with ccx's (deformed) tributary areas
                        info["normal_force_total"] = float(sum(v * area[n] for n, v in ps.items() if v > 0))
                else:
                    elems = set(p["slave_elems"])
                    ps = [r[2] for r in rows if len(r) >= 5 and int(r[0]) in elems]
                    info.update(integration_points_active=sum(1 for v in ps if v > 0),
                                max_pressure=max(ps) if ps else 0.0)
                res["contact"][p["name"]] = info
    return res


# ------------------------------------------------------------------ compare
def read_ours(path):
    """{gmsh node tag: displacement} at the last time of our .pvd (or a .vtu)."""
    import meshio
    path = Path(path)
    if path.suffix == ".pvd":
        ds = ET.parse(path).getroot().iter("DataSet")
        last = max(ds, key=lambda d: float(d.get("timestep")))
        t, path = float(last.get("timestep")), path.parent / last.get("file")
    else:
        t = None
    with contextlib.redirect_stdout(io.StringIO()):
        m = meshio.read(str(path))
    tags = np.asarray(m.point_data["gmsh_node_tag"]).astype(int)
    u = np.asarray(m.point_data["displacement"], float)
    return t, {int(tg): u[i] for i, tg in enumerate(tags)}, str(path)


def compare(res, csv_path, ours_path):
    t, ours, f = read_ours(ours_path)
    U = {}
    with open(csv_path) as fh:
        for r in csv.DictReader(fh):
            U[int(r["tag"])] = np.array([float(r["ux"]), float(r["uy"]), float(r["uz"])])
    common = sorted(set(U) & set(ours))
    d = np.array([np.linalg.norm(U[n] - ours[n]) for n in common])
    mo = max(common, key=lambda n: np.linalg.norm(ours[n]))
    umax = np.linalg.norm(ours[mo])
    k = int(np.argmax(d))
    return dict(ours=shown(f), ours_time=t, nodes=len(common),
                ours_max_u=float(umax), ours_max_u_node=mo, ours_u_at_max=[float(v) for v in ours[mo]],
                ccx_u_at_that_node=[float(v) for v in U[mo]],
                max_diff=float(d[k]), max_diff_node=common[k], max_diff_rel_to_max_u=float(d[k] / umax) if umax else None,
                rms_diff=float(np.sqrt(np.mean(d ** 2))))


# --------------------------------------------------------------------- main
def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("pipeline")
    ap.add_argument("--out", default=None, help="output folder (default <pipeline folder>/out/ccx)")
    ap.add_argument("--solve", type=int, default=0, help="which solve stage (0-based)")
    ap.add_argument("--run", action="store_true")
    ap.add_argument("--msh", default=None, help="use this .msh instead of the pipeline's (e.g. one a gmsh stage would write)")
    ap.add_argument("--slope", type=float, default=None)
    ap.add_argument("--tension", type=float, default=DEFAULT_TENSION)
    ap.add_argument("--ran", type=float, default=None)
    ap.add_argument("--direct", action="store_true")
    ap.add_argument("--contact", choices=["node", "surface"], default="node",
                    help="ccx contact type: NODE TO SURFACE (like ours, default) or SURFACE TO SURFACE")
    ap.add_argument("--compare", nargs="?", const="auto", default=None)
    ap.add_argument("--ccx", default=shutil.which("ccx") or "/usr/bin/ccx")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    try:
        P = resolve_pipeline(a.pipeline, a.solve, a.msh)
        opts = [("--solve", a.solve, 0), ("--msh", a.msh and shown(a.msh), None), ("--slope", a.slope, None),
                ("--tension", a.tension, DEFAULT_TENSION), ("--ran", a.ran, None), ("--contact", a.contact, "node")]
        P["options"] = "".join(" %s %s" % (k, v) for k, v, d in opts if v != d) + (" --direct" if a.direct else "")
        out = Path(a.out) if a.out else P["pipeline"].parent / "out" / "ccx"
        mesh = read_mesh(P["msh"])
        deck, model = build_deck(P, mesh, a.slope, a.tension, a.ran, a.direct, a.contact)
    except (DeckError, KeyError, TypeError) as e:
        sys.exit("deck.py: %s: %s" % (a.pipeline, e if isinstance(e, DeckError) else "bad pipeline/setup: %r" % (e,)))
    out.mkdir(parents=True, exist_ok=True)
    inp = out / (P["name"] + ".inp")
    inp.write_text(deck)
    if not a.run:
        print(inp)
        return
    res = run_ccx(deck, model, out, a.ccx)
    res["pipeline"] = shown(P["pipeline"])
    res["solve_stage"] = a.solve
    if a.compare and res.get("final"):
        ours = P["pvd"] if a.compare == "auto" else Path(a.compare)
        if ours is None or not Path(ours).exists():
            res["compare"] = "no result of ours found (%s): run the pipeline first" % (shown(ours) if ours else "no export stage")
        else:
            res["compare"] = compare(res, out / (P["name"] + "_u.csv"), ours)
    (out / (P["name"] + ".json")).write_text(json.dumps(res, indent=1) + "\n")
    if a.json:
        print(json.dumps(res, indent=1))
    else:
        print("%s: ccx %s %s in %.2f s; deck %s" % (P["name"], res["ccx_version"], "ok" if res["ok"] else "FAILED",
                                                  res["wall_seconds"], shown(inp)))
        for r in res["increments"]:
            print("  t = %-10.6g max|u| = %.6e at node %d  its %s  reactions %s" % (
                r["time"], r["max_u"], r["max_u_node"], r["iterations"],
                {k: v for k, v in r["reactions"].items()}))
        for k, v in (res.get("contact") or {}).items():
            print("  contact %s: %s" % (k, v))
        if "compare" in res:
            print("  compare: %s" % res["compare"])
        if not res["ok"]:
            print("  error: %s" % res.get("error"))
    if not res["ok"]:
        sys.exit(3)


if __name__ == "__main__":
    main()
