#pragma once
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "core/bed.hpp"
#include "meshing/fluid_surface.hpp"
#include "meshing/primitives.hpp"
#include "meshing/wall_mesh.hpp"

namespace bedforge::meshing {

// The bed after its contact treatment, as pieces the surface is meshed from. Lengths in m.
struct TreatedBed {
  std::vector<double> radius;                     // per sphere, after shrink or enlarge
  std::vector<std::vector<SphereCut>> cuts;       // per sphere: where its mesh stops
  std::vector<std::vector<std::string>> cut_names;  // per sphere and cut, for error messages ("sphere 7", "wall")
  std::vector<TriangleMesh> parts;                // cap disks and bridges, normals out of the solid
  std::vector<WallHole> outer_holes, inner_holes;  // where the bed meets the walls
  double solid_volume = 0.0;                      // exact volume of the treated solid (m^3)
  double min_wall_gap = 0.0;                      // narrowest gap left between a sphere and a wall (m)
  nlohmann::json report;                          // contacts treated, volume and area change, gaps, angles
};

// Contact treatment (section [contacts]) of `bed` in a cylinder or annulus whose fluid domain
// runs from z0 to z1. Pairs and wall contacts closer than the treatment's gap tolerance get
// its geometry; every other gap is left as it is and the narrowest is reported. Volumes and
// areas are exact (closed forms, or quadrature to 1e-10 for bridges to a curved wall and
// spheres crossing one). InputError naming the particles when the treatment cannot give a
// valid solid: contacts left touching, overlaps too deep, a bridge through a third sphere, a
// sphere or bridge reaching the inlet or outlet plane, cuts on one sphere that overlap.
TreatedBed treat_contacts(const Bed& bed, const SurfaceParams& p, double z0, double z1);

}  // namespace bedforge::meshing
