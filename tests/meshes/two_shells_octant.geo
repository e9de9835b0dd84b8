// One octant (x, y, z >= 0) of two concentric hollow spheres meshed on
// their own (not fragmented: no shared nodes on r = c): an inner shell
// a <= r <= c (physical volume 1) and an outer shell c <= r <= b (physical
// volume 2), a = 1, c = 1.5, b = 2, tetrahedra of size about lc_inner and
// lc_outer (at the points, so that gmsh's -clscale scales them).
// Boundary ids (physical surfaces): the planes x = 0: 1, y = 0: 2, z = 0: 3
// (both shells), r = a: 4, r = b: 5, the inner shell's outer surface: 6,
// the outer shell's inner surface: 7.
SetFactory("OpenCASCADE");
DefineConstant[ lc_inner = 0.15, lc_outer = 0.2 ];
a = 1;
c = 1.5;
b = 2;
Sphere(1) = {0, 0, 0, c, 0, Pi/2, Pi/2};
Sphere(2) = {0, 0, 0, a, 0, Pi/2, Pi/2};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Sphere(4) = {0, 0, 0, b, 0, Pi/2, Pi/2};
Sphere(5) = {0, 0, 0, c, 0, Pi/2, Pi/2};
BooleanDifference(6) = { Volume{4}; Delete; }{ Volume{5}; Delete; };
eps = 1e-6;
x0() = {}; y0() = {}; z0() = {}; ra() = {}; rb() = {}; rc_in() = {};
rc_out() = {};
For v In {3 : 6 : 3}
  s() = Boundary{ Volume{v}; };
  For i In {0 : #s() - 1}
    box() = BoundingBox Surface{ s(i) };
    If (box(3) < eps)
      x0() += s(i);
    ElseIf (box(4) < eps)
      y0() += s(i);
    ElseIf (box(5) < eps)
      z0() += s(i);
    ElseIf (box(3) < a + eps && box(4) < a + eps && box(5) < a + eps)
      ra() += s(i);
    ElseIf (box(3) < c + eps && box(4) < c + eps && box(5) < c + eps)
      If (v == 3)
        rc_in() += s(i);
      Else
        rc_out() += s(i);
      EndIf
    Else
      rb() += s(i);
    EndIf
  EndFor
EndFor
Physical Volume(1) = {3};
Physical Volume(2) = {6};
Physical Surface(1) = {x0()};
Physical Surface(2) = {y0()};
Physical Surface(3) = {z0()};
Physical Surface(4) = {ra()};
Physical Surface(5) = {rb()};
Physical Surface(6) = {rc_in()};
Physical Surface(7) = {rc_out()};
MeshSize{ PointsOf{ Volume{3}; } } = lc_inner;
MeshSize{ PointsOf{ Volume{6}; } } = lc_outer;
