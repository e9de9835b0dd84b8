// An uncemented tibial component on the proximal tibia as a 3D block model:
// a Ti6Al4V tray (material 1, 70 x 50 x 4 mm) under a chirulen insert
// (material 2, 10 mm thick), bonded (shared nodes), standing on a block of
// bone (material 3, 80 x 60 x 30 mm) meshed on its own (no shared nodes:
// the tray-bone interface is contact), hexahedra about h (tray and insert)
// and h_bone (bone) metres apart: the interface's meshes do not match.
// Boundary ids (physical surfaces): 1 the tray's bottom, 2 the insert's top
// (the femoral condyles press here), 3 the other faces of tray and insert,
// 4 the bone's bottom, 5 the bone's top, 6 the bone's sides.
DefineConstant[ h = 0.004, h_bone = 0.006 ];
W = 0.070;  D = 0.050;  tray = 0.004;  insert = 0.010;
margin = 0.005;  bone = 0.030;
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

// The bone's top at z = 0, its own points: the block below the tray.
Point(1001) = {-W/2 - margin, -D/2 - margin, 0};
Point(1002) = { W/2 + margin, -D/2 - margin, 0};
Point(1003) = { W/2 + margin,  D/2 + margin, 0};
Point(1004) = {-W/2 - margin,  D/2 + margin, 0};
Line(1001) = {1001, 1002};
Line(1002) = {1002, 1003};
Line(1003) = {1003, 1004};
Line(1004) = {1004, 1001};
Curve Loop(1001) = {1001, 1002, 1003, 1004};
Plane Surface(1001) = {1001};
Transfinite Curve {1001, 1003} = Ceil((W + 2 * margin) / h_bone) + 1;
Transfinite Curve {1002, 1004} = Ceil((D + 2 * margin) / h_bone) + 1;
Transfinite Surface {1001};
Recombine Surface {1001};
c[] = Extrude {0, 0, -bone} { Surface{1001}; Layers{Ceil(bone / h_bone)}; Recombine; };

Physical Volume(1) = {a[1]};
Physical Volume(2) = {b[1]};
Physical Volume(3) = {c[1]};
Physical Surface(1) = {1};
Physical Surface(2) = {b[0]};
Physical Surface(3) = {a[2], a[3], a[4], a[5], b[2], b[3], b[4], b[5]};
Physical Surface(4) = {c[0]};
Physical Surface(5) = {1001};
Physical Surface(6) = {c[2], c[3], c[4], c[5]};
