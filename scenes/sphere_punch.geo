// The quarter x >= 0, y >= 0 of an elastic block 4 wide and 4 deep: [0, 2] x [0, 2] x [-4, 0],
// the body of sphere_punch.toml, its top face z = 0 pressed against a rigid sphere of radius 1
// touching it at the origin, graded toward the origin. `gmsh -3 sphere_punch.geo -o
// sphere_punch.msh` (Gmsh 4.8) writes sphere_punch.msh.
SetFactory("OpenCASCADE");
W = 2; // the quarter's width (the block's half-width)
D = 4; // the block's depth
// Target edge within 0.15 of the origin (1.5 a for the contact radius a = 0.0994 of
// sphere_punch.toml): Gmsh's faces come out with edges of about that length (a / 7), its
// tetrahedra about 1.3 times longer (a / 5.5). Away from it the size grows to lc_far at the
// distance d_far.
lc_contact = 0.014;
lc_far = 0.5;
d_far = 2.5;
Box(1) = {0, 0, -D, W, W, D};
eps = 1e-6;
Physical Surface("sym_x") = Surface In BoundingBox{-eps, -eps, -D - eps, eps, W + eps, eps};
Physical Surface("sym_y") = Surface In BoundingBox{-eps, -eps, -D - eps, W + eps, eps, eps};
Physical Surface("bottom") = Surface In BoundingBox{-eps, -eps, -D - eps, W + eps, W + eps, -D + eps};
Physical Surface("top") = Surface In BoundingBox{-eps, -eps, -eps, W + eps, W + eps, eps};
Physical Volume("block") = {1};
// The sides x = W and y = W are free: in no physical surface, so not written.
Point(100) = {0, 0, 0}; // the contact point, for the size field
Field[1] = Distance;
Field[1].PointsList = {100};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = lc_contact;
Field[2].SizeMax = lc_far;
Field[2].DistMin = 0.15;
Field[2].DistMax = d_far;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.ElementOrder = 1;
Mesh.MshFileVersion = 2.2;
Mesh.Algorithm3D = 1;
