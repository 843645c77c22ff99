// 1 x 1 m square, 2 x 2 transfinite, recombined to quadrilaterals.
// Second order incomplete: 8-node serendipity quadrilaterals (Gmsh type 16).
// Regenerate: gmsh -2 -order 2 -format msh22 square_q8.geo -o square_q8_v22.msh
//             gmsh -2 -order 2 -format msh41 square_q8.geo -o square_q8_v41.msh
//             gmsh -2 -order 2 -format msh41 -bin square_q8.geo -o square_q8_v41_bin.msh
Mesh.SecondOrderIncomplete = 1;
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
Transfinite Curve {1, 2, 3, 4} = 3;
Transfinite Surface {1};
Recombine Surface {1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Surface("panel") = {1};
