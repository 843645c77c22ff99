// slope.geo: a 1 m high slope at 1:2 (26.6 degrees) on 1 m of foundation soil, for
// examples/slope.toml. Left of the toe the ground is at y = 1 m, the crest at y = 2 m from
// x = 4 m on. Eight-node quadrilaterals, 3 x 3 per block.
//   gmsh -2 -order 2 -format msh41 slope.geo -o slope.msh
Mesh.SecondOrderIncomplete = 1;
Point(1) = {0, 0, 0};
Point(2) = {2, 0, 0};
Point(3) = {4, 0, 0};
Point(4) = {6, 0, 0};
Point(5) = {6, 2, 0};
Point(6) = {4, 2, 0};
Point(7) = {2, 1, 0};
Point(8) = {0, 1, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};   // right side
Line(5) = {5, 6};   // crest
Line(6) = {6, 7};   // slope face
Line(7) = {7, 8};   // ground at the toe
Line(8) = {8, 1};   // left side
Line(9) = {2, 7};
Line(10) = {3, 6};
Curve Loop(1) = {1, 9, 7, 8};
Plane Surface(1) = {1};
Curve Loop(2) = {2, 10, 6, -9};
Plane Surface(2) = {2};
Curve Loop(3) = {3, 4, 5, -10};
Plane Surface(3) = {3};
Transfinite Curve {1, 2, 3, 4, 5, 6, 7, 8, 9, 10} = 4;
Transfinite Surface {1, 2, 3};
Recombine Surface {1, 2, 3};
Physical Curve("base") = {1, 2, 3};
Physical Curve("right") = {4};
Physical Curve("crest") = {5};
Physical Curve("face") = {6};
Physical Curve("toe") = {7};
Physical Curve("left") = {8};
Physical Surface("soil") = {1, 2, 3};
