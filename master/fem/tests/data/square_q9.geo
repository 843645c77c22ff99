// 1 x 1 m square, 3 x 2 transfinite, recombined to quadrilaterals.
// Second order complete: 9-node Lagrange quadrilaterals (Gmsh type 10), 3 x 2 elements.
// Regenerate: gmsh -2 -order 2 -format msh22 square_q9.geo -o square_q9_v22.msh
//             gmsh -2 -order 2 -format msh41 square_q9.geo -o square_q9_v41.msh
//             gmsh -2 -order 2 -format msh41 -bin square_q9.geo -o square_q9_v41_bin.msh
Mesh.SecondOrderIncomplete = 0;
Point(1) = {0, 0, 0, 1};
Point(2) = {1, 0, 0, 1};
Point(3) = {1, 1, 0, 1};
Point(4) = {0, 1, 0, 1};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 3} = 4;
Transfinite Curve {2, 4} = 3;
Transfinite Surface {1};
Recombine Surface {1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Surface("panel") = {1};
