"""Opens every kind of file sc-export and sc-check write with VTK's own reader (the
`vtk` package from PyPI: vtkXMLUnstructuredGridReader, and vtkXMLDataParser for the
.pvd collections, which is what ParaView's PVD reader parses them with) and checks
every array by name, type, size and value against our own numbers, read from the
stage files by tests/py/stagefile.py (an independent reader of docs/formats.md).

usage:
  check_vtk.py mesh MESH.vtu MODEL.scmesh
  check_vtk.py contact MODEL.vtu MODEL.sccontact     (+ MODEL_<pair>_surface.vtu, _net.vtu)
  check_vtk.py results RESULTS.pvd RESULTS.scres     (+ RESULTS_<pair>_surface.pvd series)
  check_vtk.py check CHECK.vtu CHECK.csv
Exits non-zero with the first difference; prints one JSON line on success.

Exact (bit for bit): points, connectivity, cell types, displacements, tags, body and
set arrays, contact and friction state, time values, the master surface's corners
against the control net's corner nodes. To rounding (1e-12 of the largest value):
element and nodal averages of the Gauss-point stresses, von Mises and principal
stresses recomputed here from the stored Gauss-point stresses.
"""
import csv
import json
import math
import os
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
from vtkmodules.vtkIOXMLParser import vtkXMLDataParser

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import stagefile  # noqa: E402

VTK_VERTEX, VTK_LINE, VTK_QUAD, VTK_HEXAHEDRON = 1, 3, 9, 12
# what sc-export writes: VTK XML type -> (numpy kind, bytes)
F64, I32, I64, U8 = ("f", 8), ("i", 4), ("i", 8), ("u", 1)
SUBDIVISIONS = 8  # lib/stages/export.rs


class Grid:
    """A .vtu as VTK's reader sees it."""

    def __init__(self, path):
        assert os.path.isfile(path), f"{path}: missing"
        r = vtkXMLUnstructuredGridReader()
        r.SetFileName(path)
        r.Update()
        assert r.GetErrorCode() == 0, f"{path}: VTK reader error {r.GetErrorCode()}"
        g = r.GetOutput()
        self.path = path
        self.n_points, self.n_cells = g.GetNumberOfPoints(), g.GetNumberOfCells()
        assert self.n_points == r.GetNumberOfPoints() and self.n_cells == r.GetNumberOfCells()
        self.points = vtk_to_numpy(g.GetPoints().GetData())
        assert self.points.dtype == np.float64, f"{path}: points are {self.points.dtype}"
        types = g.GetCellTypes() if hasattr(g, "GetCellTypes") else g.GetCellTypesArray()  # 9.6 renamed it
        self.types = vtk_to_numpy(types)
        self.offsets = vtk_to_numpy(g.GetCells().GetOffsetsArray())
        self.conn = vtk_to_numpy(g.GetCells().GetConnectivityArray())
        self.point = self._arrays(g.GetPointData(), self.n_points)
        self.cell = self._arrays(g.GetCellData(), self.n_cells)

    def _arrays(self, data, n):
        out = {}
        for i in range(data.GetNumberOfArrays()):
            a = data.GetAbstractArray(i)
            assert a.GetNumberOfTuples() == n, f"{self.path}: {a.GetName()} has {a.GetNumberOfTuples()} tuples for {n}"
            v = vtk_to_numpy(a)
            out[a.GetName()] = (v, a.GetNumberOfComponents(), (v.dtype.kind, v.dtype.itemsize))
        return out

    def array(self, where, name, comps, kind):
        arrays = self.point if where == "point" else self.cell
        assert name in arrays, f"{self.path}: no {where} array '{name}' (has {sorted(arrays)})"
        v, c, k = arrays[name]
        assert c == comps, f"{self.path}: {name} has {c} components, expected {comps}"
        assert k == kind, f"{self.path}: {name} is {k}, expected {kind}"
        return v.reshape(-1, comps) if comps > 1 else v

    def cells(self, vtk_type, nodes):
        assert np.all(self.types == vtk_type), f"{self.path}: cell types {np.unique(self.types)}, expected all {vtk_type}"
        assert np.array_equal(self.offsets, np.arange(self.n_cells + 1) * nodes), f"{self.path}: offsets"
        return self.conn.reshape(-1, nodes)


def same(a, b, what):
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, f"{what}: shape {a.shape} against {b.shape}"
    assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f" and b.dtype.kind == "f"), \
        f"{what}: differs at {np.argwhere(~((a == b) | (np.isnan(a) & np.isnan(b)) if a.dtype.kind == 'f' else a != b))[:5].tolist()}"


def close(a, b, what, rel=1e-12):
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, f"{what}: shape {a.shape} against {b.shape}"
    scale = max(np.abs(b).max(initial=0.0), 1e-300)
    err = np.abs(a - b).max(initial=0.0) / scale
    assert err <= rel, f"{what}: differs by {err:.3e} of its largest value"


def check_mesh_arrays(g, m, what):
    """The mesh part of any model .vtu: points, hexahedra, body, tags, node sets."""
    same(g.points, m["nodes"], f"{what}: points")
    same(g.cells(VTK_HEXAHEDRON, 8), m["hexes"].astype(np.int64), f"{what}: hexahedra")
    same(g.array("cell", "body", 1, I32), m["hex_body"].astype(np.int32), f"{what}: body")
    same(g.array("cell", "gmsh_element_tag", 1, I64), m["element_tags"].astype(np.int64), f"{what}: gmsh_element_tag")
    same(g.array("point", "gmsh_node_tag", 1, I64), m["node_tags"].astype(np.int64), f"{what}: gmsh_node_tag")
    for name, nodes in m["node_sets"].items():
        expect = np.zeros(len(m["nodes"]), np.uint8)
        expect[nodes] = 1
        same(g.array("point", f"set:{name}", 1, U8), expect, f"{what}: set:{name}")
    sets = sorted(k for k in g.point if k.startswith("set:"))
    assert sets == sorted(f"set:{s}" for s in m["node_sets"]), f"{what}: set arrays {sets}"


def cmd_mesh(vtu, scmesh):
    fmt, records = stagefile.read(scmesh)
    assert fmt == "scmesh", fmt
    m = stagefile.mesh(records)
    g = Grid(vtu)
    check_mesh_arrays(g, m, vtu)
    assert sorted(g.cell) == ["body", "gmsh_element_tag"], sorted(g.cell)
    return {"points": g.n_points, "hexes": g.n_cells, "point_arrays": len(g.point), "bodies": m["bodies"]}


def spans(pair):
    b, a = pair["net"].shape
    if pair["master_kind"] == "facet":
        return a - 1, b - 1
    ka, kb = pair["orders"]
    return a - ka + 1, b - kb + 1


def check_surface(path, pair, x_net):
    """The tessellated master surface: SUBDIVISIONS² quads per span, `normal` unit,
    `xi` on each span's lattice, and the surface through the net's corner nodes (a
    B-spline with open uniform knots interpolates its corners; the facet master goes
    through every node)."""
    g = Grid(path)
    s0, s1 = spans(pair)
    per = (SUBDIVISIONS + 1) ** 2
    assert g.n_points == s0 * s1 * per and g.n_cells == s0 * s1 * SUBDIVISIONS ** 2, \
        f"{path}: {g.n_points} points, {g.n_cells} cells for {s0} x {s1} spans"
    quads = g.cells(VTK_QUAD, 4)
    assert quads.min() >= 0 and quads.max() < g.n_points
    normal = g.array("point", "normal", 3, F64)
    xi = g.array("point", "xi", 3, F64)
    assert np.allclose(np.linalg.norm(normal, axis=1), 1.0, rtol=0, atol=1e-12), f"{path}: normals not unit"
    assert np.all(xi[:, 2] == 0.0) and xi[:, :2].min() == 0.0 and xi[:, :2].max() == 1.0, f"{path}: xi"
    b, a = pair["net"].shape
    x = x_net.reshape(b, a, 3)
    # corners (and, for facets, every node) of the net lie on the surface
    targets = [(0, 0), (a - 1, 0), (0, b - 1), (a - 1, b - 1)]
    if pair["master_kind"] == "facet":
        targets = [(i, j) for j in range(b) for i in range(a)]
    for i, j in targets:
        at = np.flatnonzero((np.abs(xi[:, 0] - i / (a - 1)) < 1e-14) & (np.abs(xi[:, 1] - j / (b - 1)) < 1e-14))
        assert len(at) >= 1, f"{path}: no surface point at net node ({i}, {j})"
        scale = np.abs(x).max()
        err = np.abs(g.points[at] - x[j, i]).max() / scale
        assert err < 1e-12, f"{path}: surface at net node ({i}, {j}) is {g.points[at[0]]}, node at {x[j, i]} ({err:.1e})"
    return g


def check_net(path, pair, m):
    g = Grid(path)
    b, a = pair["net"].shape
    nodes = pair["net"].ravel()
    same(g.points, m["nodes"][nodes], f"{path}: points (the net's nodes)")
    lines = g.cells(VTK_LINE, 2)
    assert len(lines) == (a - 1) * b + a * (b - 1), f"{path}: {len(lines)} lines for a {a} x {b} net"
    i, j = lines % a, lines // a
    step = np.abs(i[:, 1] - i[:, 0]) + np.abs(j[:, 1] - j[:, 0])
    assert np.all(step == 1), f"{path}: a line joins nodes that are not neighbours in the net"
    same(g.array("point", "gmsh_node_tag", 1, I64), m["node_tags"][nodes].astype(np.int64), f"{path}: gmsh_node_tag")
    same(g.array("point", "i", 1, I32), (np.arange(a * b) % a).astype(np.int32), f"{path}: i")
    same(g.array("point", "j", 1, I32), (np.arange(a * b) // a).astype(np.int32), f"{path}: j")
    return g


def sibling(path, suffix):
    stem = os.path.splitext(path)[0]
    return f"{stem}_{suffix}"


def cmd_contact(vtu, sccontact):
    c = stagefile.contact(sccontact)
    m = c["mesh"]
    g = Grid(vtu)
    check_mesh_arrays(g, m, vtu)
    out = {"points": g.n_points, "hexes": g.n_cells, "pairs": []}
    for p in c["pairs"]:
        x = m["nodes"][p["net"].ravel()]
        s = check_surface(sibling(vtu, f"{p['name']}_surface.vtu"), p, x)
        n = check_net(sibling(vtu, f"{p['name']}_net.vtu"), p, m)
        out["pairs"].append({"name": p["name"], "net": list(p["net"].shape[::-1]), "surface_quads": s.n_cells,
                             "net_lines": n.n_cells, "mean_normal": s.point["normal"][0].reshape(-1, 3).mean(axis=0).tolist()})
    return out


def collection(pvd):
    """(time, file) of a .pvd, parsed by VTK's XML parser."""
    p = vtkXMLDataParser()
    p.SetFileName(pvd)
    assert p.Parse() == 1, f"{pvd}: VTK cannot parse it"
    root = p.GetRootElement()
    assert root.GetName() == "VTKFile" and root.GetAttribute("type") == "Collection", f"{pvd}: not a collection"
    coll = root.FindNestedElementWithName("Collection")
    entries = []
    for i in range(coll.GetNumberOfNestedElements()):
        d = coll.GetNestedElement(i)
        assert d.GetName() == "DataSet", d.GetName()
        entries.append((float(d.GetAttribute("timestep")), os.path.join(os.path.dirname(pvd), d.GetAttribute("file"))))
    return entries


def von_mises(s):
    p = (s[:, 0] + s[:, 4] + s[:, 8]) / 3.0
    d = np.stack([s[:, 0] - p, s[:, 4] - p, s[:, 8] - p], axis=1)
    off = (s[:, [1, 2, 3, 5, 6, 7]] ** 2).sum(axis=1)
    return np.sqrt(1.5 * ((d ** 2).sum(axis=1) + off))


def principal(s):
    t = s.reshape(-1, 3, 3)
    return np.linalg.eigvalsh(0.5 * (t + t.transpose(0, 2, 1)))


def check_stress(g, where, s, what):
    close(g.array(where, "stress", 9, F64), s, f"{what}: {where} stress")
    scale = max(np.abs(s).max(), 1e-300)
    close(g.array(where, "von_mises", 1, F64), von_mises(s), f"{what}: {where} von_mises")
    ev = principal(s)
    for name, col in (("principal_max", 2), ("principal_min", 0)):
        v = g.array(where, name, 1, F64)
        err = np.abs(v - ev[:, col]).max(initial=0.0) / scale
        assert err < 1e-9, f"{what}: {where} {name} differs by {err:.2e} of the largest stress"


def cmd_results(pvd, scres):
    r = stagefile.results(scres)
    m, pairs = r["mesh"], r["pairs"]
    n, nh = len(m["nodes"]), len(m["hexes"])
    steps = [{"load_factor": 0.0, "u": np.zeros((n, 3)), "stress": np.zeros((nh, 8, 9)), "state": [None] * len(pairs),
              "friction": [None] * len(pairs)}] + r["increments"]
    entries = collection(pvd)
    same([t for t, _ in entries], [s["load_factor"] for s in steps], f"{pvd}: time values against the load factors")
    frictional = any(f is not None for s in r["increments"] for f in s["friction"])
    count = np.bincount(m["hexes"].ravel(), minlength=n)
    summary = {"steps": len(entries), "times": [t for t, _ in entries], "frictional": frictional}
    for k, ((t, f), st) in enumerate(zip(entries, steps)):
        g = Grid(f)
        check_mesh_arrays(g, m, f)
        same(g.array("point", "displacement", 3, F64), st["u"], f"{f}: displacement")
        elem = st["stress"].mean(axis=1)
        nodal = np.zeros((n, 9))
        np.add.at(nodal, m["hexes"].ravel(), np.repeat(elem, 8, axis=0))
        nodal /= np.maximum(count, 1)[:, None]
        check_stress(g, "cell", elem, f)
        check_stress(g, "point", nodal, f)
        expect = {"displacement", "stress", "von_mises", "principal_max", "principal_min", "gmsh_node_tag"}
        expect |= {f"set:{s}" for s in m["node_sets"]}
        if pairs:
            pressure, gap, lam, status = np.zeros(n), np.full(n, np.nan), np.full(n, np.nan), np.full(n, -2.0)
            traction, slip, stick = np.zeros((n, 3)), np.zeros((n, 3)), np.full(n, -2.0)
            for p, pair in enumerate(pairs):
                sl = pair["slave_nodes"].astype(np.int64)
                state, fr = st["state"][p], st["friction"][p]
                if state is None:
                    status[sl] = 0.0
                else:
                    np.subtract.at(pressure, sl, state[:, 1])
                    gap[sl], lam[sl], status[sl] = state[:, 0], state[:, 2], state[:, 3]
                if fr is None:
                    stick[sl] = np.maximum(stick[sl], 0.0)
                else:
                    np.add.at(traction, sl, fr[:, 0:3])
                    slip[sl], stick[sl] = fr[:, 3:6], fr[:, 8]
            same(g.array("point", "contact_pressure", 1, F64), pressure, f"{f}: contact_pressure")
            same(g.array("point", "contact_gap", 1, F64), gap, f"{f}: contact_gap")
            same(g.array("point", "contact_lambda_n", 1, F64), lam, f"{f}: contact_lambda_n")
            same(g.array("point", "contact_status", 1, F64), status, f"{f}: contact_status")
            expect |= {"contact_pressure", "contact_gap", "contact_lambda_n", "contact_status"}
            if frictional:
                same(g.array("point", "contact_tangential_traction", 3, F64), traction, f"{f}: contact_tangential_traction")
                same(g.array("point", "contact_slip", 3, F64), slip, f"{f}: contact_slip")
                same(g.array("point", "contact_stick_slip", 1, F64), stick, f"{f}: contact_stick_slip")
                expect |= {"contact_tangential_traction", "contact_slip", "contact_stick_slip"}
            if k == len(steps) - 1:
                summary["max_contact_pressure"] = float(pressure.max())
                summary["active"] = int((status == 1.0).sum())
        assert set(g.point) == expect, f"{f}: point arrays {sorted(set(g.point) ^ expect)} unexpected or missing"
        assert set(g.cell) == {"body", "gmsh_element_tag", "stress", "von_mises", "principal_max", "principal_min"}, sorted(g.cell)
    summary["max_abs_u"] = np.abs(steps[-1]["u"]).max(axis=0).tolist()
    summary["max_von_mises"] = float(von_mises(nodal).max())
    # the master surfaces, deformed with their bodies, one series per pair
    summary["surfaces"] = []
    for pair in pairs:
        series = sibling(pvd, f"{pair['name']}_surface.pvd")
        surf = collection(series)
        same([t for t, _ in surf], [s["load_factor"] for s in steps], f"{series}: time values")
        nodes = pair["net"].ravel()
        for (t, f), st in zip(surf, steps):
            check_surface(f, pair, m["nodes"][nodes] + st["u"][nodes])
        summary["surfaces"].append({"pair": pair["name"], "steps": len(surf)})
    return summary


CHECK_FIELDS = {"pair": I32, "gmsh_node_tag": I64, "projection": I32, "g_n": F64, "adjust_move": F64,
                "g_n_adjusted": F64, "xi": F64, "normal": F64, "penetrating": U8, "behind": I32, "flag": I32}
FLAGS = ["ok", "outside", "adjusted", "penetrating", "failed", "behind"]


def cmd_check(vtu, csv_path):
    """The pre-solve check's point cloud against its CSV (docs/formats.md)."""
    rows = list(csv.DictReader(open(csv_path)))
    g = Grid(vtu)
    n = len(rows)
    assert g.n_points == n and g.n_cells == n, f"{vtu}: {g.n_points} points, {g.n_cells} cells for {n} CSV rows"
    same(g.cells(VTK_VERTEX, 1).ravel(), np.arange(n), f"{vtu}: vertices")
    num = lambda key: np.array([float(r[key]) for r in rows])  # noqa: E731
    same(g.points, np.stack([num("x"), num("y"), num("z")], axis=1), f"{vtu}: points against the CSV")
    arr = {k: g.array("point", k, 3 if k in ("xi", "normal") else 1, t) for k, t in CHECK_FIELDS.items()}
    assert set(g.point) == set(CHECK_FIELDS), sorted(g.point)
    names = list(dict.fromkeys(r["pair"] for r in rows))
    same(arr["pair"], np.array([names.index(r["pair"]) for r in rows], np.int32), f"{vtu}: pair")
    same(arr["gmsh_node_tag"], np.array([int(r["node_tag"]) for r in rows], np.int64), f"{vtu}: gmsh_node_tag")
    same(arr["projection"], np.array([{"inside": 1, "outside": 0, "failed": -1}[r["projection"]] for r in rows], np.int32), f"{vtu}: projection")
    for k in ("g_n", "adjust_move", "g_n_adjusted"):
        same(arr[k], num(k), f"{vtu}: {k}")
    same(arr["xi"], np.stack([num("xi_1"), num("xi_2"), np.zeros(n)], axis=1), f"{vtu}: xi")
    same(arr["normal"], np.stack([num("n_x"), num("n_y"), num("n_z")], axis=1), f"{vtu}: normal")
    same(arr["penetrating"], np.array([int(r["penetrating"]) for r in rows], np.uint8), f"{vtu}: penetrating")
    same(arr["behind"], np.array([int(r["behind"]) if r["behind"] != "" else -1 for r in rows], np.int32), f"{vtu}: behind")
    same(arr["flag"], np.array([FLAGS.index(r["flag"]) for r in rows], np.int32), f"{vtu}: flag")
    return {"points": n, "pairs": names, "flags": sorted(set(r["flag"] for r in rows))}


def main():
    cmds = {"mesh": cmd_mesh, "contact": cmd_contact, "results": cmd_results, "check": cmd_check}
    if len(sys.argv) != 4 or sys.argv[1] not in cmds:
        sys.exit(__doc__)
    out = cmds[sys.argv[1]](sys.argv[2], sys.argv[3])
    print(json.dumps(out, default=lambda v: v.tolist() if hasattr(v, "tolist") else str(v)))


if __name__ == "__main__":
    main()
