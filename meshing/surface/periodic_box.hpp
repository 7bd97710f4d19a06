#pragma once
#include "core/bed.hpp"
#include "meshing/surface/fluid_surface.hpp"

namespace bedforge::meshing {

// Whether `container` is a box periodic along x, y and z (container.periodic_x, periodic_y and
// period_z): a fully periodic box, the wall-free bed that drag laws are fitted to.
bool is_fully_periodic_box(const Container& container);

// The fluid surface of `bed` in a fully periodic box (is_fully_periodic_box): the box
// -hx <= x <= hx, -hy <= y <= hy, 0 <= z <= H less the spheres, every sphere that crosses a side
// cut there and its parts moved a period across, so that each pair of opposite sides carries one
// triangulation, point for point (by construction: each side is meshed once, its copy takes the
// same doubles with the side's own coordinate set; the spheres' loops on it are the same points).
//
// How: the bed is first moved as a whole (a periodic bed moved by any vector is the same bed) by
// the shift that keeps the planes farthest from the spheres' ends and the box's edges from
// grazing a sphere (its clearance at least surface.clip_clearance_d; no sphere may hold a
// corner of the box). A sphere crossing sides is split by their planes into parts along the
// circles where it meets them: the circles meet at the points where the box's edges pierce the
// sphere, which both circles share; each part is a sphere_mesh bounded by the arcs around it and
// moved by the periods of the sides it lies beyond. Each side is the rectangle less the circles'
// disks as they fall on it, the disks cut by its edges bitten out of its outline; it is meshed by
// plane_mesh graded from the circles (contact edge at them, growing by `growth` per edge to the
// surface edge), its edges' points shared with the sides beside it.
//   bed     a fully periodic box's bed, the spheres of one period (their centres anywhere: each
//           is taken at its image in the box); spheres must not touch after the treatment
//   p       treatment "none" or "shrink" (no contact is joined across a side), lengths in d
//   fluid   closed, normals out of the fluid (m); patches x_min, x_max, y_min, y_max, inlet
//           (z = 0), outlet (z = H), particles
//   exact_volume_m3  the box's volume less the treated spheres'
//   report  "periodic_box": the shift (m), the clearance (d), the spheres cut; the treatment's
//           figures as build_fluid_surface gives them (contacts treated, smallest gap)
// InputError naming the key when the treatment is another, spheres touch or overlap, a period
// is shorter than 3 diameters, or no shift keeps the clearance; CutConflict of sphere_mesh or
// plane_mesh as InputError naming the sphere or side.
FluidSurface build_periodic_box_surface(const Bed& bed, const SurfaceParams& p);

// InputError naming the key when a box with periodic sides cannot be meshed under `p`: periodic on
// one side only or without container.period_z (a box is meshed periodic on every side or on none
// of x and y), or a treatment other than "none" or "shrink". Called when the scene is read, and
// by build_periodic_box_surface.
void check_periodic_box(const Container& container, const SurfaceParams& p);

}  // namespace bedforge::meshing
