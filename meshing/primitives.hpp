#pragma once
#include <Eigen/Core>

#include "meshing/triangle_mesh.hpp"

namespace bedforge::meshing {

// Meshes of the shapes a fluid domain is made of, each on its own with vertices on the exact
// surface, so work is proportional to the number of shapes. `edge` is the target edge length
// (m). `outward` = true orients normals away from the shape's inside, false towards it.

// Sphere (centre c, radius r) from a subdivided icosahedron: the coarsest level whose edges do
// not exceed `edge` (at most level 6; minimum angle about 50 degrees at every level).
TriangleMesh sphere_mesh(const Eigen::Vector3d& c, double r, double edge, bool outward, const std::string& patch);

// Largest distance between a sphere of radius r and the facets of sphere_mesh (chordal
// deviation), for the same `edge`.
double sphere_chordal_deviation(double r, double edge);

// Lateral surface of the cylinder of radius R around the z axis between z0 and z1: rings of
// `ring_points(R, edge)` vertices, staggered by half a step from ring to ring (near-equilateral
// triangles); `outward` = normals pointing away from the axis.
TriangleMesh tube_mesh(double R, double z0, double z1, double edge, bool outward, const std::string& patch);
int ring_points(double R, double edge);

// Flat ring R_in <= r <= R_out (R_in = 0: a disk) at height z, normal +z if `up`. Its edge
// circles carry exactly the vertices of tube_mesh's end rings at that height (`stagger` = the
// half-step offset of the tube's ring there), so a tube and its caps share their seams.
TriangleMesh ring_mesh(double r_in, double r_out, double z, double edge, bool up, bool stagger_outer,
                       bool stagger_inner, const std::string& patch);

// Whether tube_mesh's ring at height z1 is staggered (the bottom ring at z0 is not).
bool top_ring_staggered(double z0, double z1, double edge);

}  // namespace bedforge::meshing
