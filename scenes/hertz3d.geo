// The quarter of the lower half of the unit ball centred at (0, 0, 1) with x >= 0 and y >= 0
// (z <= 1): the body of hertz3d.toml, its pole (0, 0, 0) down on the rigid plane z = 0, graded
// toward the pole. `gmsh -3 hertz3d.geo -o hertz3d.msh` (Gmsh 4.8) writes hertz3d.msh.
SetFactory("OpenCASCADE");
// Target edge within 0.1 of the pole: Gmsh's edges there come out about 1.25 times longer,
// a / 10 for the contact radius a = 0.095 of hertz3d.toml. Away from it the size grows to lc_far.
lc_pole = 0.0075;
lc_far = 0.25;
Sphere(1) = {0, 0, 1, 1, -Pi/2, 0, Pi/2}; // latitudes -90..0 degrees, longitudes 0..90
eps = 1e-6;
top() = Surface In BoundingBox{-eps, -eps, 1 - eps, 1 + eps, 1 + eps, 1 + eps};
sym_x() = Surface In BoundingBox{-eps, -eps, -eps, eps, 1 + eps, 1 + eps};
sym_y() = Surface In BoundingBox{-eps, -eps, -eps, 1 + eps, eps, 1 + eps};
sphere() = Surface{:};
sphere() -= top();
sphere() -= sym_x();
sphere() -= sym_y();
Physical Surface("top") = top();
Physical Surface("sym_x") = sym_x();
Physical Surface("sym_y") = sym_y();
Physical Surface("sphere") = sphere();
Physical Volume("hemisphere") = {1};
Point(100) = {0, 0, 0}; // the pole, for the size field
Field[1] = Distance;
Field[1].PointsList = {100};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = lc_pole;
Field[2].SizeMax = lc_far;
Field[2].DistMin = 0.1;
Field[2].DistMax = 1.0;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.ElementOrder = 1;
Mesh.MshFileVersion = 2.2;
Mesh.Algorithm3D = 1;
