#pragma once
#include <nlohmann/json.hpp>

#include "core/bed.hpp"
#include "core/scene_section.hpp"
#include "meshing/triangle_mesh.hpp"

namespace bedforge::meshing {

// Contact treatment and fluid-domain surface, scene sections [contacts] and [surface]. Lengths
// in reference diameters d (Sauter mean); `resolve` turns them into metres in one place.
struct SurfaceParams {
  enum class Treatment { none, shrink };
  Treatment treatment = Treatment::shrink;
  double shrink_factor = 0.99;          // shrink: every sphere scaled about its centre
  double edge_length_d = 0.1;           // target triangle edge, walls and spheres
  double inlet_length_d = 1.0;          // empty section from the inlet plane to the floor
  double outlet_length_d = 1.0;         // empty section from the top of the bed to the outlet
  long self_intersection_limit = 2'000'000;  // triangles above which the CGAL self-intersection test is skipped
};
SurfaceParams read_surface_params(SceneSection& contacts, SceneSection& surface);
nlohmann::json to_json(const SurfaceParams& p);

struct FluidSurface {
  TriangleMesh fluid;  // closed: container between inlet and outlet, minus the treated spheres (m)
  TriangleMesh bed;    // the closed treated particles, normals outward (m)
  nlohmann::json report;
};

// Treats the contacts of `bed` and builds the fluid domain's surface: patches `inlet`,
// `outlet`, `wall` (and `inner_wall` for an annulus), `particles`. InputError, naming the
// particles, when the treatment leaves spheres overlapping or touching a wall, or when the
// wall facets would cut into the gaps left; the report holds the treatment's effect (contacts
// treated, solid volume and area change, smallest gap) and the surface's accuracy (chordal
// deviation, exact fluid volume, triangle quality).
FluidSurface build_fluid_surface(const Bed& bed, const SurfaceParams& params);

}  // namespace bedforge::meshing
