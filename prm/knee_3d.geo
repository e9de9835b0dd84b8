// A 3D total knee replacement (frictionless contact, linear elasticity),
// the seed's materials in 3D, lengths in m (numbers in mm, scaled at the
// end): a ZrO2 femoral component with two spherical condyles (radius 36 mm,
// centres 40 mm apart, each within a 13 mm cylinder) on a UHMWPE insert
// (chirulen) with two spherical dishes (radius 40 mm, 3 mm deep: a
// conformity of 0.9), on a Ti6Al4V tray on a block of tibial bone. The
// insert, tray and tibia are one fragmented piece (bonded: shared nodes);
// the femoral component is meshed on its own and touches the dishes at their
// lowest points. OpenCASCADE kernel.
// Physical volumes: 1 tibia (bone), 2 tray (Ti6Al4V), 3 insert (chirulen),
// 4 femoral component (ZrO2). Physical surfaces: 1 tibia bottom (held),
// 2 femoral top (the axial load), 3 the femoral plate's sides (guided:
// sliding), 4 medial dish, 5 lateral dish (slaves), 6 medial condyle,
// 7 lateral condyle (masters).
// Cells of size h_contact within fine_radius (12 mm) of the contact points,
// growing to h_far. With trough = 1 the dishes are troughs instead: cylinders
// of radius 40 mm along y (the same frontal conformity, none in the sagittal
// plane), so that an anterior-posterior translation or a small internal-
// external rotation of the tibial side leaves the femoral component seated
// (prm/knee_3d_iso_friction.prm); condyle_cylinder is the radius of the
// cylinders the condyles are cut from (13 mm).
SetFactory("OpenCASCADE");
DefineConstant[ h_contact = 1.2, h_far = 6, trough = 0, condyle_cylinder = 13,
                fine_radius = 12 ];
Box(1) = {-38, -22, -40, 76, 44, 30};   // tibia
Box(2) = {-38, -22, -10, 76, 44, 4};    // tray
Box(3) = {-38, -22, -6, 76, 44, 12};    // insert, top at z = 6
If (trough)
  Cylinder(4) = {-20, -30, 42, 0, 60, 0, 40};
  Cylinder(5) = {20, -30, 42, 0, 60, 0, 40};
Else
  Sphere(4) = {-20, 0, 42, 40};
  Sphere(5) = {20, 0, 42, 40};
EndIf
BooleanDifference(6) = { Volume{3}; Delete; }{ Volume{4, 5}; Delete; };
Sphere(7) = {-20, 0, 38, 36};
Cylinder(8) = {-20, 0, 2, 0, 0, 12, condyle_cylinder};
BooleanIntersection(9) = { Volume{7}; Delete; }{ Volume{8}; Delete; };
Sphere(10) = {20, 0, 38, 36};
Cylinder(11) = {20, 0, 2, 0, 0, 12, condyle_cylinder};
BooleanIntersection(12) = { Volume{10}; Delete; }{ Volume{11}; Delete; };
Box(13) = {-38, -22, 14, 76, 44, 8};   // femoral plate
BooleanUnion(14) = { Volume{13}; Delete; }{ Volume{9, 12}; Delete; };
v[] = BooleanFragments{ Volume{1, 2, 6}; Delete; }{};
e = 1e-3;
tibia[] = Volume In BoundingBox{-38 - e, -22 - e, -40 - e, 38 + e, 22 + e, -10 + e};
tray[] = Volume In BoundingBox{-38 - e, -22 - e, -10 - e, 38 + e, 22 + e, -6 + e};
insert[] = Volume In BoundingBox{-38 - e, -22 - e, -6 - e, 38 + e, 22 + e, 6 + e};
Physical Volume(1) = {tibia[]};
Physical Volume(2) = {tray[]};
Physical Volume(3) = {insert[]};
Physical Volume(4) = {14};
bottom[] = Surface In BoundingBox{-38 - e, -22 - e, -40 - e, 38 + e, 22 + e, -40 + e};
top[] = Surface In BoundingBox{-38 - e, -22 - e, 22 - e, 38 + e, 22 + e, 22 + e};
sides[] = Surface In BoundingBox{-38 - e, -22 - e, 14 - e, 38 + e, 22 + e, 22 + e};
sides[] -= {top[]};
// The plate's bottom (z = 14) is not a side.
plate_bottom[] = Surface In BoundingBox{-38 - e, -22 - e, 14 - e, 38 + e, 22 + e, 14 + e};
sides[] -= {plate_bottom[]};
// OpenCASCADE's boxes of curved faces are loose: each side's faces are
// found in generous boxes, the other body's faces taken out.
femur[] = Abs(Boundary{ Volume{14}; });
rc = condyle_cylinder + 3;
medial_condyle[] = Surface In BoundingBox{-20 - rc, -rc, 2 - e, -20 + rc, rc, 10};
lateral_condyle[] = Surface In BoundingBox{20 - rc, -rc, 2 - e, 20 + rc, rc, 10};
dy = trough ? 22.5 : 19;
medial_dish[] = Surface In BoundingBox{-38.5, -dy, 2 - e, -1.5, dy, 6 + e};
lateral_dish[] = Surface In BoundingBox{1.5, -dy, 2 - e, 38.5, dy, 6 + e};
medial_dish[] -= {femur[]};
lateral_dish[] -= {femur[]};
Physical Surface(1) = {bottom[]};
Physical Surface(2) = {top[]};
Physical Surface(3) = {sides[]};
Physical Surface(4) = {medial_dish[]};
Physical Surface(5) = {lateral_dish[]};
Physical Surface(6) = {medial_condyle[]};
Physical Surface(7) = {lateral_condyle[]};
Field[1] = Ball;
Field[1].XCenter = -20; Field[1].YCenter = 0; Field[1].ZCenter = 2;
Field[1].Radius = fine_radius; Field[1].Thickness = 10;
Field[1].VIn = h_contact; Field[1].VOut = h_far;
Field[2] = Ball;
Field[2].XCenter = 20; Field[2].YCenter = 0; Field[2].ZCenter = 2;
Field[2].Radius = fine_radius; Field[2].Thickness = 10;
Field[2].VIn = h_contact; Field[2].VOut = h_far;
Field[3] = Min;
Field[3].FieldsList = {1, 2};
Background Field = 3;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.ScalingFactor = 1e-3;
