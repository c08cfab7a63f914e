// Shallow ironing (docs/validation/shallow-ironing.md; Yastrebov, "Numerical Methods in
// Contact Mechanics"; solids4foam shallowIroning; Kratos shallow_ironing_3D):
// a stiff indenter with a circular bottom pressed into a soft foundation, then slid.
// Units: mm, N, MPa. 3D, one element layer of depth 1 in z (plane strain through
// u_z = 0 on both z faces, set in the pipeline).
// Dimensions (published):
//   foundation  x in [0, 12], y in [0, 4], z in [0, 1]
//   indenter    x in [0.2, 1.4]: flat top y = 5.4, straight sides down to y = 4.5,
//               bottom a circular arc of radius 0.75, centre (0.8, 4.95), lowest point
//               (0.8, 4.2): initial gap 0.2 to the foundation's top y = 4
// Mesh (hex8, transfinite, recombined, one layer in z):
//   foundation  nfx x nfy = 60 x 10 (x, y), graded in y toward the top (progression
//               rfy = 0.85 per element upward: 0.75 at the bottom, 0.17 at the top;
//               0.2 along x), so its top face foundation_top is a 61 x 2 node net
//               (the master; 2 = the z direction)
//   indenter    nix x niy = 13 x 4: the arc split uniformly in angle (spacing 0.107),
//               its bottom face indenter_bottom (14 x 2 nodes) is the slave. nix is
//               odd on purpose: with an even nix a slave node row sits at the arc's
//               lowest point x = 0.8, exactly on the master node row x = 0.8, and with
//               friction (mu = 0.3) the first contact increment (t = 0.21) cycles
//               between the two master elements there and fails after 6 cutbacks
//               (B-spline [2, 3] and facet alike; frictionless it converges)
// Sets: foundation_bottom (fixed), indenter_top (prescribed u_x, u_y), foundation_top
// (master), indenter_bottom (slave), z_faces (both z faces of both bodies: u_z = 0).
// Regenerate: gmsh meshes/shallow_ironing.geo -3 -format msh41 -o meshes/shallow_ironing.msh
//             (parameters: -setnumber nfx|nfy|rfy|nix|niy value)
Mesh.MshFileVersion = 4.1;

DefineConstant[
  nfx = {60, Name "Parameters/nfx"},      // foundation elements along x
  nfy = {10, Name "Parameters/nfy"},      // foundation elements along y
  rfy = {0.85, Name "Parameters/rfy"},    // foundation grading along y (upward ratio)
  nix = {13, Name "Parameters/nix"},      // indenter elements along its arc and top (odd)
  niy = {4, Name "Parameters/niy"}        // indenter elements along its sides
];

// ---- foundation: rectangle in the x-y plane (z = 0), extruded along z ----
Point(1) = {0, 0, 0};
Point(2) = {12, 0, 0};
Point(3) = {12, 4, 0};
Point(4) = {0, 4, 0};
Line(1) = {1, 2};                         // bottom y = 0
Line(2) = {2, 3};                         // x = 12, upward
Line(3) = {3, 4};                         // top y = 4
Line(4) = {1, 4};                         // x = 0, upward (same grading as line 2)
Curve Loop(1) = {1, 2, 3, -4};
Plane Surface(1) = {1};
Transfinite Curve {1, 3} = nfx + 1;
Transfinite Curve {2, 4} = nfy + 1 Using Progression rfy;
Transfinite Surface {1};
Recombine Surface {1};
fnd[] = Extrude {0, 0, 1} { Surface{1}; Layers{1}; Recombine; };
// fnd[0] z = 1, fnd[1] volume, laterals of curves 1, 2, 3, 4 at fnd[2..5]

// ---- indenter (entity tags from 1000 up) ----
Point(1001) = {0.2, 4.5, 0};
Point(1002) = {1.4, 4.5, 0};
Point(1003) = {1.4, 5.4, 0};
Point(1004) = {0.2, 5.4, 0};
Point(1005) = {0.8, 4.95, 0};             // the arc's centre (no mesh node)
Circle(1001) = {1001, 1005, 1002};        // bottom arc, through (0.8, 4.2)
Line(1002) = {1002, 1003};                // x = 1.4
Line(1003) = {1003, 1004};                // top y = 5.4
Line(1004) = {1004, 1001};                // x = 0.2
Curve Loop(1001) = {1001, 1002, 1003, 1004};
Plane Surface(1001) = {1001};
Transfinite Curve {1001, 1003} = nix + 1;
Transfinite Curve {1002, 1004} = niy + 1;
Transfinite Surface {1001};
Recombine Surface {1001};
ind[] = Extrude {0, 0, 1} { Surface{1001}; Layers{1}; Recombine; };
// ind[0] z = 1, ind[1] volume, laterals of curves 1001..1004 at ind[2..5]

Physical Volume("foundation") = {fnd[1]};
Physical Volume("indenter") = {ind[1]};
Physical Surface("foundation_bottom") = {fnd[2]};   // y = 0, fixed
Physical Surface("foundation_top") = {fnd[4]};      // y = 4, master: 61 x 2 nodes
Physical Surface("indenter_bottom") = {ind[2]};     // the arc, slave: 14 x 2 nodes
Physical Surface("indenter_top") = {ind[4]};        // y = 5.4, prescribed u_x, u_y
Physical Surface("z_faces") = {1, fnd[0], 1001, ind[0]};  // u_z = 0
