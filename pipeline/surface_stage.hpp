#pragma once
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/bed.hpp"
#include "meshing/surface/fluid_surface.hpp"
#include "pipeline/console.hpp"
#include "pipeline/output_files.hpp"

namespace bedforge::pipeline {

// The fluid-domain surface of a bed and its report entry.
struct SurfaceStage {
  std::shared_ptr<const meshing::FluidSurface> surface;  // m; checked by CGAL and held to the angle gate
  nlohmann::json report;                                 // stages.surface, with "summary"
};

// Treats the contacts of `bed` and builds the checked fluid surface
// (meshing::build_checked_fluid_surface: a surface below the angle gate writes its triangles to
// `bad_triangles_path` and throws).
SurfaceStage surface_stage(const Bed& bed, const meshing::SurfaceParams& params,
                           const std::filesystem::path& bad_triangles_path, const Console& console);

// The surface's files, added to `files`: fluid.stl (a named solid per patch), fluid_PATCH.stl,
// bed.stl and fluid.vtp.
void add_surface_files(const std::shared_ptr<const meshing::FluidSurface>& surface, OutputFiles& files);

// The files add_surface_files always writes (the per-patch ones depend on the bed).
const std::vector<std::string>& surface_file_names();

}  // namespace bedforge::pipeline
