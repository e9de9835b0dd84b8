// Two unit cubes for the 3D contact patch test, each meshed on its own (the
// bodies share no nodes): the lower [0,1]^3 and the upper [0,1]^2 x [1,2],
// n_lower and n_upper cells along each edge, hexahedra (hex_* = 1,
// transfinite and recombined) or tetrahedra (hex_* = 0), the whole stack
// rotated by angle [rad] about the skew axis (1, 2, 3) through the origin;
// the upper cube raised by gap (lowered into the lower one if negative).
// The points are placed rotated (gmsh's Rotate renumbers OpenCASCADE
// entities, which would lose the physical groups).
// Physical volumes: 1 lower, 2 upper. Physical surfaces (before rotation):
// 1: x = 0, 2: y = 0, 3: z = 0, 4: z = 2, 5: top of the lower cube,
// 6: bottom of the upper cube, 7: x = 1, 8: y = 1.
DefineConstant[ n_lower = 5, n_upper = 7, hex_lower = 1, hex_upper = 1,
                angle = 0, gap = 0 ];
// Rodrigues: R = c I + s [a]x + (1 - c) a a^T, a = (1, 2, 3) / sqrt(14).
a1 = 1 / Sqrt(14); a2 = 2 / Sqrt(14); a3 = 3 / Sqrt(14);
c = Cos(angle); s = Sin(angle);
r11 = c + (1 - c) * a1 * a1; r12 = (1 - c) * a1 * a2 - s * a3;
r13 = (1 - c) * a1 * a3 + s * a2;
r21 = (1 - c) * a2 * a1 + s * a3; r22 = c + (1 - c) * a2 * a2;
r23 = (1 - c) * a2 * a3 - s * a1;
r31 = (1 - c) * a3 * a1 - s * a2; r32 = (1 - c) * a3 * a2 + s * a1;
r33 = c + (1 - c) * a3 * a3;
n[] = {n_lower, n_upper};
hex[] = {hex_lower, hex_upper};
For b In {0 : 1}
  For k In {0 : 1}
    For j In {0 : 1}
      For i In {0 : 1}
        x = i; y = j; z = k + b * (1 + gap);
        Point(100 * b + 1 + i + 2 * j + 4 * k) =
          {r11 * x + r12 * y + r13 * z, r21 * x + r22 * y + r23 * z,
           r31 * x + r32 * y + r33 * z};
      EndFor
    EndFor
  EndFor
  P = 100 * b + 1;
  // Edges along x (j, k), y (i, k) and z (i, j).
  For k In {0 : 1}
    For j In {0 : 1}
      Line(100 * b + 1 + j + 2 * k) = {P + 2 * j + 4 * k, P + 1 + 2 * j + 4 * k};
    EndFor
    For i In {0 : 1}
      Line(100 * b + 5 + i + 2 * k) = {P + i + 4 * k, P + i + 2 + 4 * k};
    EndFor
  EndFor
  For j In {0 : 1}
    For i In {0 : 1}
      Line(100 * b + 9 + i + 2 * j) = {P + i + 2 * j, P + i + 2 * j + 4};
    EndFor
  EndFor
  X = 100 * b; Y = 100 * b + 4; Z = 100 * b + 8;
  For t In {0 : 1}
    // x = t, y = t and z = t faces.
    Curve Loop(100 * b + 1 + t) = {Y + 1 + t, Z + 1 + t + 2, -(Y + 1 + t + 2), -(Z + 1 + t)};
    Curve Loop(100 * b + 3 + t) = {X + 1 + t, Z + 2 + 2 * t, -(X + 1 + t + 2), -(Z + 1 + 2 * t)};
    Curve Loop(100 * b + 5 + t) = {X + 1 + 2 * t, Y + 2 + 2 * t, -(X + 2 + 2 * t), -(Y + 1 + 2 * t)};
  EndFor
  For f In {1 : 6}
    Plane Surface(100 * b + f) = {100 * b + f};
  EndFor
  Surface Loop(b + 1) = {100 * b + 1 : 100 * b + 6};
  Volume(b + 1) = {b + 1};
  Transfinite Curve{100 * b + 1 : 100 * b + 12} = n[b] + 1;
  If (hex[b])
    Transfinite Surface{100 * b + 1 : 100 * b + 6};
    Recombine Surface{100 * b + 1 : 100 * b + 6};
    Transfinite Volume{b + 1};
  EndIf
EndFor
Physical Volume(1) = {1};
Physical Volume(2) = {2};
Physical Surface(1) = {1, 101};
Physical Surface(2) = {3, 103};
Physical Surface(3) = {5};
Physical Surface(4) = {106};
Physical Surface(5) = {6};
Physical Surface(6) = {105};
Physical Surface(7) = {2, 102};
Physical Surface(8) = {4, 104};
