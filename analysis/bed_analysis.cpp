#include "analysis/bed_analysis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "analysis/contact_statistics.hpp"
#include "analysis/line_intersection.hpp"
#include "analysis/segregation.hpp"
#include "analysis/void_fraction.hpp"
#include "core/error.hpp"

namespace bedforge::analysis {

namespace {

struct Scales {
  double d_ref, d_min, d_mean;  // Sauter mean, smallest, arithmetic mean (m)
};
Scales scales_of(const Bed& bed) {
  const double d_min = bed.diameters.empty() ? 0.0 : *std::min_element(bed.diameters.begin(), bed.diameters.end());
  double d_mean = 0.0;
  for (double d : bed.diameters) d_mean += d / static_cast<double>(bed.diameters.size());
  return {sauter_mean(bed.diameters), d_min, d_mean};
}

struct Slab {
  double lo, hi;
  bool valid;
};
Slab central_slab(const Bed& bed, const AnalysisParams& p, double d_ref) {
  // A periodic section has no floor or top to keep away from: the whole period is central.
  if (bed.container->axial_period() > 0.0) return {0.0, bed.container->axial_period(), true};
  const double h = bed_height(bed), cut = p.exclude_d * d_ref;
  return {cut, h - cut, h - cut > cut};
}

// The bed with centres wrapped into the container's periodic cell (sphere i stays sphere i).
Bed wrapped(const Bed& bed) {
  Bed out = bed;
  const Periodicity per = bed.container->periodicity();
  for (auto& c : out.centres) c = per.wrapped(c);
  return out;
}
// Along a periodic axis of period H: a wrapped bed with, appended, the images (z +- H) of the
// spheres that cross z = 0 or z = H, so that volume measures over [0, H] count every sphere's
// whole volume once. Otherwise the bed itself.
Bed with_axial_images(const Bed& wrapped_bed) {
  const double period = wrapped_bed.container->axial_period();
  Bed out = wrapped_bed;
  if (period == 0.0) return out;
  for (std::size_t i = 0; i < wrapped_bed.size(); ++i) {
    const Eigen::Vector3d& c = wrapped_bed.centres[i];
    const double r = 0.5 * wrapped_bed.diameters[i];
    for (double shift : {period, -period})
      if ((shift > 0.0 && c.z() < r) || (shift < 0.0 && c.z() + r > period)) {
        out.centres.push_back(c + Eigen::Vector3d(0.0, 0.0, shift));
        out.diameters.push_back(wrapped_bed.diameters[i]);
      }
  }
  return out;
}

}  // namespace

AnalysisParams read_analysis_params(SceneSection& s) {
  AnalysisParams p;
  p.exclude_d = s.number("exclude_d", p.exclude_d, Range::non_negative());
  p.radial_bin_d = s.number("radial_bin_d", p.radial_bin_d, Range::open(0.0, 10.0));
  p.axial_bin_d = s.number("axial_bin_d", p.axial_bin_d, Range::open(0.0, 10.0));
  p.contact_tolerance_d = s.number("contact_tolerance_d", p.contact_tolerance_d, Range::closed(0.0, 0.5));
  p.line_intersection = s.boolean("line_intersection", p.line_intersection);
  p.line_step_d = s.number("line_step_d", p.line_step_d, Range::open(0.0, 1.0));
  return p;
}

nlohmann::json to_json(const AnalysisParams& p) {
  return {{"exclude_d", p.exclude_d},
          {"radial_bin_d", p.radial_bin_d},
          {"axial_bin_d", p.axial_bin_d},
          {"contact_tolerance_d", p.contact_tolerance_d},
          {"line_intersection", p.line_intersection},
          {"line_step_d", p.line_step_d}};
}

nlohmann::json void_fraction_summary(const Bed& bed, const AnalysisParams& p) {
  const Scales sc = scales_of(bed);
  const double h = bed_height(bed);
  const Slab slab = central_slab(bed, p, sc.d_ref);
  const Bed whole = with_axial_images(wrapped(bed));
  nlohmann::json j{{"bed_height_m", h},
                   {"bed_height_d", h / sc.d_ref},
                   {"whole_bed", void_fraction(whole, 0.0, h)},
                   {"central_slab", nullptr},
                   {"central_slab_m", {slab.lo, slab.hi}}};
  if (bed.container->axial_period() > 0.0) j["axial_period_m"] = bed.container->axial_period();
  if (slab.valid) j["central_slab"] = void_fraction(whole, slab.lo, slab.hi);
  return j;
}

AnalysisResult analyse_bed(const Bed& given, const AnalysisParams& p) {
  const auto t0 = std::chrono::steady_clock::now();
  if (given.size() == 0) throw InputError("the bed has no spheres to analyse");
  // Per-sphere measures on `bed`, volume measures on `whole` (the same unless the axis is periodic).
  const Bed bed = wrapped(given), whole = with_axial_images(bed);
  const bool periodic_axis = bed.container->axial_period() > 0.0;
  const Scales sc = scales_of(bed);
  const double d = sc.d_ref;
  const double h = bed_height(bed);
  const Slab slab = central_slab(bed, p, d);
  const double z1 = slab.valid ? slab.lo : 0.0, z2 = slab.valid ? slab.hi : h;
  AnalysisResult out;
  nlohmann::json& j = out.report;
  j["parameters"] = to_json(p);
  j["reference_diameter_m"] = d;
  j["smallest_diameter_m"] = sc.d_min;
  j["spheres"] = bed.size();
  j["container"] = bed.container->to_json();
  j["void_fraction"] = void_fraction_summary(bed, p);
  j["profiles_window_m"] = {z1, z2};

  // Radial profiles, from each curved wall towards the axis or the middle of the gap.
  struct Wall {
    std::string name;  // report key and CSV stem
    double radius, end;
  };
  std::vector<Wall> walls;
  double reachable = 0.0;  // cross-section area open to centres of mean-size spheres
  if (const auto* cyl = dynamic_cast<const Cylinder*>(bed.container.get())) {
    walls = {{"radial_profile", cyl->radius(), 0.0}};
    reachable = std::numbers::pi * std::pow(std::max(0.0, cyl->radius() - 0.5 * sc.d_mean), 2);
  } else if (const auto* ann = dynamic_cast<const Annulus*>(bed.container.get())) {
    const double mid = 0.5 * (ann->outer_radius() + ann->inner_radius());
    walls = {{"radial_profile_outer", ann->outer_radius(), mid}, {"radial_profile_inner", ann->inner_radius(), mid}};
    const double ro = std::max(mid, ann->outer_radius() - 0.5 * sc.d_mean), ri = std::min(mid, ann->inner_radius() + 0.5 * sc.d_mean);
    reachable = std::numbers::pi * (ro * ro - ri * ri);
  }
  // Writes a wall profile's CSV and its features in the report: the value in the bin at the
  // wall and the first minimum, which the references quote.
  auto add_wall_profile = [&](const std::string& name, const Profile& prof, const std::string& where) {
    std::string text = "# void fraction between z = " + fmt::format("{} and {} m", z1, z2) + ", " + where +
                       "; wall distance in reference diameters and metres\nwall_distance_d,wall_distance_m,"
                       "void_fraction\n";
    for (std::size_t k = 0; k < prof.position.size(); ++k)
      text += fmt::format("{:.6g},{:.9g},{:.9g}\n", prof.position[k] / d, prof.position[k], prof.void_fraction[k]);
    out.csv_files[name + ".csv"] = text;
    double min_v = 2.0, min_at = 0.0;
    for (std::size_t k = 0; k < prof.position.size() && prof.position[k] < 1.0 * d; ++k)
      if (prof.void_fraction[k] < min_v) min_v = prof.void_fraction[k], min_at = prof.position[k] / d;
    j[name] = {{"wall_bin", prof.void_fraction.front()},
               {"first_minimum", min_v},
               {"first_minimum_at_d", min_at},
               {"bin_d", p.radial_bin_d}};
  };
  if (const auto* box = dynamic_cast<const Box*>(bed.container.get())) {
    const Periodicity per = box->periodicity();
    if (per.lx == 0.0)
      add_wall_profile("wall_profile_x",
                       wall_void_fraction(whole, 0, 0.5 * box->size_x(), box->size_y(), p.radial_bin_d * d, z1, z2),
                       "from the walls at x = +-size_x/2, both folded together");
    if (per.ly == 0.0)
      add_wall_profile("wall_profile_y",
                       wall_void_fraction(whole, 1, 0.5 * box->size_y(), box->size_x(), p.radial_bin_d * d, z1, z2),
                       "from the walls at y = +-size_y/2, both folded together");
  }
  for (const Wall& w : walls) {
    const Profile radial = radial_void_fraction(whole, w.radius, w.end, p.radial_bin_d * d, z1, z2);
    add_wall_profile(w.name, radial, fmt::format("radial, from the wall at r = {} m", w.radius));
    const CentreDistribution centres = radial_centre_distribution(bed, w.radius, w.end, p.radial_bin_d * d, z1, z2, reachable);
    std::string csv = "# radial distribution of sphere centres between z = " + fmt::format("{} and {} m", z1, z2) +
                      fmt::format(", from the wall at r = {} m", w.radius) +
                      "\nwall_distance_d,wall_distance_m,fraction,relative_density\n";
    for (std::size_t k = 0; k < centres.position.size(); ++k)
      csv += fmt::format("{:.6g},{:.9g},{:.9g},{:.9g}\n", centres.position[k] / d, centres.position[k],
                         centres.fraction[k], centres.relative_density[k]);
    std::string stem = w.name;
    stem.replace(0, std::string("radial_profile").size(), "centre_distribution");
    out.csv_files[stem + ".csv"] = csv;
    if (p.line_intersection) {
      // The same bins by line intersection, and how far the two methods differ.
      const Profile line = line_radial_void_fraction(whole, w.radius, w.end, p.radial_bin_d * d, z1, z2, p.line_step_d * d);
      csv = "# radial void fraction by line intersection (circle at the bin's middle radius), z from " +
            fmt::format("{} to {} m", z1, z2) + "\nwall_distance_d,wall_distance_m,void_fraction\n";
      double worst = 0.0, mean = 0.0;
      for (std::size_t k = 0; k < line.position.size(); ++k) {
        csv += fmt::format("{:.6g},{:.9g},{:.9g}\n", line.position[k] / d, line.position[k], line.void_fraction[k]);
        worst = std::max(worst, std::abs(line.void_fraction[k] - radial.void_fraction[k]));
        mean += std::abs(line.void_fraction[k] - radial.void_fraction[k]) / static_cast<double>(line.position.size());
      }
      out.csv_files[w.name + "_line.csv"] = csv;
      j[w.name]["line_intersection"] = {{"max_abs_difference_to_volume", worst}, {"mean_abs_difference_to_volume", mean}};
    }
  }
  const Profile axial = axial_void_fraction(whole, p.axial_bin_d * d, h);
  std::string csv = "# axial void fraction over the whole cross-section\nz_d,z_m,void_fraction\n";
  for (std::size_t k = 0; k < axial.position.size(); ++k)
    csv += fmt::format("{:.6g},{:.9g},{:.9g}\n", axial.position[k] / d, axial.position[k], axial.void_fraction[k]);
  out.csv_files["axial_profile.csv"] = csv;

  // Segregation of a mixture of a few sizes: per-species axial profiles and an index.
  const double d_max = *std::max_element(bed.diameters.begin(), bed.diameters.end());
  const Segregation seg = axial_segregation(whole, d_max, h);
  if (!seg.diameters.empty()) {
    csv = "# solid volume fraction of each species per layer of one largest diameter\nz_d,z_m";
    for (double ds : seg.diameters) csv += fmt::format(",species_d_{:.6g}_m", ds);
    csv += "\n";
    for (std::size_t k = 0; k < seg.z.size(); ++k) {
      csv += fmt::format("{:.6g},{:.9g}", seg.z[k] / d, seg.z[k]);
      for (const auto& f : seg.volume_fraction) csv += fmt::format(",{:.9g}", f[k]);
      csv += "\n";
    }
    out.csv_files["species_profile.csv"] = csv;
    j["segregation"] = {{"species_diameters_m", seg.diameters},
                        {"mean_height_m", seg.mean_height},
                        {"intensity", seg.intensity},
                        {"index", "Danckwerts (1952) intensity of segregation of the largest species over layers "
                                  "one largest diameter high: 0 mixed, 1 fully segregated"}};
  }

  // Contacts and balance.
  const ContactStatistics cs = contact_statistics(bed, p.contact_tolerance_d * sc.d_min);
  long pair_sum = 0, bulk_n = 0, bulk_sum = 0, bulk_rattlers = 0, rattlers = 0, non_rattler_sum = 0, wall = 0, floor = 0;
  const double cut = p.exclude_d * d;
  csv = "# contacts per sphere (gap tolerance " + fmt::format("{} smallest diameters", p.contact_tolerance_d) +
        ")\nindex,sphere_contacts,wall_contacts,floor_contact\n";
  for (std::size_t i = 0; i < bed.size(); ++i) {
    const bool rattler = is_rattler(cs, i);
    pair_sum += cs.sphere_contacts[i];
    rattlers += rattler;
    if (!rattler) non_rattler_sum += cs.sphere_contacts[i];
    wall += cs.wall_contacts[i] > 0;
    floor += cs.floor_contact[i];
    const auto& c = bed.centres[i];
    WallContact probe[Container::kMaxWallContacts];
    const bool near_wall = bed.container->wall_contacts(c, cut, probe) > 0;
    if (!near_wall && (periodic_axis || (c.z() > cut && c.z() < h - cut))) {
      if (rattler) ++bulk_rattlers;
      else ++bulk_n, bulk_sum += cs.sphere_contacts[i];
    }
    csv += fmt::format("{},{},{},{}\n", i, cs.sphere_contacts[i], cs.wall_contacts[i], int(cs.floor_contact[i]));
  }
  out.csv_files["contacts.csv"] = csv;
  const double n = static_cast<double>(bed.size());
  j["coordination"] = {
      {"mean_all", pair_sum / n},
      {"mean_without_rattlers", rattlers < static_cast<long>(bed.size()) ? non_rattler_sum / (n - rattlers) : 0.0},
      {"rattlers", rattlers},
      {"bulk_mean_without_rattlers", bulk_n ? nlohmann::json(static_cast<double>(bulk_sum) / bulk_n) : nlohmann::json()},
      {"bulk_spheres", bulk_n},
      {"bulk_rattlers", bulk_rattlers},
      {"rattler_definition", "fewer than 4 contacts with spheres, walls and floor"},
      {"gap_tolerance_d", p.contact_tolerance_d}};
  if (bulk_n == 0) j["coordination"]["bulk_mean_without_rattlers"] = nullptr;
  j["coordination"]["central_slab"] = nullptr;
  if (slab.valid) {
    const SlabCoordination sl = slab_coordination(bed, cs, slab.lo, slab.hi);
    j["coordination"]["central_slab"] = {
        {"spheres", sl.spheres}, {"mean_all", sl.mean_sphere_contacts}, {"rattlers", sl.rattlers}};
  }
  j["wall_contacts"] = {{"spheres_touching_lateral_wall", wall}, {"spheres_touching_floor", floor}};
  j["overlaps"] = {{"max_pair_overlap_d", cs.max_pair_overlap / sc.d_min},
                   {"max_wall_overlap_d", cs.max_wall_overlap / sc.d_min},
                   {"max_floor_penetration_d", cs.max_floor_penetration / sc.d_min}};
  j["force_residual"] = {{"rms", cs.residual_rms},
                         {"max", cs.residual_max},
                         {"definition", "net force / own weight at the best-fit linear contact stiffness"}};
  if (periodic_axis)
    j["force_residual"] = {{"rms", nullptr}, {"max", nullptr},
                           {"definition", "not measured: a periodic section is packed without gravity"}};
  const double time = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  j["time_s"] = time;
  const auto& vf = j["void_fraction"];
  out.summary = fmt::format(
      "analysis: eps whole {:.4f}, central slab {}, Z bulk {}, max overlap {:.2g} d, residual {:.2g}",
      vf["whole_bed"].get<double>(),
      vf["central_slab"].is_null() ? std::string("n/a") : fmt::format("{:.4f}", vf["central_slab"].get<double>()),
      j["coordination"]["bulk_mean_without_rattlers"].is_null()
          ? std::string("n/a")
          : fmt::format("{:.2f}", j["coordination"]["bulk_mean_without_rattlers"].get<double>()),
      cs.max_pair_overlap / sc.d_min, cs.residual_rms);
  j["summary"] = out.summary;
  return out;
}

}  // namespace bedforge::analysis
