// Quarter annulus a = 1 <= r <= b = 2, x, y >= 0, meshed in quadrilaterals.
// Physical curves: 1 bottom (y = 0), 2 outer arc, 3 left (x = 0), 4 inner arc.
a = 1; b = 2;
n_radial = 3; n_arc = 5;
Point(1) = {0, 0, 0};
Point(2) = {a, 0, 0};
Point(3) = {b, 0, 0};
Point(4) = {0, b, 0};
Point(5) = {0, a, 0};
Line(1) = {2, 3};
Circle(2) = {3, 1, 4};
Line(3) = {4, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = n_radial;
Transfinite Curve{2, 4} = n_arc;
Transfinite Surface{1};
Recombine Surface{1};
Physical Surface(1) = {1};
Physical Curve(1) = {1};
Physical Curve(2) = {2};
Physical Curve(3) = {3};
Physical Curve(4) = {4};
