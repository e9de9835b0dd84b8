// Two blocks for the contact patch test on files of other formats
// (tests/mesh_formats.py): [0,1]x[0,1] (physical surface 1) under
// [0,1]x[1,2] (physical surface 2), each with its own points on y = 1, and
// the same number of nodes on both sides of the interface (matching
// meshes, node pairs). Physical curves: 1 left sides, 2 right sides,
// 3 bottom, 4 top, 5 top of the lower block, 6 bottom of the upper block.
// -setnumber mixed 1: the upper block of quadrilaterals (a mixed mesh).
// -setnumber groups 1: the contact sides and the top also in physical curve
// 7, both blocks also in physical surface 3 (entities in two physical
// groups, as Gmsh allows; the scenes name groups 1-6).
If (!Exists(mixed))
  mixed = 0;
EndIf
If (!Exists(groups))
  groups = 0;
EndIf
lc = 0.3;
Point(1) = {0, 0, 0, lc}; Point(2) = {1, 0, 0, lc};
Point(3) = {1, 1, 0, lc}; Point(4) = {0, 1, 0, lc};
Point(5) = {0, 1, 0, lc}; Point(6) = {1, 1, 0, lc};
Point(7) = {1, 2, 0, lc}; Point(8) = {0, 2, 0, lc};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Transfinite Curve{3, 5} = 6;
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, 7, 8}; Plane Surface(2) = {2};
If (mixed == 1)
  Recombine Surface{2};
EndIf
Physical Surface(1) = {1};
Physical Surface(2) = {2};
Physical Curve(1) = {4, 8};
Physical Curve(2) = {2, 6};
Physical Curve(3) = {1};
Physical Curve(4) = {7};
Physical Curve(5) = {3};
Physical Curve(6) = {5};
If (groups == 1)
  Physical Curve(7) = {3, 5, 7};
  Physical Surface(3) = {1, 2};
EndIf
