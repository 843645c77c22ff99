// A mesh mixing 8-node quadrilaterals and 6-node triangles, as Gmsh's simple recombination
// (algorithm 0) leaves it: the plate of plate_hole_q8.geo, 14 Q8 and 10 T6 elements.
// Q9 + T6: the same with `Mesh.SecondOrderIncomplete = 0;` (the line below changed in a copy;
// Gmsh's -setnumber is overridden by the line) into plate_hole_mixed_q9_v41.msh.
// Regenerate: gmsh -2 -order 2 -format msh22 plate_hole_mixed.geo -o plate_hole_mixed_v22.msh
//             gmsh -2 -order 2 -format msh41 plate_hole_mixed.geo -o plate_hole_mixed_v41.msh
//             gmsh -2 -order 2 -format msh41 -bin plate_hole_mixed.geo -o plate_hole_mixed_v41_bin.msh
Mesh.SecondOrderIncomplete = 1;
Mesh.RecombineAll = 1;
Mesh.RecombinationAlgorithm = 0;
Mesh.Algorithm = 6;
Mesh.CharacteristicLengthMin = 0.3;
Mesh.CharacteristicLengthMax = 0.3;
Point(1) = {0, 0, 0, 0.3};
Point(2) = {1, 0, 0, 0.3};
Point(3) = {1, 1, 0, 0.3};
Point(4) = {0, 1, 0, 0.3};
Point(5) = {0.5, 0.5, 0, 0.3};
Point(6) = {0.75, 0.5, 0, 0.3};
Point(7) = {0.25, 0.5, 0, 0.3};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 6};
Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6};
Plane Surface(1) = {1, 2};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Curve("hole") = {5, 6};
Physical Point("corner") = {1};
Physical Surface("plate") = {1};
