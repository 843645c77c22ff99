// Unstructured, distorted example: a 1 x 1 m plate with a circular hole of radius 0.25 m,
// meshed with the Blossom recombination into 8-node quadrilaterals (Gmsh type 16).
// Regenerate: gmsh -2 -order 2 -format msh22 plate_hole_q8.geo -o plate_hole_q8_v22.msh
//             gmsh -2 -order 2 -format msh41 plate_hole_q8.geo -o plate_hole_q8_v41.msh
//             gmsh -2 -order 2 -format msh41 -bin plate_hole_q8.geo -o plate_hole_q8_v41_bin.msh
Mesh.SecondOrderIncomplete = 1;
Mesh.RecombineAll = 1;
Mesh.RecombinationAlgorithm = 1;
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
