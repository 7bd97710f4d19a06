#pragma once
#include "core/bed.hpp"
#include "meshing/surface/fluid_surface.hpp"

namespace bedforge::meshing {

// Whether build_fluid_surface cuts a clip window through its treated contacts
// (build_cut_clip_surface): surface.clip_window_d with contacts.at_clip_planes = "cut" and
// bridges, caps or enlarge (on spheres or walls); shrink and none have nothing a plane opens.
bool cuts_contacts_at_clip_planes(const SurfaceParams& p);

// The fluid surface of `bed` between the clip window's planes with every bridge, cap and union
// they cross cut through as the treatment made it (none opened, none shrunk), as the slabs
// between pieces are cut (slab_mesh.hpp).
//
// How: each plane moves within surface.clip_shift_d to the middle of the widest interval between
// the spheres' ends and the treated contacts' rims (plane_clear_heights_d: the cut then meets the
// surface at wide angles), at a height an ASCII STL keeps. The spheres whose centres lie within
// piece_margin_d of the window are laid out whole, with empty ends beyond (window_for_cuts; its
// walls ringed at the planes), their surface built (build_fluid_surface) and cut at the lower
// plane and then the upper (cut_by_plane); the part between is the window.
//   fluid  closed, patches inlet (the lower plane), outlet, wall (inner_wall), particles (m)
//   bed    the particles' triangles, normals out of the solid: open where the planes cut them
//   exact_volume_m3  the container's section times the window's height less the treated solid
//          between the planes (treat_contacts_measured_between), exact as the treatment's volumes are
//   report the laid-out bed's surface report, with the treated solid and the contacts counted
//          between the planes ("contacts_treated": those whose geometry reaches between them),
//          "domain_m" and "clip" (per plane: asked_d, used_d, contacts_opened 0, and the cut's counts).
// InputError naming surface.clip_window_d when the planes leave no window or a cut meets two
// loops at a point (CutConflict), and the errors of build_fluid_surface with the spheres
// numbered as in `bed`.
FluidSurface build_cut_clip_surface(const Bed& bed, const SurfaceParams& p);

}  // namespace bedforge::meshing
