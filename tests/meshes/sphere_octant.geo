// One octant (x, y, z >= 0) of a hollow sphere a <= r <= b, a = 1, b = 2,
// meshed with tetrahedra of size about lc (at the points, so that gmsh's
// -clscale scales it). Material id 1 (physical volume);
// boundary ids (physical surfaces): the planes x = 0: 1, y = 0: 2, z = 0: 3,
// the inner sphere r = a: 4, the outer sphere r = b: 5.
SetFactory("OpenCASCADE");
DefineConstant[ lc = 0.6 ];
a = 1;
b = 2;
Sphere(1) = {0, 0, 0, b, 0, Pi/2, Pi/2};
Sphere(2) = {0, 0, 0, a, 0, Pi/2, Pi/2};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
// Sort the boundary surfaces by their bounding boxes.
eps = 1e-6;
x0() = {}; y0() = {}; z0() = {}; inner() = {}; outer() = {};
s() = Boundary{ Volume{3}; };
For i In {0 : #s() - 1}
  box() = BoundingBox Surface{ s(i) };
  If (box(3) < eps)
    x0() += s(i);
  ElseIf (box(4) < eps)
    y0() += s(i);
  ElseIf (box(5) < eps)
    z0() += s(i);
  ElseIf (box(3) < a + eps && box(4) < a + eps && box(5) < a + eps)
    inner() += s(i);
  Else
    outer() += s(i);
  EndIf
EndFor
Physical Volume(1) = {3};
Physical Surface(1) = {x0()};
Physical Surface(2) = {y0()};
Physical Surface(3) = {z0()};
Physical Surface(4) = {inner()};
Physical Surface(5) = {outer()};
MeshSize{ PointsOf{ Volume{3}; } } = lc;
