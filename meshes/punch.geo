// A punch pressed into an unstructured block (issue 26): the block is meshed by gmsh
// with all hexahedra but unstructured (tetrahedra split into hexahedra,
// Mesh.SubdivisionAlgorithm = 2), so its top, the contact master, has interior nodes
// of valence 3 to 6 and boundary nodes in 1 and 3 faces. The punch is a structured
// block (transfinite, then split once by the same algorithm). Units: mm.
// gmsh meshes/punch.geo -3 -format msh41 -o meshes/punch.msh  (gmsh 4.15, pip)
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 0.3};
Box(2) = {0.25, 0.25, 0.3, 0.5, 0.5, 0.2};
Mesh.MeshSizeMax = 0.16;
Transfinite Curve{ Abs(Boundary{ Boundary{ Volume{2}; } }) } = 5;
Transfinite Surface{ Boundary{ Volume{2}; } };
Recombine Surface{ Boundary{ Volume{2}; } };
Transfinite Volume{2};
Mesh.SubdivisionAlgorithm = 2;
Physical Volume("block") = {1};
Physical Volume("punch") = {2};
Physical Surface("block_top") = {6};
Physical Surface("block_bottom") = {5};
Physical Surface("punch_bottom") = {11};
Physical Surface("punch_top") = {12};
