Point(1) = {0, 0, 0};
Line(1) = {1, 2};
Plane Surface(1) = {7};
