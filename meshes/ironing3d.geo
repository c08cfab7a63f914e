// 3D ironing after Puso & Laursen 2004 (CMAME 193, "A mortar segment-to-segment
// frictional contact method for large deformations"; docs/validation/ironing3d.md):
// a stiff half-cylindrical die pressed into a soft slab, then dragged along it over
// about nine master element lengths. Units are consistent but arbitrary (E = 1 for the slab).
// Dimensions (as published):
//   slab  x in [0, 9] (sliding direction), y in [0, 4] (width), z in [0, 3]; bottom fixed
//   die   a half-cylindrical shell, axis along y at x = 2.5, z = 6 (so its lowest line
//         touches the slab's top z = 3 at t = 0), outer radius 3, thickness 0.2
//         (inner radius 2.8), length 5.2 in y from -0.6 to 4.6 (wider than the slab)
// Our choices (not fixed by the secondary descriptions; see pipelines/ironing3d.yaml):
//   nu = 0.3 in both bodies (compressible neo-Hookean; 0.499 would lock the fully
//   integrated hex8), die E = 1000; start x = 2.5 so that the die, pressed 1.4 and slid
//   4 to x = 6.5, stays over the slab (its contact zone, half-width ~2.5, then spans
//   x ~ 0..5 and ~4..9).
// Mesh (hex8, transfinite, recombined):
//   slab  nsx x nsy x nsz = 20 x 7 x 6 (elements 0.45 x 0.571 x 0.5): its top face
//         slab_top is a 21 x 8 node net, the master (one B-spline patch or 20 x 7
//         facets). No slab node row lies under a die node row at the start: with
//         18 x 8 (0.5 x 0.5) the die's lowest row (x = 2.5) and its middle row
//         (y = 2) sat exactly on master node rows — on facet creases, where a node
//         pressed straight down flips between the two facets at every iterate.
//   die   ndt x ndy x 1 = 72 x 6 x 1 (the half circle split uniformly in angle: arc
//         length 0.13 on the outer face; 0.87 along y; one element through the 0.2
//         thickness): its outer face die_outer (73 x 7 nodes) is the slave. With 36
//         elements (0.26 apart) V rippled at the slave's spacing as die nodes entered
//         and left the contact zone, a ripple no master removes (frictionless B-spline
//         [4, 4] V oscillation 2.2e-4; 1.05e-4 with 72: docs/validation.md). Its node
//         rows along y sit at -0.6, 0.267, 1.133, 2, 2.867, 3.733, 4.6: 0.6 beyond the
//         slab's sides or 0.27 inside them. A slave row near the master's edge crosses
//         it while the slab deforms, already penetrated, and its force switches on or
//         off with a jump: Newton then cycles. Measured: rows 0.08 outside (ndy = 10)
//         cycled 49 <-> 51 active nodes at t = 0.26 (the top edges bulge outward early);
//         rows 0.05 inside (ndy = 8) left the patch at t = 0.96 (the top edges are
//         drawn inward under the die late in the pressing).
// Sets: slab (volume), die (volume), slab_bottom (fixed), slab_top (master),
//   die_outer (slave), die_top (the two straight edge faces of the shell at z = 6:
//   prescribed u_x, u_z, u_y = 0).
// Regenerate: gmsh meshes/ironing3d.geo -3 -format msh41 -o meshes/ironing3d.msh
//             (parameters: -setnumber nsx|nsy|nsz|ndt|ndy value)
Mesh.MshFileVersion = 4.1;

DefineConstant[
  nsx = {20, Name "Parameters/nsx"},      // slab elements along x (sliding; see below)
  nsy = {7, Name "Parameters/nsy"},       // slab elements along y (width; see below)
  nsz = {6, Name "Parameters/nsz"},       // slab elements through its thickness
  ndt = {72, Name "Parameters/ndt"},      // die elements around its half circle
  ndy = {6, Name "Parameters/ndy"}        // die elements along its axis (see below)
];

xc = 2.5;   // die axis, x
zc = 6.0;   // die axis, z
R = 3.0;    // outer radius
Ri = 2.8;   // inner radius

// ---- slab: rectangle in the x-z plane (y = 0), extruded along y ----
Point(1) = {0, 0, 0};
Point(2) = {9, 0, 0};
Point(3) = {9, 0, 3};
Point(4) = {0, 0, 3};
Line(1) = {1, 2};                         // bottom z = 0
Line(2) = {2, 3};                         // x = 9
Line(3) = {3, 4};                         // top z = 3
Line(4) = {4, 1};                         // x = 0
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 3} = nsx + 1;
Transfinite Curve {2, 4} = nsz + 1;
Transfinite Surface {1};
Recombine Surface {1};
slab[] = Extrude {0, 4, 0} { Surface{1}; Layers{nsy}; Recombine; };
// slab[0] y = 4, slab[1] volume, laterals of curves 1, 2, 3, 4 at slab[2..5]

// ---- die: half annulus in the x-z plane (y = -0.6), below its axis, extruded along y ----
Point(1001) = {xc, -0.6, zc};             // centre (no mesh node)
Point(1002) = {xc - R, -0.6, zc};
Point(1003) = {xc, -0.6, zc - R};         // lowest point of the outer face
Point(1004) = {xc + R, -0.6, zc};
Point(1005) = {xc - Ri, -0.6, zc};
Point(1006) = {xc, -0.6, zc - Ri};
Point(1007) = {xc + Ri, -0.6, zc};
Circle(1001) = {1002, 1001, 1003};        // outer, left quarter
Circle(1002) = {1003, 1001, 1004};        // outer, right quarter
Line(1003) = {1004, 1007};                // right edge (top)
Circle(1004) = {1007, 1001, 1006};        // inner, right quarter
Circle(1005) = {1006, 1001, 1005};        // inner, left quarter
Line(1006) = {1005, 1002};                // left edge (top)
Curve Loop(1001) = {1001, 1002, 1003, 1004, 1005, 1006};
Plane Surface(1001) = {1001};
Transfinite Curve {1001, 1002, 1004, 1005} = ndt / 2 + 1;
Transfinite Curve {1003, 1006} = 2;
Transfinite Surface {1001} = {1002, 1004, 1007, 1005};
Recombine Surface {1001};
die[] = Extrude {0, 5.2, 0} { Surface{1001}; Layers{ndy}; Recombine; };
// die[0] y = 4.6, die[1] volume, laterals of curves 1001..1006 at die[2..7]

Physical Volume("slab") = {slab[1]};
Physical Volume("die") = {die[1]};
Physical Surface("slab_bottom") = {slab[2]};         // z = 0, fixed
Physical Surface("slab_top") = {slab[4]};            // z = 3, master: 19 x 9 nodes
Physical Surface("die_outer") = {die[2], die[3]};    // outer half cylinder, slave
Physical Surface("die_top") = {die[4], die[7]};      // the shell's straight edges at z = 6
