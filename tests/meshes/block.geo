// A box [0, 1] x [0, 1] x [0, 2] of one material (physical volume 1), or two
// bonded materials (two = 1: volumes 1 below z = 1 and 2 above, sharing the
// nodes of the interface). Hexahedra (hex = 1, transfinite and recombined) or
// tetrahedra (hex = 0); n cells per unit length along the edges.
// Boundary ids (physical surfaces): x = 0: 1, x = 1: 2, y = 0: 3, y = 1: 4,
// z = 0: 5, z = 2: 6.
DefineConstant[ hex = 1, n = 2, two = 0 ];
Point(1) = {0, 0, 0};
Point(2) = {1, 0, 0};
Point(3) = {1, 1, 0};
Point(4) = {0, 1, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve {1, 2, 3, 4} = n + 1;
Transfinite Surface {1};
If (hex)
  Recombine Surface {1};
  a[] = Extrude {0, 0, 1} { Surface{1}; Layers{n}; Recombine; };
  b[] = Extrude {0, 0, 1} { Surface{a[0]}; Layers{n}; Recombine; };
Else
  a[] = Extrude {0, 0, 1} { Surface{1}; };
  b[] = Extrude {0, 0, 1} { Surface{a[0]}; };
  Transfinite Curve {:} = n + 1;
EndIf
// a[]: top, volume, then the sides from lines 1 (y = 0), 2 (x = 1),
// 3 (y = 1), 4 (x = 0); b[] likewise above.
If (two)
  Physical Volume(1) = {a[1]};
  Physical Volume(2) = {b[1]};
Else
  Physical Volume(1) = {a[1], b[1]};
EndIf
Physical Surface(1) = {a[5], b[5]};
Physical Surface(2) = {a[3], b[3]};
Physical Surface(3) = {a[2], b[2]};
Physical Surface(4) = {a[4], b[4]};
Physical Surface(5) = {1};
Physical Surface(6) = {b[0]};
