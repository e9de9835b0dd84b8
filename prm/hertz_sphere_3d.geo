// Hertz: an elastic sphere of radius R pressed on an elastic block, a quarter
// model (x >= 0, y >= 0; the planes x = 0 and y = 0 are symmetry planes).
// The sphere is its lower hemisphere's quarter (z from 0 to R, flat top at
// z = R), the block [0, W] x [0, W] x [-H, 0]; they touch at the origin,
// meshed on their own (OpenCASCADE, not fragmented: no shared nodes).
// Cells of size h_contact within 2 a_hertz of the origin, growing to h_far;
// tetrahedra, or hexahedra with hex = 1 (each tetrahedron split into four:
// the sizes halve).
// Physical volumes: 1 sphere, 2 block. Physical surfaces: 1 x = 0, 2 y = 0,
// 3 block bottom, 4 sphere top, 5 block top (master), 6 sphere's curved
// surface (slave), 7 the block's outer sides.
SetFactory("OpenCASCADE");
DefineConstant[ R = 1, W = 1, H = 1, a_hertz = 0.1, h_contact = 0.02,
                h_far = 0.25, hex = 0 ];
Sphere(1) = {0, 0, R, R};
Box(2) = {0, 0, 0, R, R, R};
BooleanIntersection(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Box(4) = {0, 0, -H, W, W, H};
e = 1e-6 * R;
x0[] = Surface In BoundingBox{-e, -e, -H - e, e, W + e, R + e};
y0[] = Surface In BoundingBox{-e, -e, -H - e, W + e, e, R + e};
bottom[] = Surface In BoundingBox{-e, -e, -H - e, W + e, W + e, -H + e};
top[] = Surface In BoundingBox{-e, -e, R - e, R + e, R + e, R + e};
master[] = Surface In BoundingBox{-e, -e, -e, W + e, W + e, e};
sphere[] = Boundary{ Volume{3}; };
slave[] = Abs(sphere[]);
slave[] -= {x0[], y0[], top[]};
block[] = Boundary{ Volume{4}; };
sides[] = Abs(block[]);
sides[] -= {x0[], y0[], bottom[], master[]};
Physical Volume(1) = {3};
Physical Volume(2) = {4};
Physical Surface(1) = {x0[]};
Physical Surface(2) = {y0[]};
Physical Surface(3) = {bottom[]};
Physical Surface(4) = {top[]};
Physical Surface(5) = {master[]};
Physical Surface(6) = {slave[]};
Physical Surface(7) = {sides[]};
Field[1] = Box;
Field[1].VIn = h_contact;
Field[1].VOut = h_far;
Field[1].XMin = -1; Field[1].XMax = 2 * a_hertz;
Field[1].YMin = -1; Field[1].YMax = 2 * a_hertz;
Field[1].ZMin = -2 * a_hertz; Field[1].ZMax = 2 * a_hertz;
Field[1].Thickness = 0.5 * R;
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
If (hex)
  Mesh.SubdivisionAlgorithm = 2;
EndIf
