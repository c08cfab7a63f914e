// Supported beam (Santos & Bandeira 2018, sec. 7.4): a cantilever suspended 0.5 mm
// over a beam fixed at both ends; loads on the nodes of the cantilever's free end bend
// it down onto the lower beam, which then bends too.
// Topology of the paper's example (docs/validation.md): upper 2 x 3 x 20 hex8 (3 x 4 x 21 = 252
// nodes; its end face has the 12 loaded nodes), lower 2 x 2 x 20 hex8 (3 x 3 x 21 =
// 189 nodes): 441 nodes, 200 elements. The paper's figure with the dimensions is lost,
// so these dimensions are OURS (unit system: mm, N, MPa = N/mm^2):
//   upper beam  (cantilever) x in [0, 200],   y in [-5, 5],   z in [10.5, 25.5]
//               section 10 (y) x 15 (z), 2 x 3 elements of 5 x 5; 20 elements of 10
//   lower beam               x in [100, 300], y in [-10, 10], z in [0, 10]
//               section 20 (y) x 10 (z), 2 x 2 elements of 10 x 5; 20 elements of 10
//   gap 0.5 (paper) between the lower beam's top and the cantilever's bottom.
// Both beams lie along x; the cantilever is clamped at x = 0 and its free end x = 200
// is over the middle of the lower beam, which is clamped at x = 100 and x = 300. The
// lower beam is twice as wide, so that the cantilever's bottom node rows (y = 0, +-5)
// stand inside the master surface, none on its long edges (y = +-10).
// Sets: upper_clamp (x = 0 face, clamped), upper_tip (x = 200 face: the 12 loaded
// nodes), upper_bottom (slave, 3 x 21 nodes), lower_top (master, 3 x 21 node net),
// lower_ends (x = 100 and 300 faces, clamped).
// Regenerate: gmsh meshes/supported_beam.geo -3 -format msh41 -o meshes/supported_beam.msh
//             (parameters: -setnumber gap|x0 value)
Mesh.MshFileVersion = 4.1;

DefineConstant[
  gap = {0.5, Name "Parameters/gap"},     // initial gap between the beams
  x0 = {100, Name "Parameters/x0"}        // x of the lower beam's first end
];
L = 200;                                  // length of both beams
bu = 10; hu = 15;                         // upper section: width (y), height (z)
bl = 20; hl = 10;                         // lower section: width (y), height (z)
e = 1e-3 * bu;                            // bounding-box tolerance

// ---- lower beam: section in the plane x = x0, extruded along x ----
Point(1) = {x0, -bl/2, 0}; Point(2) = {x0, bl/2, 0}; Point(3) = {x0, bl/2, hl}; Point(4) = {x0, -bl/2, hl};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 2, 3, 4} = 3;       // 2 x 2 elements across the section
Transfinite Surface {1};
Recombine Surface {1};
low[] = Extrude {L, 0, 0} { Surface{1}; Layers{20}; Recombine; };
// low[0] = end face x = x0 + L, low[1] = volume

// ---- upper beam (tags from 1000 up): section in the plane x = 0 ----
zu = hl + gap;
Point(1001) = {0, -bu/2, zu}; Point(1002) = {0, bu/2, zu};
Point(1003) = {0, bu/2, zu + hu}; Point(1004) = {0, -bu/2, zu + hu};
Line(1001) = {1001, 1002}; Line(1002) = {1002, 1003};
Line(1003) = {1003, 1004}; Line(1004) = {1004, 1001};
Curve Loop(1001) = {1001, 1002, 1003, 1004};
Plane Surface(1001) = {1001};
Transfinite Curve {1001, 1003} = 3;       // 2 elements across the width
Transfinite Curve {1002, 1004} = 4;       // 3 elements through the height
Transfinite Surface {1001};
Recombine Surface {1001};
up[] = Extrude {L, 0, 0} { Surface{1001}; Layers{20}; Recombine; };
// up[0] = free-end face x = L, up[1] = volume

upper_bottom[] = Surface In BoundingBox {-e, -bu/2 - e, zu - e, L + e, bu/2 + e, zu + e};
lower_top[] = Surface In BoundingBox {x0 - e, -bl/2 - e, hl - e, x0 + L + e, bl/2 + e, hl + e};

Physical Volume("lower") = {low[1]};
Physical Volume("upper") = {up[1]};
Physical Surface("upper_clamp") = {1001};             // clamped in x, y, z
Physical Surface("upper_tip") = {up[0]};              // 12 nodes, 150 N each, -z
Physical Surface("upper_bottom") = {upper_bottom[]};  // slave contact surface
Physical Surface("lower_top") = {lower_top[]};        // master contact surface
Physical Surface("lower_ends") = {1, low[0]};         // clamped in x, y, z
