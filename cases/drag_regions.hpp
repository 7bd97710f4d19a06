#pragma once
#include <Eigen/Core>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/bed.hpp"
#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::cases {

// The drag on the particles split by where it acts: each particle face in the bed section (where
// dp/L is measured) goes to a band of the gap at its centre, the distance to the nearest other
// solid surface (another sphere or a wall), so that a study can say which region carries the
// pressure drop's discretisation error (near contacts, where one cell spans a narrow gap, or in
// the open pores); the faces beyond the section's planes (the bed's ends) go to one more band.
// The band edges are case.drag_by_gap_d; the forces come from one OpenFOAM forces object per band.
struct GapBand {
  double from_d = 0.0, to_d = 0.0;  // the gap's band, in reference diameters; to_d infinite for the last
  bool in_section = true;           // false: the faces beyond the section's planes, whatever their gap
  long faces = 0;                   // particle faces in it
  double area_m2 = 0.0;             // their area
  // Sums over its faces of S_z and z S_z, S the face's area vector out of the fluid (m^2, m^3):
  // the force of a pressure field linear in z on them, which a band's pressure force holds
  // besides its own (its faces are no closed surface).
  double area_z_m2 = 0.0, moment_z_m3 = 0.0;
  // Set by the run: the force along the flow on them (N), its shear part, and its pressure part
  // less that of the section's mean pressure, linear between its planes (in a periodic section,
  // whose pressure has no mean gradient, less that of p = 0): the band's own form drag.
  double drag_n = 0.0, viscous_n = 0.0, form_n = 0.0;
  int number = 0;                   // from 0, the narrowest; particles_ends last
  std::string patch() const;        // its patch: particles_gap<number>, or particles_ends
  std::string force_object() const; // its forces function object: forceParticlesGap<number>, or forceParticlesEnds
  nlohmann::json to_json() const;
  static GapBand from_json(const nlohmann::json& j);
};

// The forces along the flow (N, OpenFOAM's forces function objects, pressure and viscous, over the
// whole domain): the drag on the walls and on the particles, and the push of the fluid through
// the inlet and outlet (in a periodic section, the driving gradient over the fluid's volume).
// Steady flow conserves momentum, so the drag equals the push but for the momentum flux
// difference between inlet and outlet (rho u^2 A / 3 from a plug to a parabola), the solver's
// convergence and the wall gradient the forces object takes (a discretisation error, falling as
// the mesh refines).
struct Drag {
  double walls_n = 0.0, particles_n = 0.0, push_inlet_outlet_n = 0.0;
  double walls_viscous_n = 0.0, particles_viscous_n = 0.0;  // their shear; the rest is pressure (form drag)
  // With case.drag_by_gap_d: the particles' drag by the gap, and the walls' beyond the section's
  // planes (split_walls_at_section; all and viscous), so that walls less these is the section's.
  std::vector<GapBand> particles_by_gap;
  double walls_ends_n = 0.0, walls_ends_viscous_n = 0.0;
  double wall_share() const { return walls_n / (walls_n + particles_n); }
  double force_balance_relative_error() const { return (walls_n + particles_n) / push_inlet_outlet_n - 1.0; }
  nlohmann::json to_json() const;  // with wall_share and force_balance_relative_error, for the reader
  static Drag from_json(const nlohmann::json& j);
};

// Gap (m) at each point of `points` lying on a particle's surface (as meshed: to within a cell of
// it): the distance from the point to the nearest sphere (minimum image in a periodic container)
// other than the one it lies on (the nearest, by |distance to the surface|), or to the nearest
// wall, whichever is less, at least 0; capped at `reach` (m): a gap wider than it reads `reach`.
// Spheres are found on a cell grid (core/sphere_grid.hpp), so the work is O(points + spheres).
std::vector<double> gaps_at_particle_points(const std::vector<Eigen::Vector3d>& points, const Bed& bed, double reach);

// Splits `mesh`'s patch "particles" into one patch per band of the gap at its faces' centres,
// edges `edges_d` (ascending, reference diameters d_ref m): particles_gap0 below the first edge,
// ..., the last beyond the last edge, of the faces whose centre lies between the section's planes
// z_low and z_high (m), and particles_ends of the others; each keeps the type "wall", every band is
// written (empty ones too, so that every case has the same patches). The patch's faces are
// reordered, the other faces and the cells are not touched. Returns the bands with their faces
// and areas, particles_ends last. A mesh without a particles patch is left as it is (no bands).
std::vector<GapBand> split_particles_by_gap(meshing::PolyMesh& mesh, const Bed& bed, double d_ref,
                                            const std::vector<double>& edges_d, double z_low, double z_high);
std::vector<GapBand> split_particles_by_gap(meshing::PolyhedralMesh& mesh, const Bed& bed, double d_ref,
                                            const std::vector<double>& edges_d, double z_low, double z_high);

// Splits each wall patch of `mesh` (type "wall", not the particles') into the faces whose centre
// lies between the section's planes z_low and z_high (m), keeping its name, and the others,
// <name>_ends (written even when empty), so that the walls' drag in the section, where dp/L is
// measured, is told from that along the inlet's and outlet's lengths. The patches' faces are
// reordered, the other faces and the cells are not touched. Returns the faces beyond the section.
long split_walls_at_section(meshing::PolyMesh& mesh, double z_low, double z_high);
long split_walls_at_section(meshing::PolyhedralMesh& mesh, double z_low, double z_high);

}  // namespace bedforge::cases
