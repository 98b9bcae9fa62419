// Quarter of the unit disc centred at (0, 1) below y = 1, x >= 0 (the right half of the hertz
// half-disc), graded toward the contact point (0, 0).
lc_contact = 0.025;
lc_far = 0.15;
Point(1) = {0, 0, 0, lc_contact};
Point(2) = {1, 1, 0, lc_far};
Point(3) = {0, 1, 0, lc_far};
Circle(1) = {1, 3, 2};
Line(2) = {2, 3};
Line(3) = {3, 1};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};
Physical Curve("surface") = {1};
Physical Curve("top") = {2};
Physical Curve("axis") = {3};
Physical Surface("cylinder") = {1};
Mesh.ElementOrder = 1;
Mesh.MshFileVersion = 2.2;
Mesh.Algorithm = 6;
