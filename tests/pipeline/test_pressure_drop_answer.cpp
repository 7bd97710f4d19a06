// The answer a run with a solved case gives, on studies whose values follow a known power law.
#include "pipeline/pressure_drop_answer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "analysis/pressure_drop.hpp"

using namespace bedforge;
using namespace bedforge::pipeline;

namespace {

const double kD = 0.003;  // m

Scene scene_with(const std::string& extra = "") {
  return read_scene(toml::parse("[container]\ndiameter_d = 5\n[particles]\ncount = 2\ndiameter_m = 0.003\n"
                                "[surface]\nedge_length_d = 0.15\ncontact_edge_length_d = 0.05\ncells_per_gap = 4\n"
                                "[case]\nrun = true\n" + extra),
                    "test");
}

// A case entry as run_scene records it: the section, the flow on the finest mesh and E&S.
nlohmann::json case_entry(double finest_pa_m, bool converged = true) {
  return {{"section", {{"z_low_m", 0.5 * kD}, {"z_high_m", 9.5 * kD}}},
          {"d_ref_m", kD},
          {"cells", 1000000},
          {"fluid_volume_m3", 1.0e-6},
          {"parameters", {{"reynolds", 1.0}}},
          {"flow",
           {{"pressure_gradient_bed_pa_m", finest_pa_m},
            {"converged", converged},
            {"time_s", 120.0},
            {"solver_peak_memory_mb", 4000.0},
            {"mesh", {{"cells", 1000000}}},
            {"eisfeld_schnitzlein_bed_pa_m", 32.0},
            {"void_fraction_section_bed", 0.44}}}};
}

// Three levels at h = h1 r^k (r = 1.3) whose values are phi0 + c (h / h1)^p, each taking its
// cells (1e6 / r^3k) in proportion in time.
ConvergenceStudy study_of(double phi0, double c, double p) {
  ConvergenceStudy s;
  const double h1 = 0.05 * kD;
  for (int k = 0; k < 3; ++k) {
    StudyLevel l;
    l.level = k + 1;
    l.cell_size_m = h1 * std::pow(1.3, k);
    l.pressure_gradient_pa_m = phi0 + c * std::pow(1.3, p * k);
    l.cells = std::lround(1e6 / std::pow(1.3, 3 * k));
    l.own_time_s = 100.0 * static_cast<double>(l.cells) / 1e6;
    l.converged = true;
    s.levels.push_back(l);
  }
  s.convergence = analysis::grid_convergence({{s.levels[0].cell_size_m, s.levels[0].pressure_gradient_pa_m},
                                              {s.levels[1].cell_size_m, s.levels[1].pressure_gradient_pa_m},
                                              {s.levels[2].cell_size_m, s.levels[2].pressure_gradient_pa_m}});
  s.complete = true;
  s.conclusion = "levels 1-3: " + s.convergence.explanation;
  return s;
}

bool has(const std::vector<std::string>& lines, const std::string& text) {
  for (const std::string& l : lines)
    if (l.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

// Values 30 - 10 (h / h1)^2: second order, the mesh-independent value 30. The band is the finest
// value 20 +- 1.25 x |30 - 20| (Roache's GCI with its 1.25), so [7.5, 32.5], and holds 30.
TEST(PressureDropAnswer, AStudyInTheAsymptoticRangeGivesTheExtrapolationAndTheFinestMeshsBand) {
  const ConvergenceStudy study = study_of(30.0, -10.0, 2.0);
  const auto a = pressure_drop_answer(scene_with(), case_entry(20.0), &study);
  ASSERT_TRUE(a.has_value());
  ASSERT_TRUE(a->best_pa_m.has_value());
  EXPECT_NEAR(*a->best_pa_m, 30.0, 1e-9);
  EXPECT_NEAR(a->order, 2.0, 1e-9);
  EXPECT_NEAR(*a->band_low_pa_m, 7.5, 1e-9);
  EXPECT_NEAR(*a->band_high_pa_m, 32.5, 1e-9);
  EXPECT_NEAR(a->gci_fine, 0.625, 1e-12);
  EXPECT_EQ(a->reference_name, "Eisfeld & Schnitzlein (2001)");
  EXPECT_DOUBLE_EQ(*a->reference_accuracy, analysis::kEisfeldSchnitzleinAccuracy);
  const std::vector<std::string> lines = a->lines();
  EXPECT_TRUE(has(lines, "best estimate: 30 Pa/m")) << lines[1];
  EXPECT_TRUE(has(lines, "band: 7.5 to 32.5 Pa/m")) << lines[2];
  EXPECT_TRUE(has(lines, "Eisfeld & Schnitzlein (2001): 32 Pa/m +- 20 %"));
  EXPECT_TRUE(has(lines, "0.4400"));  // the void fraction it was taken at
  EXPECT_TRUE(has(lines, "best estimate / reference: 0.938"));
  const nlohmann::json j = a->to_json();
  EXPECT_EQ(j["band_pa_m"], nlohmann::json({*a->band_low_pa_m, *a->band_high_pa_m}));
  EXPECT_EQ(j["lines"].size(), lines.size());
  EXPECT_FALSE(j.contains("advice"));
}

// Levels whose polyhedra fail checkMesh's limits are named beside the answer that rests on them;
// a study whose levels all pass says nothing of it.
TEST(PressureDropAnswer, LevelsWhosePolyhedraFailCheckMeshAreSaidBesideTheAnswer) {
  ConvergenceStudy study = study_of(30.0, -10.0, 2.0);
  EXPECT_FALSE(has(pressure_drop_answer(scene_with(), case_entry(20.0), &study)->lines(), "checkMesh"));
  study.levels[1].cells_failing_check_mesh = 58;
  study.levels[2].cells_failing_check_mesh = 695;
  const std::vector<std::string> lines = pressure_drop_answer(scene_with(), case_entry(20.0), &study)->lines();
  EXPECT_TRUE(has(lines, "checkMesh: polyhedra fail its limits on the meshes solved (level 2: 58, level 3: 695"));
  EXPECT_TRUE(has(lines, "best estimate: 30 Pa/m"));  // said, not refused
}

// Each level's iteration error is said beside the band, with the study of the three levels it
// rests on redone with those errors taken out. Lower residual targets are called for when that
// moves the best estimate by more than a tenth of the band's half-width (kIterationErrorShareOfBand
// of the GCI, 62.5 % here), or when one of those levels did not settle and moved by more than that
// over its last block of iterations; a level without an estimate (a report from before they were made) is left out.
TEST(PressureDropAnswer, IterationErrorsAreSaidAndLargeOnesCallForLowerResidualTargets) {
  auto estimate = [](double remaining) {
    analysis::IterationError e;
    e.geometric = true;
    e.remaining = remaining;
    return e;
  };
  auto unsettled = [](double last_change) {
    analysis::IterationError e;
    e.last_change = last_change;
    e.block = 10;
    return e;
  };
  auto lines_of = [](const nlohmann::json& entry, const ConvergenceStudy* study) {
    return pressure_drop_answer(scene_with(), entry, study)->lines();
  };
  nlohmann::json entry = case_entry(20.0);
  entry["parameters"]["residual_u"] = 1e-4;
  entry["parameters"]["residual_p"] = 1e-5;
  const std::string advice = "of the band's half-width (62 %); set case.residual_u and case.residual_p below the "
                             "0.0001 and 1e-05 solved to";
  // The same error on every level scales the values, and the extrapolation with them.
  ConvergenceStudy study = study_of(30.0, -10.0, 2.0);
  for (StudyLevel& l : study.levels) l.iteration = estimate(0.01);
  std::vector<std::string> lines = lines_of(entry, &study);
  EXPECT_TRUE(has(lines, "had it run on (by how its last changes shrank; Ferziger & Peric 2002, 5.7): level 1 +1 %, "
                         "level 2 +1 %, level 3 +1 %; taken out where estimated, the best estimate would be 30.3 Pa/m "
                         "(+1 %) at order 2.00"));
  EXPECT_FALSE(has(lines, advice));
  EXPECT_NEAR(pressure_drop_answer(scene_with(), entry, &study)->to_json()["without_iteration_error"]["extrapolated"]
                  .get<double>(),
              30.3, 1e-9);
  // +10 % on the finest, +1 % on the others: 22, 13.2, 1.45 extrapolate to 47.6 at order 1.12.
  study.levels[0].iteration = estimate(0.1);
  lines = lines_of(entry, &study);
  EXPECT_TRUE(has(lines, "level 1 +10 %"));
  EXPECT_TRUE(has(lines, "the best estimate would be 47.56 Pa/m (+59 %) at order 1.12"));
  EXPECT_TRUE(has(lines, "not small against the band: it moves the best estimate by more than 0.1 " + advice));
  // A level without an estimate: said of the others only, and no study redone.
  study.levels[0].iteration = estimate(0.01);
  study.levels[2].iteration.reset();
  lines = lines_of(entry, &study);
  EXPECT_FALSE(has(lines, "level 3"));
  EXPECT_FALSE(has(lines, "taken out"));
  EXPECT_FALSE(has(lines, advice));
  // A level whose changes did not shrink counts as solved; it calls for lower targets only when
  // its last block alone moved it by more than a tenth of the band's half-width.
  study.levels[2].iteration = unsettled(0.003);
  lines = lines_of(entry, &study);
  EXPECT_TRUE(has(lines, "level 3 not estimated (its changes did not shrink; dp/L moved +0.3 % over its last 10 "
                         "iterations); taken out where estimated, the best estimate would be"));
  EXPECT_FALSE(has(lines, advice));
  study.levels[2].iteration = unsettled(-0.07);
  lines = lines_of(entry, &study);
  EXPECT_TRUE(has(lines, "not small against the band: a level it rests on did not settle, and moved over its last "
                         "block of iterations by more than 0.1 " + advice));
  // One mesh: the flow's own estimate, and no band to hold it against.
  entry["flow"]["pressure_gradient_iteration_error"] = estimate(0.5).to_json();
  lines = lines_of(entry, nullptr);
  EXPECT_TRUE(has(lines, "level 1 +50 %"));
  EXPECT_FALSE(has(lines, "not small against the band"));
}

// Order 0.23 (the first study of the default bed at 0.1 d): outside 1-3, so no estimate and no
// band; the advice refines every length by the ratio and costs it from the levels: cells x 1.3^3,
// time in proportion to the cells (as the levels were made), the whole study the new finest plus
// today's two finest levels, the solver's peak x 1.3^3.
TEST(PressureDropAnswer, AStudyOutsideTheAsymptoticRangeGivesNoEstimateButWhatToRefineAndItsCost) {
  const ConvergenceStudy study = study_of(80.0, -60.0, 0.23);
  ASSERT_FALSE(study.convergence.asymptotic);
  const auto a = pressure_drop_answer(scene_with(), case_entry(20.0), &study);
  ASSERT_TRUE(a.has_value());
  EXPECT_FALSE(a->best_pa_m.has_value());
  EXPECT_FALSE(a->band_low_pa_m.has_value());
  EXPECT_NE(a->why_no_estimate.find("asymptotic range"), std::string::npos) << a->why_no_estimate;
  const double r3 = std::pow(1.3, 3);
  const FinerStudyCost cost = finer_study_cost(study, 1.3, 4000.0);
  EXPECT_NEAR(cost.cells, 1e6 * r3, 1.0);
  // (The levels' cells are whole numbers, so their times are in proportion to 1e-6.)
  EXPECT_NEAR(cost.finest_time_s, 100.0 * r3, 1e-4);
  EXPECT_NEAR(cost.study_time_s, cost.finest_time_s + study.levels[0].own_time_s + study.levels[1].own_time_s, 1e-9);
  EXPECT_NEAR(cost.peak_memory_mb, 4000.0 * r3, 1e-6);
  EXPECT_NE(a->advice.find("surface.edge_length_d = 0.115"), std::string::npos) << a->advice;
  EXPECT_NE(a->advice.find("surface.cells_per_gap = 5.2"), std::string::npos) << a->advice;
  EXPECT_NE(a->advice.find("2.2e+06 cells"), std::string::npos) << a->advice;
  const std::vector<std::string> lines = a->lines();
  EXPECT_FALSE(has(lines, "best estimate:"));
  EXPECT_TRUE(has(lines, "no error band, so no best estimate"));
  EXPECT_TRUE(has(lines, "finest mesh: 20 Pa/m"));
}

TEST(PressureDropAnswer, OneMeshGivesNoBandAndSaysHowToGetOne) {
  const auto a = pressure_drop_answer(scene_with(), case_entry(20.0), nullptr);
  ASSERT_TRUE(a.has_value());
  EXPECT_FALSE(a->best_pa_m.has_value());
  EXPECT_NE(a->advice.find("levels = 3"), std::string::npos) << a->advice;
  EXPECT_EQ(a->levels.size(), 1u);
}

TEST(PressureDropAnswer, AFinestMeshTheSolverDidNotConvergeOnGivesNoEstimate) {
  const ConvergenceStudy study = study_of(30.0, -10.0, 2.0);
  const auto a = pressure_drop_answer(scene_with(), case_entry(20.0, false), &study);
  ASSERT_TRUE(a.has_value());
  EXPECT_FALSE(a->best_pa_m.has_value());
  EXPECT_TRUE(has(a->lines(), "NOT converged"));
}

TEST(PressureDropAnswer, AnUnsolvedCaseHasNoAnswer) {
  nlohmann::json entry = case_entry(20.0);
  entry.erase("flow");
  EXPECT_FALSE(pressure_drop_answer(scene_with(), entry, nullptr).has_value());
}

// The picture holds each level, the fitted curve and the band with the estimate, and the
// reference's line; without an estimate, neither curve nor band.
TEST(PressureDropAnswer, ThePictureDrawsTheLevelsTheFitTheBandAndTheReference) {
  auto count = [](const std::string& s, const std::string& what) {
    int n = 0;
    for (std::size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
    return n;
  };
  const ConvergenceStudy good = study_of(30.0, -10.0, 2.0), bad = study_of(80.0, -60.0, 0.23);
  const std::string with = answer_svg(*pressure_drop_answer(scene_with(), case_entry(20.0), &good));
  const std::string without = answer_svg(*pressure_drop_answer(scene_with(), case_entry(20.0), &bad));
  EXPECT_EQ(with.rfind("<svg", 0), 0u);
  EXPECT_EQ(count(with, "<circle"), 3 + 1);  // the levels and the legend's mark
  EXPECT_EQ(count(with, "<polyline"), 1);
  EXPECT_NE(with.find("band 7.5 to 32.5 Pa/m"), std::string::npos);
  EXPECT_NE(with.find("Eisfeld &amp; Schnitzlein"), std::string::npos);
  EXPECT_EQ(count(without, "<polyline"), 0);
  EXPECT_NE(without.find("no best estimate"), std::string::npos);
}

// snappyHexMesh's cells have no size known beforehand and a single solve has one value: the
// picture still has finite axes (a zero range once made its tick loop run without end).
TEST(PressureDropAnswer, APictureWithoutACellSizeHasFiniteAxes) {
  nlohmann::json entry = case_entry(32.0);
  entry["fluid_volume_m3"] = nullptr;
  const auto a = pressure_drop_answer(scene_with(), entry, nullptr);
  ASSERT_TRUE(a.has_value());
  EXPECT_TRUE(a->levels.empty());
  const std::string svg = answer_svg(*a);
  EXPECT_LT(svg.size(), 20000u);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
}

// A random array's case carries van der Hoef et al.'s drag beside the reference: said with its
// solid fraction, and the best estimate over it (30 / 25 = 1.2); a case without one says nothing.
TEST(PressureDropAnswer, ARandomArraysStokesDragIsSaidBesideTheReference) {
  const ConvergenceStudy study = study_of(30.0, -10.0, 2.0);
  nlohmann::json entry = case_entry(20.0);
  entry["stokes_array"] = {{"solid_fraction", 0.389}, {"diameter_m", 0.00297}, {"van_der_hoef_pa_m", 25.0}};
  const auto a = pressure_drop_answer(scene_with(), entry, &study);
  ASSERT_TRUE(a.has_value());
  const std::vector<std::string> lines = a->lines();
  EXPECT_TRUE(has(lines, "van der Hoef, Beetstra & Kuipers (2005), Stokes drag of random arrays: 25 Pa/m"));
  EXPECT_TRUE(has(lines, "0.3890"));
  EXPECT_TRUE(has(lines, "best estimate / it: 1.200"));
  EXPECT_EQ(a->to_json()["stokes_array"]["pa_m"].get<double>(), 25.0);
  const auto plain = pressure_drop_answer(scene_with(), case_entry(20.0), &study);
  EXPECT_FALSE(has(plain->lines(), "van der Hoef"));
  EXPECT_FALSE(plain->to_json().contains("stokes_array"));
  // A random array of unequal spheres is left without it, and the answer says why.
  nlohmann::json unequal = case_entry(20.0);
  unequal["stokes_array_not_compared"] = "their fit is for equal spheres, and this bed's differ in size";
  EXPECT_TRUE(has(pressure_drop_answer(scene_with(), unequal, &study)->lines(),
                  "Stokes drag of random arrays: not compared, their fit is for equal spheres"));
}

// Past the steady regime of packed beds (Dybbs & Edwards 1984) the steady answer says what it is;
// at Re_p = 100, inside it, nothing is added.
TEST(PressureDropAnswer, AReynoldsNumberPastSteadyFlowIsSaidBesideTheAnswer) {
  const ConvergenceStudy study = study_of(30.0, -10.0, 2.0);
  for (const double re : {100.0, 1000.0}) {
    nlohmann::json entry = case_entry(20.0);
    entry["parameters"]["reynolds"] = re;
    const auto a = pressure_drop_answer(scene_with(), entry, &study);
    ASSERT_TRUE(a.has_value());
    EXPECT_EQ(has(a->lines(), "Dybbs & Edwards"), re > kUnsteadyFlowReynolds) << "Re_p " << re;
  }
}

// A treated simple cubic column's reference is its untreated array's answer, said as a bound; a
// band wholly on the wrong side of it is said to be too narrow. Values 30 - 10 (h / h1)^2 give the
// band [7.5, 32.5] (as above): a bound from below at 25 lies inside it, one at 33 above it all.
TEST(PressureDropAnswer, ATreatedArraysBoundIsTheReferenceAndABandPastItIsSaid) {
  const ConvergenceStudy study = study_of(30.0, -10.0, 2.0);
  auto with_bound = [](double pa_m, const std::string& side) {
    nlohmann::json entry = case_entry(20.0);
    entry["flow"]["bound"] = cases::KnownBound{pa_m, side == "below"}.to_json();
    return entry;
  };
  const auto inside = pressure_drop_answer(scene_with(), with_bound(25.0, "below"), &study);
  ASSERT_TRUE(inside.has_value());
  ASSERT_TRUE(inside->reference_bound.has_value());
  EXPECT_TRUE(inside->reference_bound->from_below);
  EXPECT_DOUBLE_EQ(inside->reference_pa_m, 25.0);
  EXPECT_TRUE(has(inside->lines(), "the simple cubic array untreated: 25 Pa/m, a bound from below"));
  EXPECT_TRUE(has(inside->lines(), "best estimate / reference: 1.200"));
  EXPECT_FALSE(has(inside->lines(), "band is too narrow"));
  EXPECT_EQ(inside->to_json()["reference"]["bound"], "below");
  const auto past = pressure_drop_answer(scene_with(), with_bound(33.0, "below"), &study);
  EXPECT_TRUE(has(past->lines(), "the whole band lies below the bound")) << past->lines().back();
  // From above (a treatment that takes solid): the same band wholly above 7 is past it.
  EXPECT_TRUE(has(pressure_drop_answer(scene_with(), with_bound(7.0, "above"), &study)->lines(),
                  "the whole band lies above the bound"));
  EXPECT_FALSE(has(pressure_drop_answer(scene_with(), with_bound(31.0, "above"), &study)->lines(),
                   "the whole band lies"));
}
