// A tibial component as a block model in 3D: a Ti6Al4V tray (material 1,
// 70 x 50 x 4 mm) under a chirulen insert (material 2, 10 mm thick), bonded
// (shared nodes). Hexahedra, about h metres apart. Boundary ids (physical
// surfaces): the tray's bottom 1 (on the bone), the insert's top 2 (the
// femoral condyles press here), all other faces 3.
DefineConstant[ h = 0.005 ];
W = 0.070;  D = 0.050;  tray = 0.004;  insert = 0.010;
Point(1) = {-W/2, -D/2, 0};
Point(2) = { W/2, -D/2, 0};
Point(3) = { W/2,  D/2, 0};
Point(4) = {-W/2,  D/2, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 3} = Ceil(W / h) + 1;
Transfinite Curve {2, 4} = Ceil(D / h) + 1;
Transfinite Surface {1};
Recombine Surface {1};
a[] = Extrude {0, 0, tray} { Surface{1}; Layers{Ceil(tray / h) + 1}; Recombine; };
b[] = Extrude {0, 0, insert} { Surface{a[0]}; Layers{Ceil(insert / h) + 1}; Recombine; };
Physical Volume(1) = {a[1]};
Physical Volume(2) = {b[1]};
Physical Surface(1) = {1};
Physical Surface(2) = {b[0]};
Physical Surface(3) = {a[2], a[3], a[4], a[5], b[2], b[3], b[4], b[5]};
