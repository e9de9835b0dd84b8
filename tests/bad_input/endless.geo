// Never finishes: gmsh must be stopped at Mesh/Gmsh time limit.
For i In {1:1e15}
  x = i;
EndFor
