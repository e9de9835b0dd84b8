// Total knee replacement, sagittal cross-section (x anterior, y up) [m].
// A plausible geometry from implant and anatomy literature (see README):
//  - distal femur (bone) carrying the femoral component (ZrO2), outer
//    condyle radius 35 mm, 7 mm thick, bonded to the bone;
//  - mobile-bearing UHMWPE insert (chirulen), 52 mm, dished with radius
//    45 mm, 8 mm thick under the dish;
//  - Ti6Al4V tibial tray, 4 mm plate with a 12 mm wide, 50 mm long stem,
//    bonded to the proximal tibia (bone); the fibula (bone) bonded to the
//    tibia's posterior side.
// Bodies in contact have their own points and curves (AutoCoherence off);
// bonded parts share curves. Points 1-10 of the seed: 1-2 tibia cut,
// 3-4 fibula cut, 5-6 femur cut, 7-8 dish edges (condyle contact),
// 9-10 insert-tray interface ends.
// Parameters (gmsh -setnumber NAME VALUE): lc, lc_contact (mesh sizes,
// halved by the quadrilateral subdivision), tibia_length (below the tray),
// femur_length (above the condyle centre).
Geometry.AutoCoherence = 0;
If (!Exists(lc))
  lc = 0.005;
EndIf
If (!Exists(lc_contact))
  lc_contact = 0.0012;
EndIf
If (!Exists(tibia_length))
  tibia_length = 0.07;
EndIf
If (!Exists(femur_length))
  femur_length = 0.08;
EndIf

w = 0.026;          // half width of tray, insert and proximal tibia
y_tray = -0.021;    // tray bottom = tibia top
y_insert = -0.017;  // tray top = insert bottom
y_rim = -0.002;     // insert top
y_dish = -0.009;    // dish bottom = lowest point of the condyle
R_dish = 0.045;
R_out = 0.035;      // condyle (component outer surface)
R_in = 0.028;       // component inner surface
y_c = y_dish + R_out;  // condyle centre height
y_b = y_tray - tibia_length;

// Tibia, fibula, tray and stem: one bonded body.
Point(1) = {-w, y_tray, 0};  Point(2) = {w, y_tray, 0};
Point(3) = {w, y_insert, 0}; Point(4) = {-w, y_insert, 0};
Point(5) = {-0.006, y_tray, 0}; Point(6) = {0.006, y_tray, 0};
Point(7) = {0.006, y_tray - 0.05, 0}; Point(8) = {-0.006, y_tray - 0.05, 0};
Point(9) = {-w, y_b, 0}; Point(10) = {w, y_b, 0};
Point(11) = {-w, y_b + 0.035, 0};
Point(12) = {-0.038, y_b - 0.01, 0}; Point(13) = {-w, y_b - 0.01, 0};
Point(14) = {-0.038, y_b + 0.035, 0};
Line(1) = {1, 5}; Line(2) = {5, 6}; Line(3) = {6, 2};
Line(4) = {2, 3}; Line(5) = {3, 4}; Line(6) = {4, 1};
Line(7) = {5, 8}; Line(8) = {8, 7}; Line(9) = {7, 6};
Line(10) = {9, 10}; Line(11) = {10, 2}; Line(12) = {1, 11};
Line(13) = {11, 9};
Line(14) = {12, 13}; Line(15) = {13, 9}; Line(16) = {11, 14};
Line(17) = {14, 12};
Curve Loop(1) = {1, 2, 3, 4, 5, 6};           Plane Surface(1) = {1}; // tray
Curve Loop(2) = {-2, 7, 8, 9};                Plane Surface(2) = {2}; // stem
Curve Loop(3) = {10, 11, -3, -9, -8, -7, -1, 12, 13};
Plane Surface(3) = {3};                                               // tibia
Curve Loop(4) = {14, 15, -13, 16, 17};        Plane Surface(4) = {4}; // fibula

// Insert: its own points.
Point(21) = {-w, y_insert, 0}; Point(22) = {w, y_insert, 0};
Point(23) = {w, y_rim, 0};
x_edge = Sqrt(R_dish^2 - (y_dish + R_dish - y_rim)^2);
Point(24) = {x_edge, y_rim, 0}; Point(25) = {0, y_dish, 0};
Point(26) = {-x_edge, y_rim, 0}; Point(27) = {-w, y_rim, 0};
Point(28) = {0, y_dish + R_dish, 0};
Line(21) = {21, 22}; Line(22) = {22, 23}; Line(23) = {23, 24};
Circle(24) = {24, 28, 25}; Circle(25) = {25, 28, 26};
Line(26) = {26, 27}; Line(27) = {27, 21};
Curve Loop(21) = {21, 22, 23, 24, 25, 26, 27}; Plane Surface(21) = {21};

// Femoral component and femur: one bonded body.
Point(31) = {-R_out, y_c, 0}; Point(32) = {0, y_dish, 0}; Point(33) = {R_out, y_c, 0};
Point(34) = {R_in, y_c, 0}; Point(35) = {0, y_c - R_in, 0}; Point(36) = {-R_in, y_c, 0};
Point(37) = {0, y_c, 0};
Point(38) = {0.016, y_c + 0.04, 0}; Point(39) = {0.016, y_c + femur_length, 0};
Point(40) = {-0.016, y_c + femur_length, 0}; Point(41) = {-0.016, y_c + 0.04, 0};
Circle(31) = {31, 37, 32}; Circle(32) = {32, 37, 33};
Line(33) = {33, 34}; Circle(34) = {34, 37, 35}; Circle(35) = {35, 37, 36};
Line(36) = {36, 31};
Line(37) = {33, 38}; Line(38) = {38, 39}; Line(39) = {39, 40};
Line(40) = {40, 41}; Line(41) = {41, 31};
Curve Loop(31) = {31, 32, 33, 34, 35, 36};    Plane Surface(31) = {31};
Curve Loop(32) = {-36, -35, -34, -33, 37, 38, 39, 40, 41};
Plane Surface(32) = {32};

// Fine where the condyle meets the dish and along the insert-tray interface.
Field[1] = Box;
Field[1].VIn = lc_contact; Field[1].VOut = lc;
Field[1].XMin = -0.014; Field[1].XMax = 0.014;
Field[1].YMin = y_dish - 0.002; Field[1].YMax = y_dish + 0.003;
Field[1].Thickness = 0.012;
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
  Recombine Surface{:};
  Mesh.SubdivisionAlgorithm = 1;
EndIf

Physical Surface(1) = {3, 4, 32};   // bone: tibia, fibula, femur
Physical Surface(2) = {1, 2};       // Ti6Al4V: tray and stem
Physical Surface(3) = {21};         // chirulen: insert
Physical Surface(4) = {31};         // ZrO2: femoral component
Physical Curve(1) = {10};           // tibia cut, points 1-2: fixed
Physical Curve(2) = {14};           // fibula cut, points 3-4: fixed
Physical Curve(3) = {39};           // femur cut, points 5-6: loaded
Physical Curve(4) = {38, 40};       // femur shaft sides: sliding
Physical Curve(5) = {24, 25};       // dish, points 7-8: contact slave
Physical Curve(6) = {31, 32};       // condyle: contact master
Physical Curve(7) = {21};           // insert bottom, points 9-10: slave
Physical Curve(8) = {5};            // tray top: contact master
