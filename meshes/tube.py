"""A block on a tube (issue 26, pipelines/tube.yaml): the tube's outer surface is the
MASTER, a grid closed on itself, which sc-tag reads as a periodic B-spline patch.
The same mesh as tests/verification/tube.rs.

  tube   r in [2, 3], z in [0, 1]; 24 nodes around at theta_j = (j - 1/2) 15 deg, 2
         elements through the wall, 2 along z. The quadratic periodic patch's seam
         (xi^1 = 0) lies at theta = 0, between the nodes at -7.5 and 7.5 deg: the
         line x = 3 cos 7.5 deg, y = 0 where the block touches.
         Sets: tube_inner (r = 2, fixed), tube_outer (r = 3, the master).
  block  0.6 x 2.4 x 0.5 (x, y, z), 3 x 24 x 2 elements, at
         x in [3 cos 7.5 deg, + 0.6], y in [-1.63, 0.77], z in [0.25, 0.75]: its flat
         bottom tangent to the tube's top. Its node rows sit 0.03 off y = 0, the
         quadratic's span edge under the seam (docs/validation/masters.md, "A block
         sliding over a tube's periodic seam").
         Sets: block_bottom (x = 3 cos 7.5 deg, the slave), block_top (driven).

The nodes and hexahedra are written directly (gmsh discrete entities): the mesh is
exactly the one the test builds.

  python meshes/tube.py [out.msh]     (default meshes/tube.msh)
"""
import math
import sys

import gmsh

out = sys.argv[1] if len(sys.argv) > 1 else "meshes/tube.msh"
NA, NR, NZ, R0, R1, LEN = 24, 2, 2, 2.0, 3.0, 1.0
BX, BY, BZ, LX, LY, LZ = 3, 24, 2, 0.6, 2.4, 0.5
X_TOP = R1 * math.cos(math.radians(7.5))
SHIFT = (X_TOP, -1.63, 0.25)

gmsh.initialize(["-v", "2"])
gmsh.model.add("tube")
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)

nodes = []  # (x, y, z), gmsh tag = index + 1


def tube_id(i, j, k):
    return i + (NR + 1) * (j % NA + NA * k)


for k in range(NZ + 1):
    for j in range(NA):
        th = (j - 0.5) * 2 * math.pi / NA
        for i in range(NR + 1):
            r = R0 + (R1 - R0) * i / NR
            nodes.append((r * math.cos(th), r * math.sin(th), LEN * k / NZ))
n_tube = len(nodes)


def block_id(i, j, k):
    return n_tube + i + (BX + 1) * (j + (BY + 1) * k)


for k in range(BZ + 1):
    for j in range(BY + 1):
        for i in range(BX + 1):
            nodes.append((SHIFT[0] + LX * i / BX, SHIFT[1] + LY * j / BY, SHIFT[2] + LZ * k / BZ))


def hexa(idx, i, j, k):
    # bottom face (k) then top face (k + 1), each counter-clockwise about +k: a
    # right-handed hexahedron (r, theta, z for the tube; x, y, z for the block)
    return [idx(i, j, k), idx(i + 1, j, k), idx(i + 1, j + 1, k), idx(i, j + 1, k),
            idx(i, j, k + 1), idx(i + 1, j, k + 1), idx(i + 1, j + 1, k + 1), idx(i, j + 1, k + 1)]


tube_hexes = [hexa(tube_id, i, j, k) for k in range(NZ) for j in range(NA) for i in range(NR)]
block_hexes = [hexa(block_id, i, j, k) for k in range(BZ) for j in range(BY) for i in range(BX)]
# quads of the sets, each cycle seen from outside the body
inner = [[tube_id(0, j, k), tube_id(0, j, k + 1), tube_id(0, j + 1, k + 1), tube_id(0, j + 1, k)] for k in range(NZ) for j in range(NA)]
outer = [[tube_id(NR, j, k), tube_id(NR, j + 1, k), tube_id(NR, j + 1, k + 1), tube_id(NR, j, k + 1)] for k in range(NZ) for j in range(NA)]
bottom = [[block_id(0, j, k), block_id(0, j, k + 1), block_id(0, j + 1, k + 1), block_id(0, j + 1, k)] for k in range(BZ) for j in range(BY)]
top = [[block_id(BX, j, k), block_id(BX, j + 1, k), block_id(BX, j + 1, k + 1), block_id(BX, j, k + 1)] for k in range(BZ) for j in range(BY)]

# every node on the first volume entity; elements on their own entities
tags = list(range(1, len(nodes) + 1))
flat = [c for p in nodes for c in p]
v_tube = gmsh.model.addDiscreteEntity(3)
v_block = gmsh.model.addDiscreteEntity(3)
gmsh.model.mesh.addNodes(3, v_tube, tags, flat)
next_tag = 1


def add(dim, entity, gmsh_type, conn):
    global next_tag
    n = len(conn)
    gmsh.model.mesh.addElementsByType(entity, gmsh_type, list(range(next_tag, next_tag + n)), [v + 1 for c in conn for v in c])
    next_tag += n


add(3, v_tube, 5, tube_hexes)
add(3, v_block, 5, block_hexes)
surfaces = {}
for name, quads in [("tube_inner", inner), ("tube_outer", outer), ("block_bottom", bottom), ("block_top", top)]:
    s = gmsh.model.addDiscreteEntity(2)
    add(2, s, 3, quads)
    surfaces[name] = s
gmsh.model.addPhysicalGroup(3, [v_tube], name="tube")
gmsh.model.addPhysicalGroup(3, [v_block], name="block")
for name, s in surfaces.items():
    gmsh.model.addPhysicalGroup(2, [s], name=name)
gmsh.write(out)
gmsh.finalize()
print(f"{out}: {len(nodes)} nodes, {len(tube_hexes)} + {len(block_hexes)} hexahedra")
