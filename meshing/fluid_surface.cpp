#include "meshing/fluid_surface.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "analysis/void_fraction.hpp"
#include "core/error.hpp"
#include "core/neighbour_list.hpp"
#include "meshing/primitives.hpp"

namespace bedforge::meshing {

SurfaceParams read_surface_params(SceneSection& c, SceneSection& s) {
  SurfaceParams p;
  p.treatment = c.choice("treatment", "shrink", {"shrink", "none"}) == "none" ? SurfaceParams::Treatment::none
                                                                              : SurfaceParams::Treatment::shrink;
  p.shrink_factor = c.number("shrink_factor", p.shrink_factor, Range{0.5, 1.0, false, true});
  p.edge_length_d = s.number("edge_length_d", p.edge_length_d, Range{1e-3, 1.0, false, false});
  p.inlet_length_d = s.number("inlet_length_d", p.inlet_length_d, Range::non_negative());
  p.outlet_length_d = s.number("outlet_length_d", p.outlet_length_d, Range::non_negative());
  p.self_intersection_limit = s.integer("self_intersection_limit", p.self_intersection_limit, 0, 1'000'000'000);
  return p;
}

nlohmann::json to_json(const SurfaceParams& p) {
  return {{"treatment", p.treatment == SurfaceParams::Treatment::none ? "none" : "shrink"},
          {"shrink_factor", p.shrink_factor},
          {"edge_length_d", p.edge_length_d},
          {"inlet_length_d", p.inlet_length_d},
          {"outlet_length_d", p.outlet_length_d},
          {"self_intersection_limit", p.self_intersection_limit}};
}

namespace {

// Largest distance a polygon of n sides inscribed in a circle of radius R lies inside it.
double sagitta(double R, int n) { return R * (1.0 - std::cos(std::numbers::pi / n)); }

}  // namespace

FluidSurface build_fluid_surface(const Bed& bed, const SurfaceParams& p) {
  if (bed.size() == 0) throw InputError("the bed has no spheres to build a surface around");
  const Container& c = *bed.container;
  const auto* cyl = dynamic_cast<const Cylinder*>(&c);
  const auto* ann = dynamic_cast<const Annulus*>(&c);
  if (!cyl && !ann)
    throw InputError(fmt::format("the surface stage handles cylinder and annulus containers; this bed's container is "
                                 "a {}",
                                 c.kind()));
  const double d = sauter_mean(bed.diameters);
  const double d_min = *std::min_element(bed.diameters.begin(), bed.diameters.end());
  const double s = p.treatment == SurfaceParams::Treatment::shrink ? p.shrink_factor : 1.0;
  const double edge = p.edge_length_d * d;

  // Contacts and the gaps the treatment leaves, from the neighbour list (skin: the shrink margin).
  std::vector<double> r(bed.size());
  for (std::size_t i = 0; i < bed.size(); ++i) r[i] = 0.5 * bed.diameters[i];
  const double contact_tol = 1e-4 * d_min;
  NeighbourList nl(std::max(contact_tol, (1.0 - s) * 2.0 * *std::max_element(r.begin(), r.end())) + 1e-12 * d);
  nl.build(bed.centres, r, c);
  long pp = 0, pw = 0;
  double min_pair_gap = std::numeric_limits<double>::infinity(), min_wall_gap = min_pair_gap;
  std::size_t worst_i = 0, worst_j = 0, worst_wall = 0;
  for (std::size_t i = 0; i < bed.size(); ++i) {
    for (int j : nl.of(i)) {
      if (static_cast<std::size_t>(j) < i) continue;
      const double dist = (bed.centres[i] - bed.centres[j]).norm();
      if (dist - r[i] - r[j] <= contact_tol) ++pp;
      const double gap = dist - s * (r[i] + r[j]);
      if (gap < min_pair_gap) min_pair_gap = gap, worst_i = i, worst_j = j;
    }
    WallContact w[Container::kMaxWallContacts];
    const int touching = c.wall_contacts(bed.centres[i], r[i] + contact_tol, w);
    pw += touching;
    // Gap to each curved wall after the treatment.
    const double rho = std::hypot(bed.centres[i].x(), bed.centres[i].y());
    const double outer = cyl ? cyl->radius() : ann->outer_radius();
    double gap = outer - rho - s * r[i];
    if (ann) gap = std::min(gap, rho - ann->inner_radius() - s * r[i]);
    if (gap < min_wall_gap) min_wall_gap = gap, worst_wall = i;
  }
  if (!(min_pair_gap > 0.0))
    throw InputError(fmt::format("spheres {} and {} still touch or overlap by {:.3g} d after the '{}' treatment "
                                 "(contacts.shrink_factor = {}); allowed: a factor small enough to open every contact",
                                 worst_i, worst_j, -min_pair_gap / d, s < 1.0 ? "shrink" : "none", s));
  if (!(min_wall_gap > 0.0))
    throw InputError(fmt::format("sphere {} still touches or crosses the wall by {:.3g} d after the '{}' treatment "
                                 "(contacts.shrink_factor = {}); allowed: a factor small enough to open every contact",
                                 worst_wall, -min_wall_gap / d, s < 1.0 ? "shrink" : "none", s));

  // Domain and its wall facets: an inscribed polygon lies inside the true wall by its sagitta,
  // which must stay below the narrowest wall gap or the wall facets would cut a sphere.
  const double top = analysis::bed_height(bed);
  const double z0 = -p.inlet_length_d * d, z1 = top + p.outlet_length_d * d;
  const double R = cyl ? cyl->radius() : ann->outer_radius();
  // (The inner wall of an annulus is inscribed too, so its facets bend away from the spheres.)
  const double wall_sag = sagitta(R, ring_points(R, edge));
  if (wall_sag >= 0.5 * min_wall_gap)
    throw InputError(fmt::format("surface.edge_length_d = {}: the wall facets lie up to {:.3g} d inside the wall, more "
                                 "than half the narrowest wall gap ({:.3g} d, sphere {}); allowed: a shorter edge or a "
                                 "smaller contacts.shrink_factor",
                                 p.edge_length_d, wall_sag / d, min_wall_gap / d, worst_wall));
  FluidSurface out;
  TriangleMesh& f = out.fluid;
  f.append(tube_mesh(R, z0, z1, edge, true, "wall"));
  const bool stagger_top = top_ring_staggered(z0, z1, edge);
  const double r_in = ann ? ann->inner_radius() : 0.0;
  f.append(ring_mesh(r_in, R, z0, edge, false, false, false, "inlet"));
  f.append(ring_mesh(r_in, R, z1, edge, true, stagger_top, stagger_top, "outlet"));
  if (ann) f.append(tube_mesh(r_in, z0, z1, edge, false, "inner_wall"));
  f.weld();  // the container parts share bit-identical seam vertices
  double chordal = 0.0, solid = 0.0, solid0 = 0.0, area0 = 0.0;
  for (std::size_t i = 0; i < bed.size(); ++i) {
    const double ri = s * r[i];
    f.append(sphere_mesh(bed.centres[i], ri, edge, false, "particles"));
    out.bed.append(sphere_mesh(bed.centres[i], ri, edge, true, "particles"));
    chordal = std::max(chordal, sphere_chordal_deviation(ri, edge));
    solid += 4.0 / 3.0 * std::numbers::pi * ri * ri * ri;
    solid0 += 4.0 / 3.0 * std::numbers::pi * r[i] * r[i] * r[i];
    area0 += 4.0 * std::numbers::pi * r[i] * r[i];
  }
  const double domain = c.cross_section_area() * (z1 - z0);
  const MeshQuality q = mesh_quality(f);
  out.report = {
      {"parameters", to_json(p)},
      {"contacts_treated", {{"particle_particle", pp}, {"particle_wall", pw}, {"tolerance_d", 1e-4}}},
      {"solid_volume_change_relative", solid / solid0 - 1.0},
      {"particle_area_change_relative", s * s - 1.0},
      {"smallest_gap_d", {{"particle_particle", min_pair_gap / d}, {"particle_wall", min_wall_gap / d}}},
      {"domain_m", {{"inlet_z", z0}, {"outlet_z", z1}}},
      {"fluid_volume_exact_m3", domain - solid},
      {"void_fraction_bed_section_change", -(solid - solid0) / (c.cross_section_area() * top)},
      {"chordal_deviation_d", chordal / d},
      {"wall_sagitta_d", wall_sag / d},
      {"triangles", f.triangles.size()},
      {"min_angle_deg", q.min_angle_deg},
      {"min_edge_d", q.min_edge / d},
      {"max_edge_d", q.max_edge / d}};
  return out;
}

}  // namespace bedforge::meshing
