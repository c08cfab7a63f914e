// Parisch (1989) two-block contact example, as used by Santos & Bandeira (2018), sec. 7.1.
// Topology of the paper's example (docs/validation.md): lower block 3x3x1 hex8 (32 nodes), upper block
// 2x2x1 hex8 (18 nodes): 50 nodes, 13 elements. The paper's figure with the dimensions is
// lost, so these dimensions are OURS (unit system: mm, N, MPa):
//   lower block  x,y in [-15, 15], z in [0, 10]
//   upper block  x,y in [-10, 10], z in [10, 22]   (rests on the lower block, gap 0)
// The load node is the centre of the upper block's top face, (0, 0, 22).
// Regenerate: gmsh meshes/parisch.geo -3 -format msh41 -o meshes/parisch.msh
// (-setnumber r R splits every element R times per direction: the refinement levels
// of docs/performance.md; r = 1 is the paper's mesh)
Mesh.MshFileVersion = 4.1;
DefineConstant[ r = {1, Name "Parameters/r"} ];

// ---- lower block: one transfinite quad surface extruded one layer ----
Point(1) = {-15, -15, 0}; Point(2) = {15, -15, 0}; Point(3) = {15, 15, 0}; Point(4) = {-15, 15, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 2, 3, 4} = 3 * r + 1;  // 3 r elements per side
Transfinite Surface {1};
Recombine Surface {1};
lower[] = Extrude {0, 0, 10} { Surface{1}; Layers{r}; Recombine; };
// lower[0] = top surface, lower[1] = volume

// ---- upper block: four quadrants around a centre point, so the load node is a geometric point ----
// (entity tags from 1000 up, clear of the tags the lower block's extrusion creates)
zb = 10; h = 12; a = 10;
Point(1011) = {-a, -a, zb}; Point(1012) = {0, -a, zb}; Point(1013) = {a, -a, zb};
Point(1014) = {-a, 0, zb};  Point(1015) = {0, 0, zb};  Point(1016) = {a, 0, zb};
Point(1017) = {-a, a, zb};  Point(1018) = {0, a, zb};  Point(1019) = {a, a, zb};
Line(1011) = {1011, 1012}; Line(1012) = {1012, 1013};
Line(1013) = {1014, 1015}; Line(1014) = {1015, 1016};
Line(1015) = {1017, 1018}; Line(1016) = {1018, 1019};
Line(1017) = {1011, 1014}; Line(1018) = {1014, 1017};
Line(1019) = {1012, 1015}; Line(1020) = {1015, 1018};
Line(1021) = {1013, 1016}; Line(1022) = {1016, 1019};
Curve Loop(1011) = {1011, 1019, -1013, -1017}; Plane Surface(1011) = {1011};
Curve Loop(1012) = {1012, 1021, -1014, -1019}; Plane Surface(1012) = {1012};
Curve Loop(1013) = {1013, 1020, -1015, -1018}; Plane Surface(1013) = {1013};
Curve Loop(1014) = {1014, 1022, -1016, -1020}; Plane Surface(1014) = {1014};
Transfinite Curve {1011:1022} = r + 1;       // r elements per quadrant side
Transfinite Surface {1011:1014};
Recombine Surface {1011:1014};
// One extrusion of all four quadrants, so shared edges stay shared (a conforming block).
// For each surface gmsh returns: top, volume, then its 4 lateral surfaces.
up[] = Extrude {0, 0, h} { Surface{1011:1014}; Layers{r}; Recombine; };
load_pt[] = Point In BoundingBox {-0.1, -0.1, zb + h - 0.1, 0.1, 0.1, zb + h + 0.1};

Physical Volume("lower") = {lower[1]};
Physical Volume("upper") = {up[1], up[7], up[13], up[19]};
Physical Surface("lower_base") = {1};                          // fixed in all directions
Physical Surface("lower_top") = {lower[0]};                    // master contact surface
Physical Surface("upper_bottom") = {1011:1014};           // slave contact surface
Physical Surface("upper_top") = {up[0], up[6], up[12], up[18]};
Physical Point("load_node") = {load_pt[0]};
// Supports that remove the upper block's rigid in-plane modes (frictionless contact
// carries no tangential force): the two nodes on the vertical axis x = y = 0 are held
// in x and y, the top node at (0, a) in x. By symmetry their reactions vanish.
axis_pts[] = Point In BoundingBox {-0.1, -0.1, zb - 0.1, 0.1, 0.1, zb + h + 0.1};
twist_pt[] = Point In BoundingBox {-0.1, a - 0.1, zb + h - 0.1, 0.1, a + 0.1, zb + h + 0.1};
Physical Point("upper_axis") = {axis_pts[]};
Physical Point("upper_twist") = {twist_pt[]};
