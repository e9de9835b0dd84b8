// Hertz line contact, plane strain, symmetric half (x >= 0): a quarter of an
// elastic cylinder of radius R (the lower half of a half-cylinder, centre
// (0, R)) resting on an elastic block [0, 2R] x [-2R, 0]; they touch at the
// origin. The two bodies have distinct vertices (AutoCoherence off).
// Mesh sizes: lc_fine in the contact zone, lc_coarse elsewhere; gmsh's
// subdivision into quadrilaterals halves both.
Geometry.AutoCoherence = 0;
// Defaults; "gmsh -setnumber lc_fine 0.005" (Mesh/Gmsh arguments) overrides.
If (!Exists(R))
  R = 1;
EndIf
If (!Exists(lc_fine))
  lc_fine = 0.01;
EndIf
If (!Exists(lc_coarse))
  lc_coarse = 0.2;
EndIf

Point(1) = {0, 0, 0};
Point(2) = {R, R, 0};
Point(3) = {0, R, 0};
Circle(1) = {1, 3, 2};
Line(2) = {2, 3};
Line(3) = {3, 1};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};

Point(11) = {0, 0, 0};
Point(12) = {2 * R, 0, 0};
Point(13) = {2 * R, -2 * R, 0};
Point(14) = {0, -2 * R, 0};
Line(11) = {11, 12};
Line(12) = {12, 13};
Line(13) = {13, 14};
Line(14) = {14, 11};
Curve Loop(2) = {11, 12, 13, 14};
Plane Surface(2) = {2};

// Fine where the contact zone (half-width a ~ 0.15 R for the default load)
// lies, growing to lc_coarse over 0.5 R.
Field[1] = Box;
Field[1].VIn = lc_fine;
Field[1].VOut = lc_coarse;
Field[1].XMin = -0.1 * R;
Field[1].XMax = 0.25 * R;
Field[1].YMin = -0.05 * R;
Field[1].YMax = 0.05 * R;
Field[1].Thickness = 0.5 * R;
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

// -setnumber triangles 1: leave the triangles (P1) instead of making
// quadrilaterals.
If (!Exists(triangles))
  triangles = 0;
EndIf
If (triangles == 0)
  Recombine Surface{1, 2};
  Mesh.SubdivisionAlgorithm = 1;
EndIf

Physical Surface(1) = {1};      // cylinder
Physical Surface(2) = {2};      // block
Physical Curve(1) = {1};        // cylinder arc: contact slave side
Physical Curve(2) = {2};        // cylinder top: load
Physical Curve(3) = {3, 14};    // symmetry line x = 0: sliding
Physical Curve(4) = {11};       // block top: contact master side
Physical Curve(5) = {13};       // block bottom: fixed
Physical Curve(6) = {12};       // block side: free
