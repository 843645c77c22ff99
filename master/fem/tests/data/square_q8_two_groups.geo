// The 2 x 2 eight-node square of square_q8.geo, with its surface in two physical groups
// ("panel", "other") and its boundary curves also in a group "all". Format 2.2 repeats such
// elements once per group; the reader must see each element once.
// Regenerate: gmsh -2 -order 2 -format msh22 square_q8_two_groups.geo -o square_q8_two_groups_v22.msh
//             gmsh -2 -order 2 -format msh41 square_q8_two_groups.geo -o square_q8_two_groups_v41.msh
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
Physical Surface("other") = {1};
Physical Curve("all") = {1,2,3,4};
