"""3D Hertz: a ball pressed onto a block; the ball's surface is the MASTER, an
unstructured quad surface with extraordinary nodes (Catmull–Clark and facet masters
on the same mesh). Units: mm, N, MPa.

  ball   radius R = 8, centre (0, 0, R): it touches the block at the origin. Its
         whole surface is the face set `ball_surface` (closed: no boundary); its top
         cap (z >= 2R - 1.5) is also the face set `ball_cap`, whose nodes carry the load.
  block  [-L, L]^2 x [-H, 0], L = H = 2.4, transfinite; its top `block_top` is the
         slave (flat: the node-to-surface pressure lives on its nodes).

The ball is meshed with tetrahedra (size hc = 0.42/refine within |x|, |y| < 1.8,
z < 0.6 of the contact, hb = 3/refine elsewhere), then every element is split into
hexahedra (Mesh.SubdivisionAlgorithm = 2: a tetrahedron into 4 hexahedra, a
hexahedron into 8). The ball's skin becomes a free quad mesh: each triangle's centroid
is a node of valence 3, the tetrahedral mesh's own vertices keep their valences.
The block (16 refine)^2 x 4 refine transfinite hexahedra before the split.

  python meshes/hertz3d.py [refine] [out.msh]     (default 1, meshes/hertz3d.msh)
"""
import sys

import gmsh

refine = float(sys.argv[1]) if len(sys.argv) > 1 else 1.0
out = sys.argv[2] if len(sys.argv) > 2 else "meshes/hertz3d.msh"
R, L, H, cap_h = 8.0, 2.4, 2.4, 1.5
hc, hb = 0.42 / refine, 3.0 / refine
nb, nh = round(16 * refine), round(4 * refine)

gmsh.initialize(["-v", "2"])
gmsh.option.setNumber("General.Terminal", 1)
gmsh.model.add("hertz3d")
occ = gmsh.model.occ
ball = occ.addSphere(0, 0, R, R)
cutter = occ.addBox(-R - 1, -R - 1, 2 * R - cap_h, 2 * R + 2, 2 * R + 2, cap_h + 1)
pieces, _ = occ.fragment([(3, ball)], [(3, cutter)])
occ.synchronize()
# the fragment keeps the cutter's outside part: drop it
ball_vols = []
for dim, tag in pieces:
    x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(dim, tag)
    if x1 - x0 > 2 * R + 0.5:
        gmsh.model.removeEntities([(dim, tag)], recursive=True)
    else:
        ball_vols.append(tag)
block = occ.addBox(-L, -L, -H, 2 * L, 2 * L, H)
occ.synchronize()

def surfaces_of(vols):
    return {t for _, t in gmsh.model.getBoundary([(3, v) for v in vols], oriented=False, combined=True)}

skin = sorted(surfaces_of(ball_vols))
cap = [s for s in skin if gmsh.model.getBoundingBox(2, s)[2] > 2 * R - cap_h - 1e-6]
bsurf = {}
for _, s in gmsh.model.getBoundary([(3, block)], oriented=False):
    x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(2, s)
    if abs(z0) < 1e-5 and abs(z1) < 1e-5:
        bsurf["top"] = s
    elif abs(z0 + H) < 1e-5 and abs(z1 + H) < 1e-5:
        bsurf["base"] = s

# block: transfinite hexahedra
for _, c in gmsh.model.getEntities(1):
    x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(1, c)
    if z1 <= 1e-5 and x0 >= -L - 1e-5 and x1 <= L + 1e-5 and y0 >= -L - 1e-5 and y1 <= L + 1e-5:
        n = nh if z1 - z0 > 1e-3 else nb
        gmsh.model.mesh.setTransfiniteCurve(c, n + 1)
for _, s in gmsh.model.getBoundary([(3, block)], oriented=False):
    gmsh.model.mesh.setTransfiniteSurface(s)
    gmsh.model.mesh.setRecombine(2, s)
gmsh.model.mesh.setTransfiniteVolume(block)

# ball: sizes by a box field
f = gmsh.model.mesh.field.add("Box")
gmsh.model.mesh.field.setNumber(f, "VIn", hc)
gmsh.model.mesh.field.setNumber(f, "VOut", hb)
for k, v in zip(["XMin", "XMax", "YMin", "YMax", "ZMin", "ZMax", "Thickness"], [-1.8, 1.8, -1.8, 1.8, -0.1, 0.6, 1.5]):
    gmsh.model.mesh.field.setNumber(f, k, v)
gmsh.model.mesh.field.setAsBackgroundMesh(f)
gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", 2)
gmsh.option.setNumber("Mesh.Algorithm3D", 1)

gmsh.model.addPhysicalGroup(3, ball_vols, name="ball")
gmsh.model.addPhysicalGroup(3, [block], name="block")
gmsh.model.addPhysicalGroup(2, skin, name="ball_surface")
gmsh.model.addPhysicalGroup(2, cap, name="ball_cap")
gmsh.model.addPhysicalGroup(2, [bsurf["top"]], name="block_top")
gmsh.model.addPhysicalGroup(2, [bsurf["base"]], name="block_base")
gmsh.model.mesh.generate(3)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.write(out)
gmsh.finalize()
