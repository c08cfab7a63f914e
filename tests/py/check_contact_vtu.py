"""Independent check of the files sc-export writes for a contact model (.sccontact).

usage: check_contact_vtu.py MESH.vtu SURFACE.vtu NET.vtu
Reads all three with meshio and asserts: the mesh has hexahedra; the tessellated
master surface has quads with point data `normal` (unit vectors) and `xi` (n, 3)
with the third component 0 and xi in [0, 1]; the control net has lines only.
Prints one JSON line: hexes, quads, lines, net_points, mean normal.
"""
import json
import sys

import meshio
import numpy as np


def main():
    mesh, surface, net = (meshio.read(p) for p in sys.argv[1:4])
    hexes = sum(len(c.data) for c in mesh.cells if c.type == "hexahedron")
    assert hexes > 0, "mesh has no hexahedra"
    assert all(c.type == "quad" for c in surface.cells), "surface cells are not all quads"
    quads = sum(len(c.data) for c in surface.cells)
    n = len(surface.points)
    normal = np.asarray(surface.point_data["normal"])
    xi = np.asarray(surface.point_data["xi"])
    assert normal.shape == (n, 3) and xi.shape == (n, 3), (normal.shape, xi.shape)
    assert np.allclose(np.linalg.norm(normal, axis=1), 1.0), "normals are not unit vectors"
    assert np.all(xi[:, 2] == 0) and xi[:, :2].min() >= 0 and xi[:, :2].max() <= 1, "xi out of [0, 1]"
    assert all(c.type == "line" for c in net.cells), "net cells are not all lines"
    lines = sum(len(c.data) for c in net.cells)
    print(json.dumps({"hexes": hexes, "quads": quads, "lines": lines, "net_points": len(net.points),
                      "mean_normal": [float(v) for v in normal.mean(axis=0)]}))


if __name__ == "__main__":
    main()
