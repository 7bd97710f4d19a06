#include "pipeline/surface_stage.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "core/version.hpp"
#include "meshing/surface/stl_io.hpp"
#include "meshing/surface/vtp_io.hpp"

namespace bedforge::pipeline {

SurfaceStage surface_stage(const Bed& bed, const meshing::SurfaceParams& p, const std::filesystem::path& bad_triangles_path,
                           const Console& console) {
  const StageMeter meter;
  auto built = std::make_shared<meshing::FluidSurface>(meshing::build_checked_fluid_surface(bed, p, bad_triangles_path));
  nlohmann::json& j = built->report;
  const meshing::SurfaceCheck& check = built->check;
  std::string line = fmt::format(
      "surface ({}, {} contacts treated): {} triangles, closed, {}, volume error {:.2e}, chordal deviation {:.2e} d, "
      "min angle {:.1f} deg, smallest gap {:.3g} d",
      meshing::treatment_name(p.treatment),
      j["contacts_treated"]["particle_particle"].get<long>() + j["contacts_treated"]["particle_wall"].get<long>(),
      built->fluid.triangles.size(),
      check.self_intersection_test != meshing::SelfIntersectionTest::skip ? "no self-intersection" : "self-intersections not checked",
      (check.volume - built->exact_volume_m3) / built->exact_volume_m3, j["chordal_deviation_d"].get<double>(),
      j["min_angle_deg"].get<double>(),
      std::min(j["smallest_gap_d"]["particle_particle"].get<double>(),
               j["smallest_gap_d"].value("particle_wall", std::numeric_limits<double>::infinity())));
  if (j.contains("clip")) {
    line += fmt::format(", clipped at {:.3f}-{:.3f} d", j["clip"]["inlet"]["used_d"].get<double>(),
                        j["clip"]["outlet"]["used_d"].get<double>());
    const long opened = j["clip"]["inlet"]["contacts_opened"].get<long>() + j["clip"]["outlet"]["contacts_opened"].get<long>();
    if (opened > 0) line += fmt::format(" ({} contacts opened there)", opened);
  }
  if (j.contains("periodic_planes_m"))
    if (const long opened = j["periodic_planes_m"]["contacts_opened"].get<long>(); opened > 0)
      line += fmt::format(", {} contacts opened where the periodic planes cross them", opened);
  SurfaceStage out{built, std::move(j)};  // the entry lives in the stage result, not twice
  finish_stage(out.report, meter, line, console);
  return out;
}

void add_surface_files(const std::shared_ptr<const meshing::FluidSurface>& built, OutputFiles& files) {
  const std::string version = kVersion;
  files.add_writer("fluid.stl", [built](std::ostream& out) { meshing::write_stl_ascii_by_patch(out, built->fluid); });
  for (std::size_t k = 0; k < built->fluid.patches.size(); ++k)
    files.add_writer("fluid_" + built->fluid.patches[k] + ".stl", [built, k, version](std::ostream& out) {
      meshing::write_stl_binary(out, built->fluid, static_cast<int>(k), "bedforge " + version + " " + built->fluid.patches[k]);
    });
  files.add_writer("bed.stl", [built, version](std::ostream& out) {
    meshing::write_stl_binary(out, built->bed, -1, "bedforge " + version + " bed solid");
  });
  files.add_writer("fluid.vtp", [built, version](std::ostream& out) {
    meshing::write_vtp(out, built->fluid, "bedforge " + version + " fluid-domain surface, lengths in m");
  });
}

const std::vector<std::string>& surface_file_names() {
  static const std::vector<std::string> names{"fluid.stl", "bed.stl", "fluid.vtp"};
  return names;
}

}  // namespace bedforge::pipeline
