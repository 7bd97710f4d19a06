#include "pipeline/pack_stage.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "analysis/bed_analysis.hpp"
#include "analysis/contact_statistics.hpp"
#include "core/error.hpp"

namespace bedforge::pipeline {

namespace {

// A centre outside the container or below the floor means the file's frame or unit is not the
// one the scene gives; overlaps are for the surface stage to judge (it says which treatment can
// handle them).
nlohmann::json check_imported(const Bed& bed, const std::string& file) {
  const double d = sauter_mean(bed.diameters);
  for (std::size_t i = 0; i < bed.size(); ++i) {
    const double r = 0.5 * bed.diameters[i];
    WallContact walls[Container::kMaxWallContacts];
    const int nw = bed.container->wall_contacts(bed.centres[i], r, walls);
    double worst = 0.0;
    for (int k = 0; k < nw; ++k) worst = std::max(worst, walls[k].overlap);
    const auto& c = bed.centres[i];
    const bool below_floor = c.z() < 0.0 && bed.container->axial_period() == 0.0;  // a periodic axis has none
    if (worst > r || below_floor)
      throw InputError(fmt::format("{}: sphere {} (centre {:.6g}, {:.6g}, {:.6g} m) lies {} the {}; allowed: centres "
                                   "inside the container, above the floor at z = 0 (check packing.units, "
                                   "packing.origin_m and [container])",
                                   file, i + 1, c.x(), c.y(), c.z(), below_floor ? "below the floor of" : "outside",
                                   bed.container->kind()));
  }
  const analysis::ContactStatistics cs = analysis::contact_statistics(bed, 0.0);
  return {{"max_pair_overlap_d", cs.max_pair_overlap / d},
          {"max_wall_overlap_d", cs.max_wall_overlap / d},
          {"max_floor_penetration_d", cs.max_floor_penetration / d}};
}

}  // namespace

PackStage pack_stage(const Scene& scene, const Console& console) {
  const StageMeter meter;
  PackStage out;
  std::string line;
  if (scene.algorithm == "import") {
    const ImportedBed& imported = *scene.import.bed;
    out.bed = imported.bed;
    out.bed.container = scene.container;
    const auto& o = scene.import.origin_m;
    out.report = {{"algorithm", "import"},
                  {"file", scene.import.file.string()},
                  {"format", bed_file_format_name(scene.import.format)},
                  {"to_metres", scene.import.to_metres},
                  {"origin_m", {o.x(), o.y(), o.z()}},
                  {"header", imported.header}};
    const nlohmann::json overlaps = check_imported(out.bed, scene.import.file.string());
    out.report["overlaps"] = overlaps;
    line = fmt::format("import: {} spheres from {}, max overlap {:.2g} d (wall {:.2g} d)", out.bed.size(),
                       scene.import.file.string(), overlaps["max_pair_overlap_d"].get<double>(),
                       overlaps["max_wall_overlap_d"].get<double>());
  } else if (scene.count == 0) {
    out.bed.container = scene.container;
    out.bed.reference_diameter_m = scene.sizes.sauter_mean();
    out.report = {{"algorithm", "none: particles.count = 0, the empty container"}};
    line = "pack: no spheres (particles.count = 0): the empty container";
  } else {
    Progress progress("pack", console.progress);
    packer::PackResult r =
        scene.algorithm == "monte-carlo"
            ? packer::pack_monte_carlo(scene.monte_carlo, scene.sizes, *scene.container, scene.count, scene.seed, progress)
            : packer::pack_soft_sphere(scene.soft_sphere, scene.sizes, *scene.container, scene.count, scene.seed, progress);
    out.bed = std::move(r.bed);
    out.report = std::move(r.info);
    line = std::move(r.summary);
  }
  out.report["spheres"] = out.bed.size();
  out.report["container_m"] = out.bed.container->to_json();
  if (out.bed.size() > 0) {
    out.report["void_fraction"] = analysis::void_fraction_summary(out.bed, scene.analysis);
    const auto& vf = out.report["void_fraction"];
    line += fmt::format(", eps {:.4f} (central {})", vf["whole_bed"].get<double>(),
                        vf["central_slab"].is_null() ? std::string("n/a") : fmt::format("{:.4f}", vf["central_slab"].get<double>()));
  }
  finish_stage(out.report, meter, line, console);
  return out;
}

}  // namespace bedforge::pipeline
