// The box of issue 26: all hexahedra, unstructured (gmsh's subdivision of tetrahedra),
// so its top has boundary nodes in 1 and in 3 faces and interior nodes of valence ≠ 4.
// gmsh allhex_box.geo -3 -clscale 4 -format msh41 -o allhex_box.msh
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 0.3};
Mesh.SubdivisionAlgorithm = 2;
Physical Volume("block") = {1};
Physical Surface("top") = {6};
Physical Surface("bottom") = {5};
