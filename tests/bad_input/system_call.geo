// A .geo that runs a program: refused before gmsh sees it.
lc = 0.1;
SystemCall "touch knee_contact_was_here";
Point(1) = {0, 0, 0, lc};
