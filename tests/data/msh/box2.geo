// 2x2x2 structured hex8 box [0,1]x[0,2]x[0,0.3] for the MSH reader tests.
// Regenerate: gmsh box2.geo -3 -format msh22 -o box2_v22_ascii.msh (and -bin, msh41).
Point(1) = {0, 0, 0};
Point(2) = {1, 0, 0};
Point(3) = {1, 2, 0};
Point(4) = {0, 2, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 2, 3, 4} = 3;
Transfinite Surface{1};
Recombine Surface{1};
out[] = Extrude {0, 0, 0.3} { Surface{1}; Layers{2}; Recombine; };
Physical Volume("block") = {out[1]};
Physical Surface("base") = {1};
Physical Surface("top") = {out[0]};
Physical Curve("edge") = {1};
Physical Point("origin") = {1};
