// Two concentric quarter rings in contact at r = b, meshed independently
// (non-matching along the interface): inner ring a <= r <= b, outer ring
// b <= r <= c, x, y >= 0, quadrilaterals. The rings share no points
// (Geometry.AutoCoherence = 0), so their sides at r = b can be a contact
// interface. Physical surfaces: 1 inner ring, 2 outer ring. Physical curves:
// 1 inner arc r = a, 2 inner ring at r = b, 3 outer ring at r = b,
// 4 outer arc r = c, 5 the edges on y = 0, 6 the edges on x = 0.
// Parameters (-setnumber): n_inner, n_outer vertices along the arcs.
Geometry.AutoCoherence = 0;
a = 1; b = 1.5; c = 2.5;
DefineConstant[n_inner = 9, n_outer = 7, n_radial = 4];
Point(1) = {0, 0, 0};
Point(2) = {a, 0, 0}; Point(3) = {b, 0, 0};
Point(4) = {0, b, 0}; Point(5) = {0, a, 0};
Point(12) = {b, 0, 0}; Point(13) = {c, 0, 0};
Point(14) = {0, c, 0}; Point(15) = {0, b, 0};
Line(1) = {2, 3}; Circle(2) = {3, 1, 4}; Line(3) = {4, 5};
Circle(4) = {5, 1, 2};
Line(11) = {12, 13}; Circle(12) = {13, 1, 14}; Line(13) = {14, 15};
Circle(14) = {15, 1, 12};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {11, 12, 13, 14};
Plane Surface(2) = {2};
Transfinite Curve{1, 3, 11, 13} = n_radial;
Transfinite Curve{2, 4} = n_inner;
Transfinite Curve{12, 14} = n_outer;
Transfinite Surface{1, 2};
Recombine Surface{1, 2};
Physical Surface(1) = {1};
Physical Surface(2) = {2};
Physical Curve(1) = {4};
Physical Curve(2) = {2};
Physical Curve(3) = {14};
Physical Curve(4) = {12};
Physical Curve(5) = {1, 11};
Physical Curve(6) = {3, 13};
