#include "meshing/fluid_surface.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "analysis/void_fraction.hpp"
#include "core/error.hpp"
#include "meshing/contacts.hpp"
#include "meshing/primitives.hpp"
#include "meshing/wall_mesh.hpp"

namespace bedforge::meshing {

namespace {

constexpr std::array<const char*, 5> kTreatments{"none", "shrink", "enlarge", "bridge", "cap"};

SurfaceParams::Treatment treatment_of(const std::string& name) {
  return static_cast<SurfaceParams::Treatment>(std::find(kTreatments.begin(), kTreatments.end(), name) -
                                               kTreatments.begin());
}

}  // namespace

const char* treatment_name(SurfaceParams::Treatment t) { return kTreatments[static_cast<int>(t)]; }

SurfaceParams read_surface_params(SceneSection& c, SceneSection& s) {
  SurfaceParams p;
  p.treatment = treatment_of(c.choice("treatment", "shrink", {"none", "shrink", "enlarge", "bridge", "cap"}));
  const std::string wall = c.choice("wall_treatment", "same", {"same", "bridge", "cap", "none"});
  p.wall_treatment = wall == "same" ? p.treatment : treatment_of(wall);
  if (wall != "same" && (p.treatment == SurfaceParams::Treatment::shrink || p.treatment == SurfaceParams::Treatment::enlarge))
    throw InputError(fmt::format("contacts.wall_treatment = '{}' with contacts.treatment = '{}': shrink and enlarge act "
                                 "on the spheres, so on their wall contacts too; allowed: 'same', or a treatment "
                                 "bridge, cap or none",
                                 wall, treatment_name(p.treatment)));
  p.shrink_factor = c.number("shrink_factor", p.shrink_factor, Range{0.5, 1.0, false, true});
  p.enlarge_factor = c.number("enlarge_factor", p.enlarge_factor, Range{1.0, 1.2, true, false});
  p.bridge_diameter_d = c.number("bridge_diameter_d", p.bridge_diameter_d, Range{0.0, 0.8, true, true});
  p.bridge_gap_d = c.number("bridge_gap_d", p.bridge_gap_d, Range{0.0, 0.5, false, false});
  p.cap_gap_d = c.number("cap_gap_d", p.cap_gap_d, Range{0.0, 0.2, true, false});
  p.edge_length_d = s.number("edge_length_d", p.edge_length_d, Range{1e-3, 1.0, false, false});
  p.contact_edge_length_d = s.number("contact_edge_length_d", p.contact_edge_length_d, Range{1e-3, 1.0, false, false});
  p.growth = s.number("growth", p.growth, Range{1.05, 2.0, false, false});
  p.inlet_length_d = s.number("inlet_length_d", p.inlet_length_d, Range::non_negative());
  p.outlet_length_d = s.number("outlet_length_d", p.outlet_length_d, Range::non_negative());
  p.self_intersection_limit = s.integer("self_intersection_limit", p.self_intersection_limit, 0, 1'000'000'000);
  return p;
}

nlohmann::json to_json(const SurfaceParams& p) {
  return {{"treatment", treatment_name(p.treatment)},
          {"wall_treatment", treatment_name(p.wall_treatment)},
          {"shrink_factor", p.shrink_factor},
          {"enlarge_factor", p.enlarge_factor},
          {"bridge_diameter_d", p.bridge_diameter_d},
          {"bridge_gap_d", p.bridge_gap_d},
          {"cap_gap_d", p.cap_gap_d},
          {"edge_length_d", p.edge_length_d},
          {"contact_edge_length_d", p.contact_edge_length_d},
          {"growth", p.growth},
          {"inlet_length_d", p.inlet_length_d},
          {"outlet_length_d", p.outlet_length_d},
          {"self_intersection_limit", p.self_intersection_limit}};
}

FluidSurface build_fluid_surface(const Bed& bed, const SurfaceParams& p) {
  if (bed.size() == 0) throw InputError("the bed has no spheres to build a surface around");
  const double d = sauter_mean(bed.diameters), edge = p.edge_length_d * d;
  const double top = analysis::bed_height(bed);
  const double z0 = -p.inlet_length_d * d, z1 = top + p.outlet_length_d * d;
  TreatedBed tb = treat_contacts(bed, p, z0, z1);
  const Container& c = *bed.container;
  const auto* ann = dynamic_cast<const Annulus*>(&c);
  const double R = ann ? ann->outer_radius() : dynamic_cast<const Cylinder&>(c).radius();
  const double r_in = ann ? ann->inner_radius() : 0.0;

  // The wall is faceted between vertices on it: its facets lie inside it by up to the sagitta,
  // which must stay below half the narrowest wall gap or a facet would come close to a sphere.
  const double wall_sag = R * (1.0 - std::cos(std::numbers::pi / ring_points(R, edge)));
  if (wall_sag >= 0.5 * tb.min_wall_gap)
    throw InputError(fmt::format("surface.edge_length_d = {}: the wall facets lie up to {:.3g} d inside the wall, more "
                                 "than half the narrowest gap left at the wall ({:.3g} d); allowed: a shorter edge or a "
                                 "treatment that leaves a wider gap",
                                 p.edge_length_d, wall_sag / d, tb.min_wall_gap / d));

  // Spheres, each on its own (in parallel), stopping at their cuts.
  const std::size_t n = bed.size();
  std::vector<TriangleMesh> spheres(n);
  std::vector<double> chordal(n, 0.0);
  std::vector<std::string> failure(n);
#pragma omp parallel for schedule(dynamic, 16)
  for (std::size_t i = 0; i < n; ++i) {
    try {
      spheres[i] = sphere_mesh(bed.centres[i], tb.radius[i], tb.cuts[i], edge, p.growth, true, "particles");
      chordal[i] = chordal_deviation(spheres[i], bed.centres[i], tb.radius[i]);
    } catch (const CutConflict& e) {
      failure[i] = fmt::format("sphere {} (cuts: {}): {}; allowed: a shorter surface.contact_edge_length_d or "
                               "another treatment",
                               i, fmt::join(tb.cut_names[i], ", "), e.what());
    }
  }
  for (const auto& f : failure)
    if (!f.empty()) throw InputError(f);

  // Container: walls with holes where the bed meets them, inlet and outlet sharing their edges.
  auto walls = [&](double radius, const std::vector<WallHole>& holes, bool outward, const std::string& patch) {
    try {
      return wall_mesh(radius, z0, z1, edge, holes, p.growth, outward, patch);
    } catch (const CutConflict& e) {
      throw InputError(fmt::format("the {}: {}", patch, e.what()));
    }
  };
  const WallMesh outer = walls(R, tb.outer_holes, true, "wall");
  FluidSurface out;
  TriangleMesh& f = out.fluid;
  f.append(outer.outside);
  f.append(ring_mesh(Frame::along({0.0, 0.0, z0}, Eigen::Vector3d::UnitZ()), r_in, R, edge, false, "inlet"));
  f.append(ring_mesh(Frame::along({0.0, 0.0, z1}, Eigen::Vector3d::UnitZ()), r_in, R, edge, true, "outlet"));
  out.bed.append(outer.inside);
  if (ann) {
    const WallMesh inner = walls(r_in, tb.inner_holes, false, "inner_wall");
    f.append(inner.outside);
    out.bed.append(inner.inside);
  }
  // The bed solid (normals out of it), and the same pieces turned inside out for the fluid.
  TriangleMesh solid;
  for (const auto& m : spheres) solid.append(m);
  for (const auto& m : tb.parts) solid.append(m);
  out.bed.append(solid);
  for (auto& t : solid.triangles) std::swap(t[1], t[2]);
  f.append(solid);
  f.weld();
  out.bed.weld();

  const double domain = std::numbers::pi * (R * R - r_in * r_in) * (z1 - z0);
  const MeshQuality q = mesh_quality(f);
  out.report = tb.report;
  out.report["parameters"] = to_json(p);
  out.report["domain_m"] = {{"inlet_z", z0}, {"outlet_z", z1}};
  out.report["fluid_volume_exact_m3"] = domain - tb.solid_volume;
  out.report["void_fraction_bed_section_change"] =
      -out.report["solid_volume_change_m3"].get<double>() / (c.cross_section_area() * top);
  out.report["chordal_deviation_d"] = *std::max_element(chordal.begin(), chordal.end()) / d;
  out.report["wall_sagitta_d"] = wall_sag / d;
  out.report["triangles"] = f.triangles.size();
  out.report["min_angle_deg"] = q.min_angle_deg;
  out.report["min_edge_d"] = q.min_edge / d;
  out.report["max_edge_d"] = q.max_edge / d;
  return out;
}

}  // namespace bedforge::meshing
