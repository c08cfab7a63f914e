"""Independent check of sc-import + sc-export with meshio.

usage: compare_msh_vtu.py MESH.msh MODEL.vtu
Reads the gmsh file and our .vtu with meshio and asserts:
  * the same number of hexahedra, in the same order, whose corner coordinates are
    bit-identical (compared as uint64 bit patterns, not with a tolerance);
  * identical connectivity: the node correspondence induced by the hexahedra is a
    bijection between the .vtu points and the .msh nodes used by hexahedra;
  * the cell array "body" and one "set:<name>" point array per gmsh physical group.
Prints one JSON line with counts; exits non-zero with a message on any mismatch.
"""
import json
import sys

import meshio
import numpy as np


def hexes(mesh):
    blocks = [c.data for c in mesh.cells if c.type == "hexahedron"]
    h = np.concatenate(blocks) if blocks else np.zeros((0, 8), dtype=np.int64)
    # meshio 5.3 on NumPy 2 adds an int64 offset to our UInt64 connectivity, which
    # NumPy promotes to float64: convert back, checking the values are exact integers.
    if h.dtype.kind == "f":
        assert np.array_equal(h, np.round(h)), "non-integer connectivity"
        h = h.astype(np.int64)
    return h


def main():
    msh_path, vtu_path = sys.argv[1], sys.argv[2]
    m = meshio.read(msh_path)
    v = meshio.read(vtu_path)
    mh, vh = hexes(m), hexes(v)
    assert mh.shape == vh.shape, f"hex count differs: msh {mh.shape}, vtu {vh.shape}"
    assert m.points.dtype == np.float64 and v.points.dtype == np.float64, "points must be float64"
    mc = np.ascontiguousarray(m.points[mh])
    vc = np.ascontiguousarray(v.points[vh])
    assert np.array_equal(mc.view(np.uint64), vc.view(np.uint64)), "hex corner coordinates are not bit-identical"
    # connectivity: vtu node -> msh node must be a bijection on the used nodes
    pairs = {}
    for a, b in zip(vh.ravel(), mh.ravel()):
        if pairs.setdefault(int(a), int(b)) != int(b):
            raise AssertionError(f"vtu point {a} maps to two msh nodes")
    assert len(set(pairs.values())) == len(pairs), "two vtu points map to one msh node"
    assert len(pairs) == len(v.points), f"vtu has {len(v.points)} points, hexes use {len(pairs)}"
    assert "body" in v.cell_data, "cell data 'body' missing"
    names = [n for n in m.field_data]
    missing = [n for n in names if f"set:{n}" not in v.point_data]
    assert not missing, f"point data set:<name> missing for {missing}"
    for n in names:
        arr = np.asarray(v.point_data[f"set:{n}"]).ravel()
        assert set(np.unique(arr)) <= {0, 1}, f"set:{n} is not 0/1"
        assert arr.sum() > 0, f"set:{n} is empty"
    print(json.dumps({"hexes": int(mh.shape[0]), "points": int(len(v.points)), "groups": sorted(names)}))


if __name__ == "__main__":
    main()
