// Cattaneo-Mindlin line contact, plane strain, the whole model (tangential
// loads are not symmetric): two equal half-discs of radius R, the lower
// half of the disc centred at (0, R) on the upper half of the disc centred
// at (0, -R); they touch at the origin. Mirror images of each other, so
// that (for equal materials) a normal load moves the two sides of the
// interface alike and gives no tangential traction, as two half-spaces
// do; a block instead of the lower disc does not (its surface stretches
// less than the disc's). Meant to be loaded by moving the upper disc's
// flat side down (u_y given, u_x free; it also carries the moment of a
// tangential load) with the lower flat side held.
Geometry.AutoCoherence = 0;
If (!Exists(R))
  R = 1;
EndIf
If (!Exists(lc_fine))
  lc_fine = 0.01;
EndIf
If (!Exists(lc_coarse))
  lc_coarse = 0.2;
EndIf

Point(1) = {-R, R, 0};
Point(2) = {0, 0, 0};
Point(3) = {R, R, 0};
Point(4) = {0, R, 0};
Circle(1) = {1, 4, 2};
Circle(2) = {2, 4, 3};
Line(3) = {3, 1};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};

Point(11) = {-R, -R, 0};
Point(12) = {0, 0, 0};
Point(13) = {R, -R, 0};
Point(14) = {0, -R, 0};
Circle(11) = {11, 14, 12};
Circle(12) = {12, 14, 13};
Line(13) = {13, 11};
Curve Loop(2) = {-11, -12, -13};
Plane Surface(2) = {2};

// Fine over the contact zone (half-width about 0.1 R), growing to
// lc_coarse over 0.5 R.
Field[1] = Box;
Field[1].VIn = lc_fine;
Field[1].VOut = lc_coarse;
Field[1].XMin = -0.2 * R;
Field[1].XMax = 0.2 * R;
Field[1].YMin = -0.03 * R;
Field[1].YMax = 0.03 * R;
Field[1].Thickness = 0.5 * R;
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Recombine Surface{1, 2};
Mesh.SubdivisionAlgorithm = 1;

Physical Surface(1) = {1};      // upper disc
Physical Surface(2) = {2};      // lower disc
Physical Curve(1) = {1, 2};     // upper arc: contact slave side
Physical Curve(2) = {3};        // upper flat side: moved down
Physical Curve(4) = {11, 12};   // lower arc: contact master side
Physical Curve(5) = {13};       // lower flat side: held
