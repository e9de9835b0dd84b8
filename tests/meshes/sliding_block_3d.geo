// A block [-0.5, 0.5] x [-0.5, 0.5] x [0, 0.25] resting on a base
// [-1, 1] x [-1, 1] x [-0.5, 0], meshed on their own (no shared nodes),
// tetrahedra of size h (base) and 0.8 h (block): non-matching meshes on the
// interface. Physical volumes: 1 base, 2 block. Physical surfaces: 1 base
// bottom, 2 base top, 4 block bottom, 5 block side x = -0.5, 6 block top.
SetFactory("OpenCASCADE");
DefineConstant[ h = 0.2 ];
Box(1) = {-1, -1, -0.5, 2, 2, 0.5};
Box(2) = {-0.5, -0.5, 0, 1, 1, 0.25};
// OpenCASCADE numbers a box's faces x min, x max, y min, y max, z min,
// z max: the base's are 1-6, the block's 7-12.
Physical Volume(1) = {1};
Physical Volume(2) = {2};
Physical Surface(1) = {5};
Physical Surface(2) = {6};
Physical Surface(4) = {11};
Physical Surface(5) = {7};
Physical Surface(6) = {12};
MeshSize{PointsOf{Volume{1};}} = h;
MeshSize{PointsOf{Volume{2};}} = 0.8 * h;
