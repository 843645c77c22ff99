// footing.geo: the half of a strip footing's soil, for examples/footing.toml.
// 3 m wide (x from the footing's centre line), 2 m deep; the footing is 1 m wide, its half
// (0.5 m) on the left of the top edge. A mixed mesh, as Gmsh makes one: eight-node
// quadrilaterals in a structured block under the footing (surface 1, recombined), six-node
// triangles beside it (surface 2, unstructured: 0.3 m at the footing's edge, 0.8 m at the
// far corners), sharing the second-order edges of line 7.
//   gmsh -2 -order 2 -format msh41 footing.geo -o footing.msh
Mesh.SecondOrderIncomplete = 1;
b = 0.5;  // half-width of the footing (m)
w = 3.0;  // half-width of the soil (m)
h = 2.0;  // depth (m)
Point(1) = {0, 0, 0};
Point(2) = {b, 0, 0, 0.5};
Point(3) = {w, 0, 0, 0.8};
Point(4) = {w, h, 0, 0.8};
Point(5) = {b, h, 0, 0.3};  // finer at the footing's edge
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
Transfinite Curve {6} = 5 Using Progression 1.25;
Transfinite Curve {7} = 5 Using Progression 1/1.25;
Transfinite Surface {1};
Recombine Surface {1};
Physical Curve("base") = {1, 2};
Physical Curve("side") = {3};
Physical Curve("surface") = {4};
Physical Curve("footing") = {5};
Physical Curve("axis") = {6};
Physical Surface("soil") = {1, 2};
