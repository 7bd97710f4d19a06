#include "cases/case_params.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <functional>

#include "core/error.hpp"

namespace bedforge::cases {

CaseParams read_case_params(SceneSection& s) {
  CaseParams p;
  p.reynolds = s.number("reynolds", p.reynolds, Range{0.0, 1000.0, true, false});
  p.density_kg_m3 = s.number("density_kg_m3", p.density_kg_m3, Range::positive());
  p.viscosity_pa_s = s.number("viscosity_pa_s", p.viscosity_pa_s, Range::positive());
  p.iterations = static_cast<int>(s.integer("iterations", p.iterations, 1, 1'000'000));
  p.residual_p = s.optional_number("residual_p", Range::open(0.0, 1.0),
                                  fmt::format("{}; {} on a periodic section", kResidualP, kResidualPeriodic));
  p.residual_u = s.optional_number("residual_u", Range::open(0.0, 1.0),
                                  fmt::format("{}; {} on a periodic section; {} on cells with prism layers", kResidualU,
                                              kResidualPeriodic, kResidualULayered));
  p.iteration_tolerance = s.number("iteration_tolerance", p.iteration_tolerance, Range{0.0, 0.1, true, false});
  p.processors = static_cast<int>(s.integer("processors", p.processors, 1, 4096));
  p.decomposition = s.choice("decomposition", p.decomposition, {"hierarchical", "scotch"});
  p.binary = s.choice("format", "binary", {"binary", "ascii"}) == "binary";
  p.polyhedra = s.choice("cells", "polyhedra", {"polyhedra", "tetrahedra"}) == "polyhedra";
  p.snappy_cells = s.choice("mesher", "gmsh", {"gmsh", "snappy"}) == "snappy";
  p.snappy = s.boolean("snappy", p.snappy) || p.snappy_cells;
  p.snappy_cell_d = s.number("snappy_cell_d", p.snappy_cell_d, Range::closed(0.01, 10.0));
  p.snappy_level = static_cast<int>(s.integer("snappy_level", p.snappy_level, 0, 6));
  p.slip_walls = s.choice("walls", "no_slip", {"no_slip", "slip"}) == "slip";
  p.section_exclude_d = s.number("section_exclude_d", p.section_exclude_d, Range::non_negative());
  p.run = s.boolean("run", p.run);
  p.drag_by_gap_d = s.numbers("drag_by_gap_d", Range::positive());
  if (p.drag_by_gap_d.size() > kMostGapBands - 1 ||
      std::adjacent_find(p.drag_by_gap_d.begin(), p.drag_by_gap_d.end(), std::greater_equal<>()) !=
          p.drag_by_gap_d.end())
    throw InputError(fmt::format("case.drag_by_gap_d = [{}]: allowed: up to {} band edges, ascending (reference "
                                 "diameters)",
                                 fmt::join(p.drag_by_gap_d, ", "), kMostGapBands - 1));
  if (!p.drag_by_gap_d.empty() && p.snappy_cells)
    throw InputError("case.drag_by_gap_d with case.mesher = \"snappy\": the particles' patch is split on gmsh's "
                     "cells; allowed: case.mesher = \"gmsh\", or no case.drag_by_gap_d");
  SceneSection convergence = s.sub("convergence");
  // A solved case is studied by default: a pressure drop without its discretisation error is
  // half an answer (docs/defaults.md).
  const int study_levels = p.run && !p.snappy_cells ? kStudyLevels : 0;
  p.convergence.levels = static_cast<int>(convergence.integer(
      "levels", study_levels, 0, 6, fmt::format("{} when case.run = true on gmsh's cells, else 0", kStudyLevels)));
  p.convergence.ratio = convergence.number("ratio", p.convergence.ratio, Range::closed(1.1, 2.0));
  convergence.finish();
  if (p.convergence.levels == 1 || p.convergence.levels == 2)
    throw InputError(fmt::format("case.convergence.levels = {}: an order and an extrapolation need three meshes; "
                                 "allowed: 0 (no study) or 3 to 6",
                                 p.convergence.levels));
  if (p.convergence.levels > 0 && (!p.run || p.snappy_cells))
    throw InputError("case.convergence.levels > 0 needs the flow solved on gmsh's meshes; allowed: case.run = true "
                     "with case.mesher = \"gmsh\"");
  return p;
}

nlohmann::json to_json(const CaseParams& p) {
  return {{"reynolds", p.reynolds},         {"density_kg_m3", p.density_kg_m3},
          {"viscosity_pa_s", p.viscosity_pa_s}, {"iterations", p.iterations},
          {"residual_p", p.residual_p ? nlohmann::json(*p.residual_p) : nlohmann::json()},
          {"residual_u", p.residual_u ? nlohmann::json(*p.residual_u) : nlohmann::json()},
          {"iteration_tolerance", p.iteration_tolerance},
          {"processors", p.processors},     {"decomposition", p.decomposition},
          {"format", p.binary ? "binary" : "ascii"}, {"cells", p.polyhedra ? "polyhedra" : "tetrahedra"},
          {"snappy", p.snappy},             {"snappy_cell_d", p.snappy_cell_d},
          {"snappy_level", p.snappy_level}, {"section_exclude_d", p.section_exclude_d},
          {"walls", p.slip_walls ? "slip" : "no_slip"},
          {"run", p.run},                   {"mesher", p.snappy_cells ? "snappy" : "gmsh"},
          {"drag_by_gap_d", p.drag_by_gap_d},
          {"convergence", {{"levels", p.convergence.levels}, {"ratio", p.convergence.ratio}}}};
}

}  // namespace bedforge::cases
