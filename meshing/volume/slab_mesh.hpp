#pragma once
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/bed.hpp"
#include "core/error.hpp"
#include "core/progress.hpp"
#include "meshing/surface/clip_planes.hpp"
#include "meshing/surface/fluid_surface.hpp"
#include "meshing/volume/volume_mesh.hpp"

namespace bedforge::meshing {

// The fluid domain meshed in axial slabs, one gmsh run each, and the slabs joined into one
// mesh: gmsh's peak memory (its tetrahedra, then its optimiser's connectivity) follows the
// largest slab instead of the whole bed. Each slab is the surface stage's domain clipped to its
// heights (build_fluid_surface with a clip window): the planes between slabs cut the spheres
// crossing them, and both slabs triangulate a shared plane alike, so the joined cells are
// conforming and the planes' triangles become internal faces. A clip plane through a treated
// contact (bridge, cap, union) would open it, so under those treatments the slabs are cut by
// cut_by_plane, which cuts any contact and triangulates a plane from its section alone: each
// from the surface of its window widened by at least piece_margin_d, whose walls are ringed at
// every plane (wall_mesh), so that two neighbours' surfaces cross their shared plane in the same
// triangles and their cuts triangulate it alike (mesh_slab, in one process or on ranks of their
// own, pipeline/piece_stage); in a box, whose flat sides are not ringed, in one process from the
// whole domain's surface.

// Whether a bed can be meshed in slabs with `params`: no prism layers (they would meet the
// planes between slabs).
bool slabs_possible(const VolumeMeshParams& params);
// Whether each slab's surface is built on its own from a clip window (contacts and walls shrunk
// or left alone); otherwise slabs are cut by planes from a surface.
bool slabs_from_clip_windows(const SurfaceParams& surface);
// Whether a bed in `container` under `surface` can be meshed in pieces that need no whole
// surface (mesh_slab): from clip windows in any container; cut from widened windows only where
// the walls can be ringed (a cylinder or annulus; a box's flat sides are not).
bool pieces_possible(const SurfaceParams& surface, const Container& container);

// Whether the mesh stage meshes a bed in `container` in slabs: asked (params.slabs > 1) or left
// to it (params.slabs = 0) where slabs_from_clip_windows; never with prism layers
// (slabs_possible), nor a periodic section, whose planes are its period's (its inlet and outlet
// one cyclic pair, which slabs' clip windows would make walls).
bool meshes_in_slabs(const SurfaceParams& surface, const VolumeMeshParams& params, const Container& container);

// How many slabs: 1 unless meshes_in_slabs; then params.slabs when set, else one per
// kSurfaceTrianglesPerSlab of the whole fluid surface (a slab of a million triangles makes about
// 2.7 M cells; a = 10, N = 4000 at 0.1 d: 3.2 M triangles, 4 slabs).
constexpr double kSurfaceTrianglesPerSlab = 1.0e6;
int slab_count(std::size_t surface_triangles, const SurfaceParams& surface, const VolumeMeshParams& params,
               const Container& container);

// Heights above the floor (d) of the planes between `slabs` slabs: the fluid domain (from its
// inlet to its outlet, or a clip window's ends) cut into slabs of about equal cells by the
// surface stage's own estimate (fluid_domain_profile: the fluid volume and the cells its narrow
// gaps add), each plane then moved within surface.clip_shift_d to the middle of the widest
// interval between the spheres' tops and bottoms (at their own and their shrunk radius): a plane
// just clear of a sphere's top cuts it in a thin cap and leaves an acute wedge of fluid beside
// it. Empty when slabs < 2. The second form takes the profile slab_profile made for as many slabs.
std::vector<double> slab_planes_d(const Bed& bed, const SurfaceParams& surface, int slabs);
std::vector<double> slab_planes_d(const Bed& bed, const SurfaceParams& surface, const FluidDomainProfile& profile,
                                  int slabs);
// The planes between `slabs` slabs (slab_planes_d, d) and the whole bed's narrowest wall gap
// (FluidDomainProfile::bed_wall_gap_m, m), which every slab's window rings its walls with, from
// one survey of the bed (slab_profile): what a run hands its ranks (`piece --planes-d
// --wall-gap-m`), so that each treats only its window.
struct SlabPlanes {
  std::vector<double> planes_d;
  double wall_gap_m = 0.0;
};
SlabPlanes slab_planes(const Bed& bed, const SurfaceParams& surface, int slabs);
// Where `planes` (d) go when the slabs between them fail the quality gate or cannot be cut: each
// to the middle of the widest interval between the spheres' ends within surface.clip_shift_d of
// it, other than the interval it lies in (where it stays when there is no other). When `failed`
// names the slabs that failed (0 = the lowest), only the planes bounding them move, so that the
// other slabs, made already, can be kept.
std::vector<double> moved_slab_planes_d(const Bed& bed, const SurfaceParams& surface, const std::vector<double>& planes,
                                        const std::vector<int>& failed = {});

// A slab that cannot be cut from the bed between its planes (its clip planes find no height
// clear of the spheres, or a plane's cut meets another cut): like a slab failing the gate, the
// planes' place is to blame, so the slab routes try once more with them moved. An InputError
// where nothing retries; what() names the slab or plane and its heights but no scene key, and
// holds kSlabCutPhrase, by which a rank's message is known for one (pipeline/piece_stage).
struct SlabCutError : InputError {
  using InputError::InputError;
};
inline constexpr const char* kSlabCutPhrase = "cannot be cut from the bed";

// The planes an attempt was retried with and why (attempt_with_planes_moved).
struct PlanesMoved {
  std::vector<double> from_d, to_d;
  std::string because;  // the first attempt's error
};
// The error of slabs that failed, `what` saying why: InputError naming `key` (the scene key or
// option that set their count) when one could not be cut (`cut`), else ConvergenceError.
[[noreturn]] void throw_slabs_failed(bool cut, const std::string& key, const std::string& what);
// `attempt(planes)` (planes in d), and when it throws ConvergenceError or SlabCutError,
// `on_retry` then `attempt(moved)`, moved by moved_slab_planes_d (only about the slabs `failed()`
// names, when it is given and names any); returns what the attempt that succeeded returned. The
// error when both fail names both attempts (throw_slabs_failed, by the second's kind); when the
// planes have nowhere else to go, the first's, not tried again.
template <class Attempt>
auto attempt_with_planes_moved(const Bed& bed, const SurfaceParams& surface, const std::vector<double>& planes,
                               const std::string& key, Attempt&& attempt,
                               const std::function<void(const PlanesMoved&)>& on_retry,
                               const std::function<std::vector<int>()>& failed = {}) {
  PlanesMoved moved;
  bool cut = false;
  try {
    return attempt(planes);
  } catch (const ConvergenceError& e) {
    moved.because = e.what();
  } catch (const SlabCutError& e) {
    moved.because = e.what(), cut = true;
  }
  moved.from_d = planes, moved.to_d = moved_slab_planes_d(bed, surface, planes, failed ? failed() : std::vector<int>{});
  if (moved.to_d == planes) throw_slabs_failed(cut, key, moved.because);
  on_retry(moved);
  const auto both = [&](const char* second) {
    return fmt::format("{}; and with the planes moved from {:.3f} to {:.3f} d: {}", moved.because,
                       fmt::join(moved.from_d, ", "), fmt::join(moved.to_d, ", "), second);
  };
  try {
    return attempt(moved.to_d);
  } catch (const ConvergenceError& e) {
    throw_slabs_failed(false, key, both(e.what()));
  } catch (const SlabCutError& e) {
    throw_slabs_failed(true, key, both(e.what()));
  }
}

// InputError naming `name` (the option or key that gave them) unless `planes` are slabs - 1
// heights (d above the floor), increasing, inside the fluid domain of `bed` under `surface`.
void check_given_planes_d(const Bed& bed, const SurfaceParams& surface, const std::vector<double>& planes, int slabs,
                          const std::string& name);
// The fluid domain's profile (fluid_domain_profile, its size at `volume_per_cell`) in bins fine
// enough to place the planes of `slabs` slabs: 0.02 d, at least 100 per slab. On a bed of more
// than twice `spheres_per_window` spheres (no clip window, no period) made window by window
// (survey_stretches), each stretch's bins from its own window, so that no process treats the
// whole bed at once: the same bins (to rounding) and wall gap; the size's fluid volume then
// leaves the contacts' parts out, and its thin gaps are shared as the cells are.
FluidDomainProfile slab_profile(const Bed& bed, const SurfaceParams& surface, int slabs, double volume_per_cell,
                                std::size_t spheres_per_window = kSpheresPerSurveyWindow);
// The size of slab `k`'s fluid domain between `planes` (d) at `volume_per_cell` (m^3), from the
// spheres within piece_margin_d of it only (its window, window_for_cuts), so that a rank sizes
// its piece without treating the whole bed: the window's size, each part times its share between
// the slab's planes (the fluid volume, the gaps' cells and the loops' edges by their own
// profiles, the thin gaps by the cells'). Sums over the slabs to about the whole domain's size.
FluidDomainSize slab_domain_size(const Bed& bed, const SurfaceParams& surface, const std::vector<double>& planes,
                                 int k, double volume_per_cell);

// The surface parameters of slab `k` (from 0, bottom up) between `planes` (slab_planes_d): a clip
// window from the plane below it to the plane above it, the whole domain's ends (or the scene's
// clip window's) outside. The surface stage may move a plane a little to keep it clear of the
// spheres, alike for the slabs on either side.
SurfaceParams slab_surface(const Bed& bed, const SurfaceParams& surface, const std::vector<double>& planes, int k);

// Slab `k` between `planes` meshed on its own, needing no other slab's surface: from its clip
// window (slabs_from_clip_windows) over the spheres within piece_margin_d of it (spheres_between:
// the whole bed's wall gap in surface.ring_wall_gap_m, else found by treating the whole bed),
// or under treated contacts from its window widened by
// piece_margin_d + 1 d (its own clip planes free to move 1 d, so they stay at least
// piece_margin_d away), ringed at every plane and cut at its own (cut_by_plane; the report's
// "plane_cut" lists each cut); its surface and build_volume_mesh with
// `params` (`params.layers` off), quietly; `release_memory` as there (off when more slabs follow
// in the same process, whose gmsh runs reuse what this one freed). Its report adds "heights_d" (asked), "planes_d"
// (where the surface stage put them), "surface_triangles" and "cells". SlabCutError when
// the slab cannot be cut from the bed; ConvergenceError naming the slab when
// its cells fail the gate (written to `bad_cells_path`).
VolumeMesh mesh_slab(const Bed& bed, const SurfaceParams& surface, const std::vector<double>& planes, int k,
                     double d_ref, const VolumeMeshParams& params, const std::filesystem::path& bad_cells_path,
                     bool release_memory);

// The volume mesh of the fluid domain of `bed` under `surface`, in slabs meshed one after the
// other by build_volume_mesh (each slab with `params`: its algorithms, optimiser and gate;
// `params.layers` must be off) and joined, each by mesh_slab where pieces_possible (so the slabs
// are the pieces ranks would make); treated contacts in a box are cut from `whole` (the surface
// stage's fluid surface of the same bed under `surface`; m), which may be null otherwise.
// `d_ref` (m) scales the parameters; the report holds each slab's report under "slabs" (a cut
// slab's with "plane_cut": each cut's plane, loops, snapped vertices, plane triangles, edges
// flipped and split, and the triangles left for gmsh to recover).
// Writes the joined mesh (MSH 2.2: physical groups per patch and `fluid`) to `msh_path` when
// not empty. std::runtime_error when two slabs' shared plane is not triangulated alike (a
// defect of ours). When a slab cannot be cut from the bed (SlabCutError) or fails the gate, or
// the joined mesh fails it at the joins (its cells written to `bad_cells_path`), the slabs are
// meshed once more between planes moved by moved_slab_planes_d (the report then says so under
// "planes_moved": from_d, to_d and the first failure); the error names both attempts
// (attempt_with_planes_moved: InputError naming mesh.slabs, or ConvergenceError).
VolumeMesh build_slabbed_volume_mesh(const Bed& bed, const SurfaceParams& surface, const TriangleMesh* whole,
                                     int slabs, double d_ref, const VolumeMeshParams& params,
                                     const std::filesystem::path& msh_path,
                                     const std::filesystem::path& bad_cells_path, Progress& progress);

}  // namespace bedforge::meshing
