// Cantilever beam for the solver-core pipeline and tests.
// Dimensions (ours; units mm, N, MPa): x in [0, 10] (length), y in [0, 1], z in [0, 1].
// Mesh: 20 x 2 x 2 hex8 (transfinite, recombined).
// Regenerate: gmsh meshes/cantilever.geo -3 -format msh41 -o meshes/cantilever.msh
Mesh.MshFileVersion = 4.1;
Point(1) = {0, 0, 0}; Point(2) = {0, 1, 0}; Point(3) = {0, 1, 1}; Point(4) = {0, 0, 1};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 2, 3, 4} = 3;          // 2 elements across the section
Transfinite Surface {1};
Recombine Surface {1};
out[] = Extrude {10, 0, 0} { Surface{1}; Layers{20}; Recombine; };
// out[0] = tip face (x = 10), out[1] = volume, out[2..5] = lateral faces
Physical Volume("beam") = {out[1]};
Physical Surface("clamped") = {1};
Physical Surface("tip") = {out[0]};
Physical Surface("top") = {out[4]};
