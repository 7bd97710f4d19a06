#pragma once
#include <array>
#include <filesystem>
#include <optional>
#include <nlohmann/json.hpp>

#include "core/bed.hpp"
#include "core/scene_section.hpp"
#include "meshing/surface/end_wedges.hpp"
#include "meshing/surface/gap_spacing.hpp"
#include "meshing/surface/surface_checks.hpp"
#include "meshing/surface/triangle_mesh.hpp"

namespace bedforge::meshing {

// Contact treatment and fluid-domain surface, scene sections [contacts] and [surface]. Lengths
// in reference diameters d (Sauter mean); `resolve` turns them into metres in one place.
struct SurfaceParams {
  // none: spheres as they are (no contact allowed); shrink: every sphere scaled about its
  // centre; enlarge: every sphere grown, overlaps joined (union); bridge: a cylinder joins each
  // pair (and sphere and wall) closer than bridge_gap_d; cap: both sides cut flat, leaving cap_gap_d.
  enum class Treatment { none, shrink, enlarge, bridge, cap };
  Treatment treatment = Treatment::shrink;
  Treatment wall_treatment = Treatment::shrink;  // bridge, cap or none; shrink and enlarge act on the walls' contacts too
  double shrink_factor = 0.99;
  double enlarge_factor = 1.01;
  double enlarge_join_gap_d = 0.01;     // enlarge: spheres left nearer than this to a sphere or wall are grown to join it (thin joints are, whatever it is)
  double bridge_diameter_d = 0.2;
  double bridge_gap_d = 0.01;           // pairs closer than this get a bridge
  double cap_gap_d = 0.02;              // pairs closer than this are capped, leaving this gap
  // On a periodic section: the bridges and caps its planes cross are cut through (true) or
  // opened there, their spheres shrunk (false; see treat_periodic_section, build_cut_periodic_surface).
  bool cut_at_periodic_planes = false;
  // With a clip window: the bridges, caps and unions its planes cross are cut through (true, a
  // scene's default; build_cut_clip_surface) or opened there, their spheres shrunk (false;
  // treat_contacts).
  bool cut_at_clip_planes = false;
  double edge_length_d = 0.1;           // target triangle edge, walls and spheres
  double contact_edge_length_d = 0.033; // edge on the loops where treated contacts meet (refinement near contacts)
  double growth = 1.5;                  // edge growth per ring away from those loops
  // The spheres' vertices moved out so that their facets hold each sphere's volume
  // (match_sphere_volume), instead of lying on the sphere, inscribed, with less solid than it.
  bool facets_hold_sphere_volume = true;
  // Cells across narrow gaps: where a sphere or wall faces another surface closer than
  // cells_per_gap x edge_length_d, its edge shrinks to gap / cells_per_gap (not below
  // contact_edge_length_d), and the volume mesh follows. 0: edge_length_d everywhere.
  double cells_per_gap = 0.0;
  double inlet_length_d = 1.0;          // empty section from the inlet plane to the floor
  double outlet_length_d = 1.0;         // empty section from the top of the bed to the outlet
  // Height window of the bed (above the floor, d) whose planes are the inlet and outlet,
  // instead of the empty sections: the spheres crossing them are cut there.
  bool clip = false;
  double clip_bottom_d = 0.0, clip_top_d = 0.0;
  double clip_shift_d = 0.25;           // how far a clip plane may move to keep clear of the bed
  double clip_clearance_d = 0.005;      // from every sphere's top and bottom and every treated contact
  // Heights above the floor (d) where the walls get rings, not from a scene: the planes a bed's
  // pieces are cut at, so that each piece's window cuts the wall there alike (curved walls: a
  // row of vertices, wall_mesh; a box's sides: strips between them, passing a hole that
  // crosses one along either half of its loop; holes' vertices near a ring moved onto it);
  // and the narrowest wall gap of the whole bed (m), whose edge the ringed walls take, and walls
  // without rings when narrower than this bed's (0: this bed's; window_for_cuts sets both, and
  // spheres_between the gap).
  std::vector<double> wall_rings_d;
  double ring_wall_gap_m = 0.0;
  // Quality gate: a surface with a smaller angle fails, its triangles written to
  // bad_triangles.vtp (0 turns the gate off).
  double min_angle_deg = 2.0;
  // No treatment changes a sphere: the surface's spheres are the bed's own.
  bool keeps_spheres() const { return treatment == Treatment::none && wall_treatment == Treatment::none; }
  // The one scale every sphere takes: 1 when kept, shrink_factor when every sphere and contact
  // is shrunk; 0 when the treatment joins, cuts or grows them.
  double sphere_scale() const {
    if (keeps_spheres()) return 1.0;
    const bool shrunk = treatment == Treatment::shrink &&
                        (wall_treatment == Treatment::shrink || wall_treatment == Treatment::none);
    return shrunk ? shrink_factor : 0.0;
  }
  // +1 when the treatment only adds solid to the spheres (bridges, enlarged spheres), -1 when it
  // only takes it (shrink, caps), 0 when it keeps them or does both. On a bed periodic along some
  // side (`periodic`), contacts opened at its planes have their spheres shrunk, and so do those at
  // clip planes left open: a treatment that adds solid then does both.
  int solid_change(bool periodic) const;
};
const char* treatment_name(SurfaceParams::Treatment t);
// A scene's defaults are those of a pressure-drop run, where they differ from the struct's (the
// plain geometry a caller of this library starts from): bridged contacts (they change the bed's
// solid by +0.2 %, shrink by -3 %), a 0.15 d edge, a third of it at contacts and 4 cells across
// narrow gaps, the settings whose studies on a = 5, N = 500 converge in the asymptotic range; and
// clip windows cut through their contacts (docs/defaults.md).
inline constexpr double kSceneEdgeLengthD = 0.15, kSceneContactEdgeLengthD = 0.05, kSceneCellsPerGap = 4.0;
SurfaceParams read_surface_params(SceneSection& contacts, SceneSection& surface);
nlohmann::json to_json(const SurfaceParams& p);

// The rule for edges across narrow gaps as the surface stage applies it, from `p`'s
// cells_per_gap, contact and surface edges (d the reference diameter, m); unset when
// p.cells_per_gap is 0. The other inputs are GapSpacing's, kept by reference.
std::optional<GapSpacing> gap_spacing(const SurfaceParams& p, double d, const std::vector<Eigen::Vector3d>& centres,
                                      const std::vector<double>& radii, const std::vector<char>& kept,
                                      const Container& container);

// The spheres' clearance as match_sphere_volume limits their vertices' move by it: GapSpacing's
// gap() out to three surface edges (beyond the edge of a vertex's triangles and eight moves of
// edge^2 / (8 r), it does not limit the move); unset when p.facets_hold_sphere_volume is false.
// Inputs as gap_spacing's.
std::optional<GapSpacing> facet_clearance(const SurfaceParams& p, double d, const std::vector<Eigen::Vector3d>& centres,
                                          const std::vector<double>& radii, const std::vector<char>& kept,
                                          const Container& container);

// The fluid domain of `bed` under `p`, known before its surface is meshed, from one sampling of
// its narrow gaps. Throws treat_contacts's InputErrors.
//   size   the treated bed's exact fluid volume (m^3), the tetrahedra its narrow gaps add to a
//          mesh of the surface edge everywhere (GapSpacing::added_cells_profile at `volume_per_cell`
//          edge^3 per cell; 0 without cells_per_gap), the edges of its graded loops and its
//          contacts left as thin gaps: what the mesh estimate takes;
//   cells  along the height, `bins` bins of equal height from the inlet z0 to the outlet z1 (m),
//          each with a weight for the cells a mesh would have there (no unit): the fluid volume
//          over one edge^3 (the spheres at their treated radii, bridges and caps left out), plus
//          kCellsPerSurfaceEdgeSquared per edge^2 of the spheres' and walls' area (cells next to
//          a surface are smaller than in the bulk), plus the gaps' added cells at one edge^3 per
//          cell. What pieces of about equal cells are cut from; only the weights' ratios matter.
// kCellsPerSurfaceEdgeSquared is a calibration, of the surface term against the volume's one
// per edge^3: on a = 4, N = 80, 0.2 d, no gap rule, 3 d empty ends, the packed bed's heights held
// 2.1 times the cells its fluid volume gives at 0.24 edge^3 per cell and the empty ends 1.25
// times (2026-11-29, docs/findings.md), and 4 made the slabs' cells about even; validated on
// other beds in docs/mesh_case_benchmark.md (weak scaling: the ranks' cells).
inline constexpr double kCellsPerSurfaceEdgeSquared = 4.0;
struct FluidDomainSize {
  double volume_m3 = 0.0;
  double gap_cells = 0.0;
  // Edges on the loops where the mesh is graded from surface.contact_edge_length_d up to the
  // surface edge (treated contacts, clip planes' cuts; the spheres' and the walls' sides alike),
  // weighted by how much grading there is: 1 up to a contact edge of half the surface edge,
  // falling linearly to 0 when the two are equal (not measured there); 0 when the contact edge
  // is not the shorter.
  double contact_loop_edges = 0.0;
  // Contacts left as thin gaps (shrunk, or untreated), each refined around by the volume mesh.
  double thin_gap_contacts = 0.0;
};
struct FluidDomainProfile {
  FluidDomainSize size;
  double z0 = 0.0, z1 = 0.0;  // m
  std::vector<double> cells;  // bins
  // Bins: the fluid's volume (m^3; the spheres' slices taken out, their contacts' parts not), the
  // cells the narrow gaps add (at the volume per cell asked) and the graded loops' edges (each
  // loop in the bin of its first point), for a share of the size.
  std::vector<double> fluid_m3, gap_cells, loop_edges;
  // The whole bed's narrowest gap at a curved wall (m; infinite without one): the edge every
  // window of the bed rings its walls with (SurfaceParams::ring_wall_gap_m, window_for_cuts).
  double bed_wall_gap_m = 0.0;
};
// `grid` (m, its bottom and top): the bins over it instead of from z0 to z1 (a window's profile
// on the whole bed's bins, slab_profile's); the size stays the window's.
FluidDomainProfile fluid_domain_profile(const Bed& bed, const SurfaceParams& p, double volume_per_cell, int bins,
                                        const std::optional<std::array<double, 2>>& grid = std::nullopt);

struct FluidSurface {
  TriangleMesh fluid;  // closed: container between inlet and outlet, minus the treated spheres (m)
  TriangleMesh bed;    // the closed treated particles, normals outward (m)
  double exact_volume_m3 = 0.0;  // of the treated geometry's fluid domain, what the facets approximate
  std::vector<SurfacePiece> pieces;  // of `fluid`, each meshed on its own: walls, inlet, outlet, spheres, parts
  SurfaceCheck check;            // CGAL's verdict on `fluid` (build_checked_fluid_surface only)
  // Spheres' ends near the planes the surface is to be cut at (SurfaceParams::wall_rings_d) or
  // ends at (a clip window's, a periodic section's; there only ends the plane does not cut), which
  // the spheres grade their vertices about and a cut's face must too (PlaneCutParams::ends).
  std::vector<EndNearPlane> ends_near_planes;
  // The treated spheres whose surface comes within twice cells_per_gap x edge of those planes (the
  // face measures gaps to the nearer, and their spacing from their own neighbours), which a cut's
  // face sizes its edge across the fluid from (PlaneCutParams::spheres); none without
  // [surface] cells_per_gap.
  std::vector<SphereNearPlane> spheres_near_planes;
  nlohmann::json report;
};

// Treats the contacts of `bed` and builds the fluid domain's surface: patches `inlet`,
// `outlet`, `wall` (the four sides of a box; and `inner_wall` for an annulus), `particles`. InputError, naming the
// particles, when the treatment leaves spheres overlapping or touching a wall, or a wall gap
// so thin that wall facets short enough to keep clear of it would be shorter than the contact
// edge (the curved walls take a shorter edge than the spheres where their gaps need it); the
// report holds the treatment's effect (contacts
// treated, solid volume and area change, smallest gap) and the surface's accuracy (chordal
// deviation, exact fluid volume, triangle quality).
FluidSurface build_fluid_surface(const Bed& bed, const SurfaceParams& params);

// The surface stage: build_fluid_surface, then CGAL's check (closed, 2-manifold, no
// self-intersection, tested by pieces; the enclosed volume against
// the exact one, all into the report) and the angle gate. std::runtime_error locating the defects
// when the surface is not valid (a defect of ours, not of the input); ConvergenceError naming the
// particles nearest the triangles below params.min_angle_deg, after writing those triangles to
// `bad_triangles_path` (VTK PolyData).
FluidSurface build_checked_fluid_surface(const Bed& bed, const SurfaceParams& params,
                                         const std::filesystem::path& bad_triangles_path);

}  // namespace bedforge::meshing
