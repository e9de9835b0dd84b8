// Total knee replacement, frontal cross-section (x medial-lateral, lateral
// positive; y up) [m]. Plausible dimensions (see README): two condyles of
// the femoral component (ZrO2), outer radius 20 mm, 6 mm thick, centres
// 48 mm apart, bonded to the distal femur (bone); a mobile-bearing UHMWPE
// insert (chirulen), 92 mm wide, with two dishes of radius 26 mm, 8 mm thick
// under them; the Ti6Al4V tray, 4 mm plate with a 50 mm stem, bonded to the
// proximal tibia (bone), which narrows to its shaft; the fibula (bone),
// bonded to the tibia's lateral side. Points: 1-2 tibia cut, 3-4 fibula cut,
// 5-6 femur cut, 7-8 medial dish (contact), 9-10 lateral dish (contact),
// 11-12 insert-tray interface. Parameters as in knee.geo.
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

w = 0.046;          // half width of tray, insert and tibial plateau
y_tray = -0.021;
y_insert = -0.017;
y_rim = -0.002;
y_dish = -0.009;
x_k = 0.024;        // condyle centres at -x_k (medial) and x_k (lateral)
R_out = 0.020;
R_in = 0.014;
R_dish = 0.026;
y_c = y_dish + R_out;
y_b = y_tray - tibia_length;
y_top = y_c + femur_length;

// Tibia, fibula, tray and stem: one bonded body.
Point(1) = {-w, y_tray, 0}; Point(2) = {-0.006, y_tray, 0};
Point(3) = {0.006, y_tray, 0}; Point(4) = {w, y_tray, 0};
Point(5) = {w, y_insert, 0}; Point(6) = {-w, y_insert, 0};
Point(7) = {0.006, y_tray - 0.05, 0}; Point(8) = {-0.006, y_tray - 0.05, 0};
Point(9) = {-0.024, y_b, 0}; Point(10) = {0.024, y_b, 0};
Point(11) = {0.024, y_b + 0.035, 0}; Point(12) = {0.024, -0.05, 0};
Point(13) = {-0.024, -0.05, 0};
Point(14) = {0.024, y_b - 0.01, 0}; Point(15) = {0.036, y_b - 0.01, 0};
Point(16) = {0.036, y_b + 0.035, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5};
Line(5) = {5, 6}; Line(6) = {6, 1};
Line(7) = {2, 8}; Line(8) = {8, 7}; Line(9) = {7, 3};
Line(10) = {9, 10}; Line(11) = {10, 11}; Line(12) = {11, 12};
Line(13) = {12, 4}; Line(14) = {1, 13}; Line(15) = {13, 9};
Line(16) = {14, 15}; Line(17) = {15, 16}; Line(18) = {16, 11};
Line(19) = {10, 14};
Curve Loop(1) = {1, 2, 3, 4, 5, 6};            Plane Surface(1) = {1};
Curve Loop(2) = {-2, 7, 8, 9};                 Plane Surface(2) = {2};
Curve Loop(3) = {10, 11, 12, 13, -3, -9, -8, -7, -1, 14, 15};
Plane Surface(3) = {3};
Curve Loop(4) = {16, 17, 18, -11, 19};         Plane Surface(4) = {4};

// Insert with two dishes.
x_e = Sqrt(R_dish^2 - (y_dish + R_dish - y_rim)^2);
Point(21) = {-w, y_insert, 0}; Point(22) = {w, y_insert, 0};
Point(23) = {w, y_rim, 0};
Point(24) = {x_k + x_e, y_rim, 0}; Point(25) = {x_k, y_dish, 0};
Point(26) = {x_k - x_e, y_rim, 0};
Point(27) = {-x_k + x_e, y_rim, 0}; Point(28) = {-x_k, y_dish, 0};
Point(29) = {-x_k - x_e, y_rim, 0}; Point(30) = {-w, y_rim, 0};
Point(31) = {x_k, y_dish + R_dish, 0}; Point(32) = {-x_k, y_dish + R_dish, 0};
Line(21) = {21, 22}; Line(22) = {22, 23}; Line(23) = {23, 24};
Circle(24) = {24, 31, 25}; Circle(25) = {25, 31, 26};
Line(26) = {26, 27};
Circle(27) = {27, 32, 28}; Circle(28) = {28, 32, 29};
Line(29) = {29, 30}; Line(30) = {30, 21};
Curve Loop(21) = {21, 22, 23, 24, 25, 26, 27, 28, 29, 30};
Plane Surface(21) = {21};

// Femur with the two condyles of the component.
For k In {0:1}
  s = 2 * k - 1;          // -1 medial, +1 lateral
  c = 100 + 20 * k;
  Point(c) = {s * x_k, y_c, 0};
  Point(c + 1) = {s * x_k - R_out, y_c, 0};
  Point(c + 2) = {s * x_k, y_c - R_out, 0};
  Point(c + 3) = {s * x_k + R_out, y_c, 0};
  Point(c + 4) = {s * x_k + R_in, y_c, 0};
  Point(c + 5) = {s * x_k, y_c - R_in, 0};
  Point(c + 6) = {s * x_k - R_in, y_c, 0};
  Circle(c + 1) = {c + 1, c, c + 2}; Circle(c + 2) = {c + 2, c, c + 3};
  Line(c + 3) = {c + 3, c + 4};
  Circle(c + 4) = {c + 4, c, c + 5}; Circle(c + 5) = {c + 5, c, c + 6};
  Line(c + 6) = {c + 6, c + 1};
  Curve Loop(c) = {c + 1, c + 2, c + 3, c + 4, c + 5, c + 6};
  Plane Surface(c) = {c};
EndFor
Point(141) = {0.016, y_c + 0.045, 0}; Point(142) = {0.016, y_top, 0};
Point(143) = {-0.016, y_top, 0}; Point(144) = {-0.016, y_c + 0.045, 0};
Line(141) = {103, 121};   // across the intercondylar notch
Line(142) = {123, 141}; Line(143) = {141, 142}; Line(144) = {142, 143};
Line(145) = {143, 144}; Line(146) = {144, 101};
Curve Loop(140) = {-106, -105, -104, -103, 141, -126, -125, -124, -123,
                   142, 143, 144, 145, 146};
Plane Surface(140) = {140};

Field[1] = Box;
Field[1].VIn = lc_contact; Field[1].VOut = lc;
Field[1].XMin = -x_k - 0.012; Field[1].XMax = x_k + 0.012;
Field[1].YMin = y_dish - 0.002; Field[1].YMax = y_dish + 0.003;
Field[1].Thickness = 0.012;
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Recombine Surface{:};
Mesh.SubdivisionAlgorithm = 1;

Physical Surface(1) = {3, 4, 140};   // bone: tibia, fibula, femur
Physical Surface(2) = {1, 2};        // Ti6Al4V: tray and stem
Physical Surface(3) = {21};          // chirulen: insert
Physical Surface(4) = {100, 120};    // ZrO2: femoral component
Physical Curve(1) = {10};            // tibia cut, points 1-2
Physical Curve(2) = {16};            // fibula cut, points 3-4
Physical Curve(3) = {144};           // femur cut, points 5-6
Physical Curve(4) = {143, 145};      // femur shaft sides: sliding
Physical Curve(5) = {27, 28};        // medial dish, points 7-8: slave
Physical Curve(6) = {101, 102};      // medial condyle: master
Physical Curve(9) = {24, 25};        // lateral dish, points 9-10: slave
Physical Curve(10) = {121, 122};     // lateral condyle: master
Physical Curve(7) = {21};            // insert bottom, points 11-12: slave
Physical Curve(8) = {5};             // tray top: master
