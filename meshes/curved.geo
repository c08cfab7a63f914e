// Curved-master test: a block ("pad") pressed onto a cylindrical surface ("base").
// Units: mm, N, MPa. Dimensions (ours):
//   base  x in [-10, 10], y in [0, 10], z from -6 up to the cylindrical top
//         z = sqrt(Rc^2 - x^2) - Rc, Rc = 20 (axis along y through (x, z) = (0, -Rc));
//         apex line z = 0 at x = 0, z = -2.68 at x = +-10
//   pad   x in [-4, 4], y in [2, 8], z in [gap, gap + 4], gap = 0 (parameter): its flat
//         bottom touches the apex line x = 0 (gap 0 there, opening as about x^2/(2 Rc)
//         elsewhere: 0.4 at x = +-4)
// Mesh (hex8, transfinite, recombined):
//   base  6 x 4 x 2 (x, y, z); the top arc is split uniformly in angle (nodes at
//         x = 0, +-3.47, +-6.84, +-10), so its top face base_top is a 7 x 5 node net
//         (the master) with a node row on the apex line
//   pad   8 x 6 x 2 (x, y, z), finer: its bottom pad_bottom is the slave
// Sets: base_bottom (fix), pad_top (prescribed displacement), base_top, pad_bottom.
// Regenerate: gmsh meshes/curved.geo -3 -format msh41 -o meshes/curved.msh
//             (parameters: -setnumber Rc|nbx|nby|nbz|npx|npy|npz|gap value)
Mesh.MshFileVersion = 4.1;

DefineConstant[
  Rc = {20, Name "Parameters/Rc"},        // radius of the base's cylindrical top
  nbx = {6, Name "Parameters/nbx"},       // base elements along x (even: a node at the apex)
  nby = {4, Name "Parameters/nby"},       // base elements along y
  nbz = {2, Name "Parameters/nbz"},       // base elements along z
  npx = {8, Name "Parameters/npx"},       // pad elements along x
  npy = {6, Name "Parameters/npy"},       // pad elements along y
  npz = {2, Name "Parameters/npz"},       // pad elements along z
  gap = {0, Name "Parameters/gap"}        // initial gap at the apex (pad bottom at z = gap)
];
zt = Sqrt(Rc^2 - 10^2) - Rc;              // base top at x = +-10

// ---- base: a section in the x-z plane (y = 0), extruded along y ----
Point(1) = {-10, 0, -6};
Point(2) = {10, 0, -6};
Point(3) = {10, 0, zt};
Point(4) = {-10, 0, zt};
Point(5) = {0, 0, -Rc};                   // the arc's centre (no mesh node)
Line(1) = {1, 2};                         // bottom
Line(2) = {2, 3};                         // x = 10
Circle(3) = {3, 5, 4};                    // the cylindrical top
Line(4) = {4, 1};                         // x = -10
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 3} = nbx + 1;
Transfinite Curve {2, 4} = nbz + 1;
Transfinite Surface {1};
Recombine Surface {1};
base[] = Extrude {0, 10, 0} { Surface{1}; Layers{nby}; Recombine; };
// base[0] y = 10, base[1] volume, laterals of curves 1, 2, 3, 4 at base[2..5]

// ---- pad: a rectangle in the x-y plane (z = gap), extruded along z ----
// (entity tags from 1000 up, clear of the tags the base's extrusion creates)
Point(1011) = {-4, 2, gap};
Point(1012) = {4, 2, gap};
Point(1013) = {4, 8, gap};
Point(1014) = {-4, 8, gap};
Line(1011) = {1011, 1012};
Line(1012) = {1012, 1013};
Line(1013) = {1013, 1014};
Line(1014) = {1014, 1011};
Curve Loop(1011) = {1011, 1012, 1013, 1014};
Plane Surface(1011) = {1011};
Transfinite Curve {1011, 1013} = npx + 1;
Transfinite Curve {1012, 1014} = npy + 1;
Transfinite Surface {1011};
Recombine Surface {1011};
pad[] = Extrude {0, 0, 4} { Surface{1011}; Layers{npz}; Recombine; };
// pad[0] top (z = gap + 4), pad[1] volume

Physical Volume("base") = {base[1]};
Physical Volume("pad") = {pad[1]};
Physical Surface("base_top") = {base[4]};     // master: cylindrical, 7 x 5 nodes
Physical Surface("base_bottom") = {base[2]};  // z = -6, fixed
Physical Surface("pad_bottom") = {1011};        // slave
Physical Surface("pad_top") = {pad[0]};       // prescribed displacement
