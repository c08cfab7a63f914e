"""Independent read of the .vtu sc-check writes (docs/formats.md, "Pre-solve check").

usage: check_presolve_vtu.py CHECK.vtu CHECK.csv
Reads the .vtu with meshio and the CSV with the csv module and asserts: one vertex
per CSV row, at the row's position; every documented point field with its
components; the values equal the CSV's (node tags, g_n, flags as codes).
Prints one JSON line: points, fields, flags.
"""
import csv
import json
import sys

import meshio
import numpy as np

FIELDS = {"pair": 1, "gmsh_node_tag": 1, "projection": 1, "g_n": 1, "xi": 3, "normal": 3,
          "penetrating": 1, "behind": 1, "adjust_move": 1, "g_n_adjusted": 1, "flag": 1}
FLAGS = ["ok", "outside", "adjusted", "penetrating", "failed", "behind"]


def main():
    m = meshio.read(sys.argv[1])
    rows = list(csv.DictReader(open(sys.argv[2])))
    n = len(m.points)
    assert n == len(rows), (n, len(rows))
    assert all(c.type == "vertex" for c in m.cells) and sum(len(c.data) for c in m.cells) == n
    for name, k in FIELDS.items():
        a = np.asarray(m.point_data[name])
        assert a.shape in ((n,), (n, 1)) if k == 1 else a.shape == (n, k), (name, a.shape)
    xyz = np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in rows])
    assert np.array_equal(m.points, xyz), "points differ from the CSV positions"
    tags = np.asarray(m.point_data["gmsh_node_tag"]).ravel()
    assert [int(t) for t in tags] == [int(r["node_tag"]) for r in rows]
    g = np.asarray(m.point_data["g_n"]).ravel()
    assert np.array_equal(g, np.array([float(r["g_n"]) for r in rows]), equal_nan=True)
    flags = np.asarray(m.point_data["flag"]).ravel()
    assert [FLAGS[int(f)] for f in flags] == [r["flag"] for r in rows]
    print(json.dumps({"points": n, "fields": sorted(m.point_data), "flags": sorted(set(r["flag"] for r in rows))}))


if __name__ == "__main__":
    main()
