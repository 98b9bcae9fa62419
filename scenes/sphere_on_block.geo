// The half y >= 0 of an elastic hemisphere on an elastic block: the two bodies of
// sphere_on_block.toml, in one file, graded toward their contact point (the origin).
// `gmsh -3 sphere_on_block.geo -o sphere_on_block.msh` (Gmsh 4.8) writes sphere_on_block.msh.
//
// hemisphere: the lower half of the ball of radius R centred at (0, 0, R), y >= 0 (its pole
//   touches the block at the origin); faces "sphere" (curved), "platen" (the flat top z = R)
//   and "sphere_sym" (the half disc on y = 0).
// block: [-W, W] x [0, W] x [-D, 0], the half y >= 0 of a block 2 W wide and D deep; faces
//   "block_top" (z = 0), "block_sym" (y = 0) and "block_bottom" (z = -D); the sides are free,
//   in no physical surface.
// The two volumes are separate OpenCASCADE solids (no fragments): they touch at the origin but
// share no vertex, so that the bodies stay two bodies.
SetFactory("OpenCASCADE");
R = 1;
W = 2; // the block's half-width (the block is 4 = 40 a wide for a = 0.1)
D = 4; // the block's depth
// Target edge within 0.12 of the origin (1.2 a for the contact radius a = 0.1 of
// sphere_on_block.toml): Gmsh's faces come out with edges of about that length there (a / 7).
// Away from it the size grows to lc_far at the distance d_far (both bodies: one field).
lc_contact = 0.014;
lc_far = 0.5;
d_near = 0.12;
d_far = 1.5;
Sphere(1) = {0, 0, R, R, -Pi/2, 0, Pi}; // latitudes -90..0 degrees, longitudes 0..180
Box(2) = {-W, 0, -D, 2 * W, W, D};
eps = 1e-6;
platen() = Surface In BoundingBox{-R - eps, -eps, R - eps, R + eps, R + eps, R + eps};
sphere_sym() = Surface In BoundingBox{-R - eps, -eps, -eps, R + eps, eps, R + eps};
sphere() = Surface In BoundingBox{-R - eps, -eps, -eps, R + eps, R + eps, R + eps};
sphere() -= platen();
sphere() -= sphere_sym();
Physical Surface("platen") = platen();
Physical Surface("sphere_sym") = sphere_sym();
Physical Surface("sphere") = sphere();
Physical Surface("block_top") = Surface In BoundingBox{-W - eps, -eps, -eps, W + eps, W + eps, eps};
Physical Surface("block_sym") = Surface In BoundingBox{-W - eps, -eps, -D - eps, W + eps, eps, eps};
Physical Surface("block_bottom") = Surface In BoundingBox{-W - eps, -eps, -D - eps, W + eps, W + eps, -D + eps};
Physical Volume("block") = {2};
Physical Volume("hemisphere") = {1};
Point(100) = {0, 0, 0}; // the contact point, for the size field
Field[1] = Distance;
Field[1].PointsList = {100};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = lc_contact;
Field[2].SizeMax = lc_far;
Field[2].DistMin = d_near;
Field[2].DistMax = d_far;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.ElementOrder = 1;
Mesh.MshFileVersion = 2.2;
Mesh.Algorithm3D = 1;
