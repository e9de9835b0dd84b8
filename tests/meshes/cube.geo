// The unit cube [0, 1]^3 of one material (physical volume 1): hexahedra
// (hex = 1, transfinite and recombined, n cells per edge) or tetrahedra
// (hex = 0, unstructured, size 1/n at the corners so that gmsh's -clscale
// scales it). Boundary ids (physical surfaces): x = 0: 1, x = 1: 2, y = 0: 3,
// y = 1: 4, z = 0: 5, z = 1: 6.
DefineConstant[ hex = 1, n = 2 ];
Point(1) = {0, 0, 0, 1 / n};
Point(2) = {1, 0, 0, 1 / n};
Point(3) = {1, 1, 0, 1 / n};
Point(4) = {0, 1, 0, 1 / n};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
If (hex)
  Transfinite Curve {1, 2, 3, 4} = n + 1;
  Transfinite Surface {1};
  Recombine Surface {1};
  a[] = Extrude {0, 0, 1} { Surface{1}; Layers{n}; Recombine; };
Else
  a[] = Extrude {0, 0, 1} { Surface{1}; };
EndIf
// a[]: top, volume, then the sides from lines 1 (y = 0), 2 (x = 1),
// 3 (y = 1), 4 (x = 0).
Physical Volume(1) = {a[1]};
Physical Surface(1) = {a[5]};
Physical Surface(2) = {a[3]};
Physical Surface(3) = {a[2]};
Physical Surface(4) = {a[4]};
Physical Surface(5) = {1};
Physical Surface(6) = {a[0]};
