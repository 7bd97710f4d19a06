#pragma once
#include <Eigen/Core>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/bed.hpp"
#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::cases {

// The drag on the particles split by where it acts: each particle face goes to a band of the gap
// at its centre, the distance to the nearest other solid surface (another sphere or a wall), so
// that a study can say which region carries the pressure drop's discretisation error (near
// contacts, where one cell spans a narrow gap, or in the open pores). The band edges are
// case.drag_by_gap_d; the forces come from one OpenFOAM forces object per band.
struct GapBand {
  double from_d = 0.0, to_d = 0.0;  // the gap's band, in reference diameters; to_d infinite for the last
  long faces = 0;                   // particle faces in it
  double area_m2 = 0.0;             // their area
  double drag_n = 0.0, viscous_n = 0.0;  // the force along the flow on them (N) and its shear part; set by the run
  int number = 0;                   // from 0, the narrowest
  std::string patch() const;        // its patch: particles_gap<number>
  std::string force_object() const; // its forces function object: forceParticlesGap<number>
  nlohmann::json to_json() const;
  static GapBand from_json(const nlohmann::json& j);
};

// Gap (m) at each point of `points` lying on a particle's surface (as meshed: to within a cell of
// it): the distance from the point to the nearest sphere (minimum image in a periodic container)
// other than the one it lies on (the nearest, by |distance to the surface|), or to the nearest
// wall, whichever is less, at least 0; capped at `reach` (m): a gap wider than it reads `reach`.
// Spheres are found on a cell grid, so the work is O(points + spheres).
std::vector<double> gaps_at_particle_points(const std::vector<Eigen::Vector3d>& points, const Bed& bed, double reach);

// Splits `mesh`'s patch "particles" into one patch per band of the gap at its faces' centres,
// edges `edges_d` (ascending, reference diameters d_ref m): particles_gap0 below the first edge,
// ..., the last beyond the last edge; each keeps the type "wall", every band is written (empty
// ones too, so that every case has the same patches). The patch's faces are reordered, the other
// faces and the cells are not touched. Returns the bands with their faces and areas. A mesh
// without a particles patch is left as it is (no bands).
std::vector<GapBand> split_particles_by_gap(meshing::PolyMesh& mesh, const Bed& bed, double d_ref,
                                            const std::vector<double>& edges_d);
std::vector<GapBand> split_particles_by_gap(meshing::PolyhedralMesh& mesh, const Bed& bed, double d_ref,
                                            const std::vector<double>& edges_d);

}  // namespace bedforge::cases
