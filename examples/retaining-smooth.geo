// retaining-smooth.geo: FEMxDEM's retainingSmooth backfill, for examples/retaining-smooth-*.toml.
// 0.4 m wide, 0.2 m deep; the smooth wall is the right edge above y = 0.03 m (0.17 m high),
// the base the right edge below it. A structured mesh of eight-node quadrilaterals, nx x ny,
// split at the wall's foot so that it falls on a row of nodes (nb = Round(ny * 0.15) rows
// below it, as Gmsh rounds: 1 of 30 mm for ny = 10, 3 of 10 mm for ny = 20).
//   gmsh -2 -order 2 -format msh41 -setnumber nx 20 -setnumber ny 10 retaining-smooth.geo -o retaining-smooth.msh
//   gmsh -2 -order 2 -format msh41 -setnumber nx 40 -setnumber ny 20 retaining-smooth.geo -o retaining-smooth-40x20.msh
Mesh.SecondOrderIncomplete = 1;
Mesh.RecombineAll = 1;
DefineConstant[ nx = 40, ny = 20 ];
l = 0.4;       // width of the backfill (m)
h = 0.2;       // depth (m)
hb = 0.03;     // height of the base below the wall (m)
nb = Round(ny * hb / h);  // rows below the wall's foot
Point(1) = {0, 0, 0};
Point(2) = {l, 0, 0};
Point(3) = {l, hb, 0};
Point(4) = {l, h, 0};
Point(5) = {0, h, 0};
Point(6) = {0, hb, 0};
Line(1) = {1, 2};   // bottom
Line(2) = {2, 3};   // base, below the wall
Line(3) = {3, 4};   // wall
Line(4) = {4, 5};   // ground surface
Line(5) = {5, 6};   // left, upper part
Line(6) = {6, 1};   // left, lower part
Line(7) = {6, 3};   // the row of nodes at the wall's foot
Curve Loop(1) = {1, 2, -7, 6};
Plane Surface(1) = {1};
Curve Loop(2) = {7, 3, 4, 5};
Plane Surface(2) = {2};
Transfinite Curve {1, 4, 7} = nx + 1;
Transfinite Curve {2, 6} = nb + 1;
Transfinite Curve {3, 5} = ny - nb + 1;
Transfinite Surface {1, 2};
Recombine Surface {1, 2};
Physical Curve("bottom") = {1};
Physical Curve("base") = {2};
Physical Curve("wall") = {3};
Physical Curve("top") = {4};
Physical Curve("left") = {5, 6};
// The wall's foot, shared by the wall and the base: its reaction is reported apart, since
// it carries the stress concentration where the moving wall meets the fixed base.
Physical Point("foot") = {3};
Physical Surface("backfill") = {1, 2};
