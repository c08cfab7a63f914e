// Crossed beams (Santos & Bandeira 2018, sec. 7.2): two beams crossed and superposed
// with a 0.2 mm gap; the upper beam is a cantilever loaded at the edge of its free end
// and pressed onto the lower beam, which is clamped at both ends.
// Topology of the paper's example (docs/validation.md): each beam 2 x 2 x 15 hex8 (3 x 3 x 16 = 144
// nodes): 288 nodes, 120 elements. The paper's figure with the dimensions is lost, so
// these dimensions are OURS (unit system: mm, N, MPa = N/mm^2):
//   upper beam  (cantilever, along x)  x in [0, 150],  y in [-5, 5],   z in [10.2, 20.2]
//               section 10 (y) x 10 (z), 2 x 2 elements; 15 elements of 10 along x
//   lower beam  (along y)              x in [100, 120], y in [-75, 75], z in [0, 10]
//               section 20 (x) x 10 (z), 2 x 2 elements; 15 elements of 10 along y
//   gap 0.2 between the lower beam's top (z = 10) and the upper beam's bottom.
// The beams cross at the middle of the lower beam (y = 0) and in the outer third of the
// cantilever (x = 100..120; the free end overhangs 30 beyond the crossing), so the tip
// load levers the upper beam onto the lower one (which takes about 1.3 times the load)
// and both bend. Three rows of the upper beam's bottom nodes stand over the lower beam,
// x = 100 and 120 on its edges and x = 110 on its axis: the cantilever pivots on the
// lower beam's tip-side edge x = 120, so that edge must carry slave nodes (with the
// edges between node rows, x = 95..115, its corner would cut into the upper beam
// undetected: node-to-surface checks nodes only).
// Sets: upper_clamp (x = 0 face, clamped), load_edge (top edge of the free end,
// x = 150, z = 20.2: 3 nodes), upper_tip (x = 150 face), upper_bottom (slave),
// lower_top (master, 3 x 16 node net), lower_ends (y = +-75 faces, clamped).
// Regenerate: gmsh meshes/crossed_beams.geo -3 -format msh41 -o meshes/crossed_beams.msh
//             (parameters: -setnumber gap|xc|lu|ll|nc|nl value; the refinement levels of
//             docs/performance.md use nc = n, nl = 15 n)
Mesh.MshFileVersion = 4.1;

DefineConstant[
  gap = {0.2, Name "Parameters/gap"},     // initial gap between the beams
  lu = {150, Name "Parameters/lu"},       // upper beam length (along x)
  ll = {150, Name "Parameters/ll"},       // lower beam length (along y)
  xc = {110, Name "Parameters/xc"},       // x of the lower beam's axis
  nc = {2, Name "Parameters/nc"},         // elements across each section (y/x and z)
  nl = {15, Name "Parameters/nl"}         // elements along each beam
];
bu = 10; hu = 10;                         // upper section: width (y), height (z)
bl = 20; hl = 10;                         // lower section: width (x), height (z)
e = 1e-3 * bu;                            // bounding-box tolerance

// ---- lower beam: section in the plane y = -ll/2, extruded along y ----
Point(1) = {xc - bl/2, -ll/2, 0}; Point(2) = {xc + bl/2, -ll/2, 0};
Point(3) = {xc + bl/2, -ll/2, hl}; Point(4) = {xc - bl/2, -ll/2, hl};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 2, 3, 4} = nc + 1;  // nc elements across the section
Transfinite Surface {1};
Recombine Surface {1};
low[] = Extrude {0, ll, 0} { Surface{1}; Layers{nl}; Recombine; };
// low[0] = end face y = +ll/2, low[1] = volume

// ---- upper beam: section in the plane x = 0, extruded along x (tags from 1000 up) ----
zu = hl + gap;
Point(1001) = {0, -bu/2, zu}; Point(1002) = {0, bu/2, zu};
Point(1003) = {0, bu/2, zu + hu}; Point(1004) = {0, -bu/2, zu + hu};
Line(1001) = {1001, 1002}; Line(1002) = {1002, 1003};
Line(1003) = {1003, 1004}; Line(1004) = {1004, 1001};
Curve Loop(1001) = {1001, 1002, 1003, 1004};
Plane Surface(1001) = {1001};
Transfinite Curve {1001:1004} = nc + 1;
Transfinite Surface {1001};
Recombine Surface {1001};
up[] = Extrude {lu, 0, 0} { Surface{1001}; Layers{nl}; Recombine; };
// up[0] = free-end face x = lu, up[1] = volume

upper_bottom[] = Surface In BoundingBox {-e, -bu/2 - e, zu - e, lu + e, bu/2 + e, zu + e};
lower_top[] = Surface In BoundingBox {xc - bl/2 - e, -ll/2 - e, hl - e, xc + bl/2 + e, ll/2 + e, hl + e};
load_edge[] = Curve In BoundingBox {lu - e, -bu/2 - e, zu + hu - e, lu + e, bu/2 + e, zu + hu + e};

Physical Volume("lower") = {low[1]};
Physical Volume("upper") = {up[1]};
Physical Surface("upper_clamp") = {1001};             // clamped in x, y, z
Physical Surface("upper_tip") = {up[0]};
Physical Surface("upper_bottom") = {upper_bottom[]};  // slave contact surface
Physical Surface("lower_top") = {lower_top[]};        // master contact surface
Physical Surface("lower_ends") = {1, low[0]};         // clamped in x, y, z
Physical Curve("load_edge") = {load_edge[]};          // 9000 N in total, -z
