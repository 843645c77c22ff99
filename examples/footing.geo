// footing.geo: the half of a strip footing's soil, for examples/footing.toml.
// 3 m wide (x from the footing's centre line), 2 m deep; the footing is 1 m wide, its half
// (0.5 m) on the left of the top edge. Eight-node quadrilaterals, finer under the footing.
//   gmsh -2 -order 2 -format msh41 footing.geo -o footing.msh
Mesh.SecondOrderIncomplete = 1;
b = 0.5;  // half-width of the footing (m)
w = 3.0;  // half-width of the soil (m)
h = 2.0;  // depth (m)
Point(1) = {0, 0, 0};
Point(2) = {b, 0, 0};
Point(3) = {w, 0, 0};
Point(4) = {w, h, 0};
Point(5) = {b, h, 0};
Point(6) = {0, h, 0};
Line(1) = {1, 2};   // base under the footing
Line(2) = {2, 3};   // base beside it
Line(3) = {3, 4};   // far side
Line(4) = {4, 5};   // ground surface
Line(5) = {5, 6};   // footing
Line(6) = {6, 1};   // symmetry axis
Line(7) = {2, 5};   // inner line below the footing's edge
Curve Loop(1) = {1, 7, 5, 6};
Plane Surface(1) = {1};
Curve Loop(2) = {2, 3, 4, -7};
Plane Surface(2) = {2};
Transfinite Curve {1, 5} = 3;
Transfinite Curve {2} = 6 Using Progression 1.3;
Transfinite Curve {4} = 6 Using Progression 1/1.3;
Transfinite Curve {6} = 5 Using Progression 1.25;
Transfinite Curve {3, 7} = 5 Using Progression 1/1.25;
Transfinite Surface {1};
Transfinite Surface {2};
Recombine Surface {1, 2};
Physical Curve("base") = {1, 2};
Physical Curve("side") = {3};
Physical Curve("surface") = {4};
Physical Curve("footing") = {5};
Physical Curve("axis") = {6};
Physical Surface("soil") = {1, 2};
