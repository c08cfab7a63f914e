// Plane-strain Hertz benchmark slice: a cylinder pressed onto a flat block.
// Units: mm, N, MPa. Dimensions (ours):
//   cylinder  radius R = 8, centre (0, 0); half-symmetry x >= 0, so the body "cylinder"
//             is the lower quarter disk x in [0, R], y in [-R, 0]; contact point (0, -R)
//   block     x in [0, W], y in [-R-D, -R], W = 8, D = 8; its top y = -R touches the
//             cylinder at (0, -R) (gap 0 there, opening as x^2/(2R))
//   both      z in [0, t], t = 1, ONE element layer (plane strain: hold z0 and z1 in z)
// Hertz (plane strain, rigid flat, E = 200, nu = 0.3, P = 10 per unit length):
//   b = sqrt(4 P R / (pi E*)), E* = E/(1 - nu^2) -> b = 0.681.
// Mesh (hex8, transfinite, recombined), `refine` (1, 2, 4) multiplies every element
// count and takes the refine-th root of every progression, so sizes scale by 1/refine:
//   cylinder  O-grid of 3 patches (inner quad + two curved patches, no degenerate
//             element), graded so elements are smallest at the contact point:
//             arc 0..45 deg 31 elements (progression 1.07 from (0,-R)), arc 45..90 deg
//             12, radial 16 (progression 1.15 from the arc). refine = 1: contact
//             elements 0.062 x 0.065, 8 arc elements within x < 0.68 (16, 33 at
//             refine = 2, 4).
//   block     15 x 10 elements, graded toward x = 0 (1.15) and toward its top (1.3):
//             ~0.17 at the contact, coarser than the cylinder (the cylinder is the slave).
// The block's top (block_top) is the master: a structured (15 + 1) x 2 node net.
// Regenerate: gmsh meshes/hertz.geo -3 -format msh41 -o meshes/hertz.msh
//             (finer: add -setnumber refine 2, or 4)
Mesh.MshFileVersion = 4.1;

DefineConstant[
  refine = {1, Name "Parameters/refine"},
  R = {8, Name "Parameters/R"},
  W = {8, Name "Parameters/W"},
  D = {8, Name "Parameters/D"},
  t = {1, Name "Parameters/t"}
];
sA = 0.55 * R;      // inner quad: corners (0,0), (sA,0), (sC,-sC), (0,-sA)
sC = 0.45 * R;
na1 = 31 * refine; ra1 = 1.07^(1 / refine);   // arc 0..45 deg, fine at (0,-R)
na2 = 12 * refine;                            // arc 45..90 deg, uniform
nr  = 16 * refine; rr  = 1.15^(1 / refine);   // radial, fine at the arc
ri  = 1.04^(1 / refine);                      // inner quad edges along x, fine at x = 0
nbx = 15 * refine; rbx = 1.15^(1 / refine);   // block along x, fine at x = 0
nby = 10 * refine; rby = 1.3^(1 / refine);    // block along y, fine at the top

// ---- cylinder: O-grid ----
Point(1) = {0, 0, 0};                          // O, the centre
Point(2) = {sA, 0, 0};                         // A
Point(3) = {sC, -sC, 0};                       // C
Point(4) = {0, -sA, 0};                        // B
Point(5) = {0, -R, 0};                         // contact point
Point(6) = {R * Cos(Pi / 4), -R * Sin(Pi / 4), 0};
Point(7) = {R, 0, 0};
Line(1) = {1, 2};          // O -> A   (y = 0)
Line(2) = {2, 3};          // A -> C
Line(3) = {4, 3};          // B -> C
Line(4) = {1, 4};          // O -> B   (x = 0)
Line(5) = {5, 4};          // contact point -> B (x = 0), radial
Line(6) = {6, 3};          // 45 deg arc point -> C, radial
Line(7) = {7, 2};          // (R, 0) -> A (y = 0), radial
Circle(8) = {5, 1, 6};     // arc 0..45 deg from the contact point
Circle(9) = {6, 1, 7};     // arc 45..90 deg
Curve Loop(1) = {4, 3, -2, -1};  Plane Surface(1) = {1};   // inner quad   O B C A
Curve Loop(2) = {8, 6, -3, -5};  Plane Surface(2) = {2};   // lower patch  P0 P45 C B
Curve Loop(3) = {-6, 9, 7, 2};   Plane Surface(3) = {3};   // side patch   C P45 P90 A
Transfinite Curve {8} = na1 + 1 Using Progression ra1;
Transfinite Curve {1, 3} = na1 + 1 Using Progression ri;
Transfinite Curve {9, 2, 4} = na2 + 1;
Transfinite Curve {5, 6, 7} = nr + 1 Using Progression rr;
Transfinite Surface {1, 2, 3};
Recombine Surface {1, 2, 3};

// ---- block ----
// Its corner (0, -R) coincides with the cylinder's contact point, but the two must stay
// separate points (two bodies). gmsh's built-in kernel merges coincident entities after
// every extrusion (Geometry.AutoCoherence, which the extrusions need to keep shared
// edges shared), so the block is built `off` lower, extruded, and moved into place with
// the merging switched off.
off = 4 * (R + D);
Point(11) = {0, -R - off, 0};
Point(12) = {W, -R - off, 0};
Point(13) = {W, -R - D - off, 0};
Point(14) = {0, -R - D - off, 0};
Line(11) = {11, 12};       // top,    x = 0 -> W
Line(12) = {12, 13};       // right,  top -> base
Line(13) = {14, 13};       // base,   x = 0 -> W
Line(14) = {11, 14};       // x = 0,  top -> base
Curve Loop(11) = {13, -12, -11, 14};  Plane Surface(11) = {11};
Transfinite Curve {11, 13} = nbx + 1 Using Progression rbx;
Transfinite Curve {12, 14} = nby + 1 Using Progression rby;
Transfinite Surface {11};
Recombine Surface {11};

// ---- one element layer in z ----
// Per surface gmsh returns: top (z = t), volume, then one lateral surface per curve of
// its loop, in loop order.
cyl[] = Extrude {0, 0, t} { Surface{1, 2, 3}; Layers{1}; Recombine; };
// inner: cyl[0] top, cyl[1] vol, laterals of 4, 3, -2, -1 at cyl[2..5]
// lower: cyl[6] top, cyl[7] vol, laterals of 8, 6, -3, -5 at cyl[8..11]
// side:  cyl[12] top, cyl[13] vol, laterals of -6, 9, 7, 2 at cyl[14..17]
blk[] = Extrude {0, 0, t} { Surface{11}; Layers{1}; Recombine; };
// blk[0] top, blk[1] vol, laterals of 13, -12, -11, 14 at blk[2..5]
Geometry.AutoCoherence = 0;
Translate {0, off, 0} { Volume{blk[1]}; }

Physical Volume("cylinder") = {cyl[1], cyl[7], cyl[13]};
Physical Volume("block") = {blk[1]};
Physical Surface("cyl_contact") = {cyl[8], cyl[15]};        // slave: the curved surface
Physical Surface("block_top") = {blk[4]};                   // master: (nbx+1) x 2 net
Physical Surface("cyl_load") = {cyl[5], cyl[16]};           // y = 0, x in [0, R]
Physical Surface("cyl_sym") = {cyl[2], cyl[11]};            // x = 0, cylinder
Physical Surface("block_sym") = {blk[5]};                   // x = 0, block
Physical Surface("sym") = {cyl[2], cyl[11], blk[5]};        // x = 0, both bodies
Physical Surface("block_base") = {blk[2]};                  // y = -R-D
Physical Surface("z0") = {1, 2, 3, 11};                     // z = 0, both bodies
Physical Surface("z1") = {cyl[0], cyl[6], cyl[12], blk[0]}; // z = t, both bodies
