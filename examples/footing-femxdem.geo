// footing-femxdem.geo: FEMxDEM's strip footing, for examples/footing-femxdem.toml.
// The half of the problem right of the footing's centre line: 0.6 m of soil beside the
// centre line, 0.4 m deep, the footing's half-width B = 0.05 m on the left of the top edge.
// Unstructured six-node triangles, `fine` (m) at the footing's edge, `coarse` at the far
// corners and the bottom of the centre line.
//   gmsh -2 -order 2 -format msh41 -setnumber fine 0.01 -setnumber coarse 0.06 footing-femxdem.geo -o footing-femxdem.msh
//   gmsh -2 -order 2 -format msh41 -setnumber fine 0.0032 -setnumber coarse 0.026 footing-femxdem.geo -o footing-femxdem-2500.msh
Mesh.SecondOrderIncomplete = 1;
DefineConstant[ fine = 0.01, coarse = 0.06 ];
b = 0.05;  // half-width of the footing (m)
l = 0.6;   // soil beside the centre line (m)
h = 0.4;   // depth (m)
Point(1) = {0, 0, 0, coarse};
Point(2) = {l, 0, 0, coarse};
Point(3) = {l, h, 0, coarse};
Point(4) = {b, h, 0, fine};
Point(5) = {0, h, 0, fine};
Line(1) = {1, 2};  // base
Line(2) = {2, 3};  // far side
Line(3) = {3, 4};  // ground surface beside the footing
Line(4) = {4, 5};  // footing
Line(5) = {5, 1};  // centre line
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
Physical Curve("base") = {1};
Physical Curve("side") = {2};
Physical Curve("surface") = {3};
Physical Curve("footing") = {4};
Physical Curve("axis") = {5};
Physical Surface("soil") = {1};
