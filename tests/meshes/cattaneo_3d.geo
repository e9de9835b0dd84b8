// Cattaneo-Mindlin point contact: two equal hemispheres of radius R, the
// lower half of the sphere centred at (0, 0, R) on the upper half of the
// sphere centred at (0, 0, -R), touching at the origin; mirror images of
// each other about z = 0 (so that, for equal materials, a normal load moves
// the two sides of the interface alike, as two half-spaces do). Whole
// hemispheres (on a half model y >= 0 the slave vertices on the symmetry
// plane could not stick: doc/friction.md). Meshed on their own (OpenCASCADE, not fragmented: no shared nodes), tetrahedra of size
// h_contact within r_fine of the origin, growing to h_far.
// Physical volumes: 1 upper, 2 lower. Physical surfaces: 2 upper flat top
// (z = R), 3 lower flat bottom (z = -R), 4 upper curved surface (slave),
// 5 lower curved surface (master).
SetFactory("OpenCASCADE");
DefineConstant[ R = 1, h_contact = 0.01, h_far = 0.25, r_fine = 0.1 ];
Sphere(1) = {0, 0, R, R};
Box(2) = {-R, -R, 0, 2 * R, 2 * R, R};
BooleanIntersection(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Sphere(4) = {0, 0, -R, R};
Box(5) = {-R, -R, -R, 2 * R, 2 * R, R};
BooleanIntersection(6) = { Volume{4}; Delete; }{ Volume{5}; Delete; };
e = 1e-6 * R;
top[] = Surface In BoundingBox{-R - e, -R - e, R - e, R + e, R + e, R + e};
bottom[] = Surface In BoundingBox{-R - e, -R - e, -R - e, R + e, R + e, -R + e};
upper[] = Abs(Boundary{ Volume{3}; });
upper[] -= {top[]};
lower[] = Abs(Boundary{ Volume{6}; });
lower[] -= {bottom[]};
Physical Volume(1) = {3};
Physical Volume(2) = {6};
Physical Surface(2) = {top[]};
Physical Surface(3) = {bottom[]};
Physical Surface(4) = {upper[]};
Physical Surface(5) = {lower[]};
Field[1] = Ball;
Field[1].Radius = r_fine;
Field[1].Thickness = 0.5 * R;
Field[1].VIn = h_contact;
Field[1].VOut = h_far;
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
