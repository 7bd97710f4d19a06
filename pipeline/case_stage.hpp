#pragma once
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "cases/case_runner.hpp"
#include "core/bed.hpp"
#include "core/bed_io.hpp"
#include "meshing/volume/poly_mesh.hpp"
#include "meshing/surface/triangle_mesh.hpp"
#include "pipeline/console.hpp"

namespace bedforge::pipeline {

// The OpenFOAM case of a bed, and its flow when it was run.
struct CaseStage {
  cases::CaseInfo info;
  std::optional<cases::FlowResult> flow;  // with params.run
  nlohmann::json report;                  // stages.case, with "flow" and "summary"
};

// Writes the case of `bed` (m) into `case_dir` (replacing one only with `overwrite`), recording
// `scene_toml` and the bed, and runs it when params.run. `treated`: what the contact treatment did
// to the spheres (treated_solid in scene.hpp), so a known answer, a bound or a Stokes drag law for
// the bed applies to the spheres solved.
// On gmsh's cells `mesh`; or, when params.snappy_cells, with no cells (mesh null) for
// snappyHexMesh to make from `surface`, the fluid surface whose ASCII STL is `fluid_stl` (also
// needed, with params.snappy, beside gmsh's).
// Both are let go of once the case is written and the allocator's free pages handed back, so
// that OpenFOAM's processes get the memory they held (callers pass their only reference).
// A case in pieces (mesh.pieces > 1), made by ranks of their own (piece_stage.hpp): the domain's
// inlet and outlet heights (m), and `write`, which puts the pieces into the case just written and
// completes its info (cells, fluid volume, the section's void fraction as meshed).
struct CasePieces {
  int count = 0;
  double inlet_z = 0.0, outlet_z = 0.0;
  std::function<void(cases::CaseInfo&)> write;
};

// With `pieces` (mesh and surface null) the case is written without cells, then its pieces.
CaseStage case_stage(std::shared_ptr<const meshing::PolyMesh> mesh, std::shared_ptr<const meshing::TriangleMesh> surface,
                     const Bed& bed,
                     const cases::CaseParams& params, const Provenance& provenance, const std::string& scene_toml,
                     const std::filesystem::path& fluid_stl, const std::filesystem::path& case_dir, bool overwrite,
                     const cases::TreatedSolid& treated, const Console& console, const CasePieces* pieces = nullptr);

// Runs a case that case_stage wrote without running it (a convergence level in pieces, sized on
// its cells before it is solved): its flow into `written` (flow, report["flow"]) and a stage line
// of its own, whose time is the solve's.
void solve_case_stage(CaseStage& written, const Console& console);

}  // namespace bedforge::pipeline
