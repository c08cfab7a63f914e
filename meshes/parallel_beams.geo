// Parallel beams (Santos & Bandeira 2018, sec. 7.3): two parallel beams, both
// restrained (clamped) at both ends, one above the other with a gap; line loads press
// them towards each other (down on the upper beam's top, up under the lower beam), so
// both arch before they touch and the contact surfaces are curved.
// Topology of the paper's example (docs/validation.md): lower 2 x 2 x 15 hex8 (144 nodes), upper
// 4 x 2 x 15 hex8 (5 x 3 x 16 = 240 nodes): 384 nodes, 180 elements. The upper beam is
// twice as wide, otherwise the same size (paper). The paper's figure with the
// dimensions, supports and load positions is lost, so these are OURS (unit system:
// mm, N, MPa = N/mm^2):
//   lower beam  x in [0, 150], y in [-5, 5],   z in [0, 10]            section 10 x 10
//   upper beam  x in [0, 150], y in [-10, 10], z in [10 + gap, 20 + gap] section 20 x 10
//   gap = 0.5 (ours: the paper gives none). Without contact the loads close 1.32 in
//   the middle (x = 70 and 80: lower beam up 0.88, upper beam down 0.44, this mesh),
//   so the beams touch at about 40 % of the load, both already arched.
//   15 elements of 10 along x; sections 2 x 2 (lower, elements 5 x 5) and 4 x 2
//   (upper, elements 5 x 5).
// Load lines (ours, the paper: "4 kN on each load line", the loading under the lower
// beam the same pattern as on top of the upper one): the transverse node lines at the
// third points x = 50 and x = 100, on the upper beam's top (5 nodes each) and on the
// lower beam's bottom (3 nodes each). Each beam is built from three extruded segments
// (x = 0..50, 50..100, 100..150) so that these lines are gmsh curves.
// The upper beam's inner node rows y = +-5 stand exactly on the lower beam's long
// edges (the master patch's edges): the solver keeps such nodes in contact on the
// patch's extension (edge tolerance), the rows y = 0, +-5 carry the contact, y = +-10
// are outside the master. (Parameter yi moves the inner rows, e.g. to 4.5.)
// Sets: lower_ends, upper_ends (x = 0 and 150 faces, clamped), lower_top (master,
// 3 x 16 node net), upper_bottom (slave, 5 x 16 nodes), upper_load_lines (top,
// x = 50 and 100), lower_load_lines (bottom, x = 50 and 100).
// Regenerate: gmsh meshes/parallel_beams.geo -3 -format msh41 -o meshes/parallel_beams.msh
//             (parameters: -setnumber gap value)
Mesh.MshFileVersion = 4.1;

DefineConstant[
  gap = {0.5, Name "Parameters/gap"}      // initial gap between the beams
];
L = 150; nseg = 5;                        // length; elements per third (15 in all)
bl = 10; bu = 20; h = 10;                 // widths (y) of lower and upper beam, height (z)
e = 1e-3 * bl;                            // bounding-box tolerance

// ---- lower beam: section in the plane x = 0, extruded along x in three segments ----
Point(1) = {0, -bl/2, 0}; Point(2) = {0, bl/2, 0}; Point(3) = {0, bl/2, h}; Point(4) = {0, -bl/2, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 2, 3, 4} = 3;       // 2 x 2 elements across the section
Transfinite Surface {1};
Recombine Surface {1};
l1[] = Extrude {L/3, 0, 0} { Surface{1}; Layers{nseg}; Recombine; };
l2[] = Extrude {L/3, 0, 0} { Surface{l1[0]}; Layers{nseg}; Recombine; };
l3[] = Extrude {L/3, 0, 0} { Surface{l2[0]}; Layers{nseg}; Recombine; };

// ---- upper beam (tags from 1000 up): the section as four columns of quads (one
// element wide, two high), extruded together so that shared faces stay shared ----
zu = h + gap;
yi = 5.0;                                 // inner node rows of the upper beam at y = +-yi
Point(1001) = {0, -bu/2, zu}; Point(1002) = {0, -yi, zu}; Point(1003) = {0, 0, zu};
Point(1004) = {0, yi, zu}; Point(1005) = {0, bu/2, zu};
Point(1006) = {0, -bu/2, zu + h}; Point(1007) = {0, -yi, zu + h}; Point(1008) = {0, 0, zu + h};
Point(1009) = {0, yi, zu + h}; Point(1010) = {0, bu/2, zu + h};
For i In {0:3}
  Line(1001 + i) = {1001 + i, 1002 + i};          // bottom
  Line(1011 + i) = {1006 + i, 1007 + i};          // top
EndFor
For i In {0:4}
  Line(1021 + i) = {1001 + i, 1006 + i};          // verticals
EndFor
For i In {0:3}
  Curve Loop(1001 + i) = {1001 + i, 1022 + i, -(1011 + i), -(1021 + i)};
  Plane Surface(1001 + i) = {1001 + i};
EndFor
Transfinite Curve {1001:1004, 1011:1014} = 2;
Transfinite Curve {1021:1025} = 3;
Transfinite Surface {1001:1004};
Recombine Surface {1001:1004};
u1[] = Extrude {L/3, 0, 0} { Surface{1001:1004}; Layers{nseg}; Recombine; };
u2[] = Extrude {L/3, 0, 0} { Surface{u1[0], u1[6], u1[12], u1[18]}; Layers{nseg}; Recombine; };
u3[] = Extrude {L/3, 0, 0} { Surface{u2[0], u2[6], u2[12], u2[18]}; Layers{nseg}; Recombine; };

lower_top[] = Surface In BoundingBox {-e, -bl/2 - e, h - e, L + e, bl/2 + e, h + e};
upper_bottom[] = Surface In BoundingBox {-e, -bu/2 - e, zu - e, L + e, bu/2 + e, zu + e};
ul1[] = Curve In BoundingBox {L/3 - e, -bu/2 - e, zu + h - e, L/3 + e, bu/2 + e, zu + h + e};
ul2[] = Curve In BoundingBox {2*L/3 - e, -bu/2 - e, zu + h - e, 2*L/3 + e, bu/2 + e, zu + h + e};
ll1[] = Curve In BoundingBox {L/3 - e, -bl/2 - e, -e, L/3 + e, bl/2 + e, e};
ll2[] = Curve In BoundingBox {2*L/3 - e, -bl/2 - e, -e, 2*L/3 + e, bl/2 + e, e};

Physical Volume("lower") = {l1[1], l2[1], l3[1]};
Physical Volume("upper") = {u1[1], u1[7], u1[13], u1[19], u2[1], u2[7], u2[13], u2[19], u3[1], u3[7], u3[13], u3[19]};
Physical Surface("lower_ends") = {1, l3[0]};              // clamped in x, y, z
Physical Surface("upper_ends") = {1001:1004, u3[0], u3[6], u3[12], u3[18]};           // clamped in x, y, z
Physical Surface("lower_top") = {lower_top[]};            // master contact surface
Physical Surface("upper_bottom") = {upper_bottom[]};      // slave contact surface
Physical Curve("upper_load_lines") = {ul1[], ul2[]};      // 2 x 4 kN, -z
Physical Curve("lower_load_lines") = {ll1[], ll2[]};      // 2 x 4 kN, +z
