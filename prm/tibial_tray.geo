// Uncemented tibial tray on the proximal tibia, sagittal section (x
// anterior, y up) [m]: the fixation interface of knee.geo's tray taken as
// contact with friction instead of bonded.
//  - proximal tibia (bone), 60 mm wide, 60 mm of it below the cut;
//  - Ti6Al4V tray plate, 52 mm, 4 mm thick, on the cut (its own points:
//    the tray-bone interface is a contact interface);
//  - UHMWPE insert (chirulen), 8 mm, bonded to the tray (shared curve).
// Simplification: no stem or pegs, so the tray is held by friction on the
// cut alone (the worst case for micromotion before bone ingrowth).
// Parameters (gmsh -setnumber NAME VALUE): lc, lc_contact (mesh sizes,
// halved by the quadrilateral subdivision).
Geometry.AutoCoherence = 0;
If (!Exists(lc))
  lc = 0.004;
EndIf
If (!Exists(lc_contact))
  lc_contact = 0.001;
EndIf

w_bone = 0.030;
w = 0.026;        // half width of tray and insert
h_bone = 0.060;
t_tray = 0.004;
t_insert = 0.008;

// Bone: bottom, sides, and its cut in three parts (under the tray: the
// contact master).
Point(1) = {-w_bone, -h_bone, 0};
Point(2) = {w_bone, -h_bone, 0};
Point(3) = {w_bone, 0, 0};
Point(4) = {w, 0, 0};
Point(5) = {-w, 0, 0};
Point(6) = {-w_bone, 0, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6};
Plane Surface(1) = {1};

// Tray and insert: one bonded body with its own points.
Point(11) = {-w, 0, 0};
Point(12) = {w, 0, 0};
Point(13) = {w, t_tray, 0};
Point(14) = {-w, t_tray, 0};
Point(15) = {w, t_tray + t_insert, 0};
Point(16) = {-w, t_tray + t_insert, 0};
Line(11) = {11, 12};
Line(12) = {12, 13};
Line(13) = {13, 14};
Line(14) = {14, 11};
Line(15) = {13, 15};
Line(16) = {15, 16};
Line(17) = {16, 14};
Curve Loop(2) = {11, 12, 13, 14};
Plane Surface(2) = {2};
Curve Loop(3) = {-13, 15, 16, 17};
Plane Surface(3) = {3};

// Fine along the interface.
Field[1] = Box;
Field[1].VIn = lc_contact; Field[1].VOut = lc;
Field[1].XMin = -w - 0.001; Field[1].XMax = w + 0.001;
Field[1].YMin = -0.002; Field[1].YMax = 0.002;
Field[1].Thickness = 0.010;
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Recombine Surface{:};
Mesh.SubdivisionAlgorithm = 1;

Physical Surface(1) = {1};             // bone
Physical Surface(2) = {2};             // Ti6Al4V: tray
Physical Surface(3) = {3};             // chirulen: insert
Physical Curve(1) = {1};               // tibia, distal cut: fixed
Physical Curve(2) = {16};              // insert top: loaded
Physical Curve(3) = {11};              // tray bottom: contact slave
Physical Curve(4) = {4};               // bone cut under the tray: master
Physical Curve(5) = {2, 3, 5, 6, 12, 14, 15, 17}; // free sides
