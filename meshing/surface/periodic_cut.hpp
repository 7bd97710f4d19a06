#pragma once
#include "core/bed.hpp"
#include "meshing/surface/fluid_surface.hpp"

namespace bedforge::meshing {

// Whether build_fluid_surface cuts a periodic section of `bed` under `p` through its treated
// contacts (build_cut_periodic_surface): contacts.at_periodic_planes = "cut", bridges, caps or
// enlarge.
bool cuts_contacts_at_periodic_planes(const Bed& bed, const SurfaceParams& p);

// The fluid surface of `bed`, periodic along z (container.axial_period() = H > 0), between two
// planes a period apart, z0 (unwrap_periodic_section's with the rims and treated ends to keep
// clear of, rounded as an ASCII STL keeps it) and z1 = z0 + H, with every bridge, cap and union
// the planes cross cut through as the treatment made it (none opened), and the outlet's face
// the inlet's moved up a period, point for point.
//
// How: the spheres whose centres lie from s - W to z1 + W (s = z0 - m, the seam; W =
// piece_margin_d) are laid out a period apart as an ordinary bed, whole, with an empty end half a
// diameter deep each side (so no plane of its own cuts a contact), its walls ringed at s, z0,
// s + H and z1 (a box's sides meshed in strips between them), and its surface built
// (build_fluid_surface) and cut at z0 (cut_by_plane). The section is the part above z0 up to
// s + H, and the part below z0 from s up, moved up a period. The cut's changes reach no seam (m
// is at least kSeamDepthEdges edges and kSeamDepthMinD d, a hair more where the seam keeps clear
// of a height about which a sphere's or contact's mesh is symmetric), and there the repeated layout's surface repeats itself a period on: the
// spheres and contacts by construction, the wall along its ring or strip edge; the seam's
// vertices are taken from the part moved up, so the two join bit for bit. A surface some three
// times the period's.
//   fluid  closed, patches inlet, outlet, wall (inner_wall), particles (m)
//   bed    the particles' triangles, normals out of the solid: open where the planes cut them
//   exact_volume_m3  A H less the treated solid of one period: the solid of two periods of the
//          bed repeated less that of one (each contact then counted once), exact as the
//          treatment's volumes are
//   pieces one piece of no known shape (the self-intersection test takes every pair near)
//   report the layout's surface report with the treatment's figures for one period
//          (contacts_treated, solid_volume_change_m3, ...) and "periodic_planes_m" with the cut's.
// InputError naming the key when the period is shorter than twice the seam depth; the errors of
// build_fluid_surface and cut_by_plane (CutConflict as InputError); std::runtime_error when the
// layout's surface does not repeat itself at the seam (a defect of ours), saying where, after up
// to three seam depths were tried (a cap's regular rings across a seam can take other diagonals
// in the two copies of its sphere).
inline constexpr double kSeamDepthEdges = 4.0, kSeamDepthMinD = 0.5;
FluidSurface build_cut_periodic_surface(const Bed& bed, const SurfaceParams& p);

// InputError naming the key when a periodic section in `container` (its axial period set) cannot
// be cut through its contacts under `p` (contacts.at_periodic_planes = "cut"): a period shorter
// than twice the seam depth (d: the reference diameter, m). The scene reader calls it
// before any work; build_cut_periodic_surface checks the period again.
void check_periodic_cut(const Container& container, const SurfaceParams& p, double d);

}  // namespace bedforge::meshing
