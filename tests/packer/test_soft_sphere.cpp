// Stability, extreme geometries, reproducibility and a small validation of the soft-sphere
// packer against Salvat et al. (2005).
#include "packer/soft_sphere.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>

#include "analysis/bed_analysis.hpp"
#include "analysis/contact_statistics.hpp"
#include "core/error.hpp"
#include "core/parallel.hpp"

using namespace bedforge;
using packer::SoftSphereParams;

namespace {

SizeDistribution equal_spheres(double d = 1.0) {
  SizeDistribution s;
  s.diameters_m = {d};
  s.number_fractions = {1.0};
  return s;
}

SoftSphereParams mode(SoftSphereParams::Mode m) {
  SoftSphereParams p;
  p.mode = m;
  return p;
}

packer::PackResult pack(double a, long n, std::uint64_t seed, const SoftSphereParams& p,
                        const SizeDistribution& sizes = equal_spheres()) {
  Progress quiet("test", false);
  return packer::pack_soft_sphere(p, sizes, Cylinder(0.5 * a * sizes.sauter_mean()), n, seed, quiet);
}

// A tube of a = 5 (unit spheres) periodic along its axis every `period`, holding `count` spheres.
packer::PackResult pack_section(double period, long count, std::uint64_t seed, const SoftSphereParams& p = {}) {
  Progress quiet("test", false);
  Cylinder tube(2.5);
  tube.set_axial_period(period);
  return packer::pack_soft_sphere(p, equal_spheres(), tube, count, seed, quiet);
}

// Every promise a packed bed makes: finite, inside the wall and above the floor, overlaps below
// the tolerance (relative to the smallest diameter), checked independently of the packer.
void expect_valid(const packer::PackResult& r, double tol_d = 1e-4) {
  const Bed& b = r.bed;
  const double d_min = *std::min_element(b.diameters.begin(), b.diameters.end());
  const Periodicity per = b.container->periodicity();
  for (size_t i = 0; i < b.size(); ++i) {
    const auto& c = b.centres[i];
    const double ri = 0.5 * b.diameters[i];
    ASSERT_TRUE(c.allFinite()) << "sphere " << i;
    WallContact w[Container::kMaxWallContacts];
    const int nw = b.container->wall_contacts(c, ri, w);
    for (int k = 0; k < nw; ++k) EXPECT_LE(w[k].overlap, tol_d * d_min) << "sphere " << i << " crosses a wall";
    if (per.lz == 0.0) {  // a periodic axis has no floor
      EXPECT_GE(c.z() - ri, -tol_d * d_min) << "sphere " << i << " below the floor";
    }
    for (size_t j = i + 1; j < b.size(); ++j) {
      const double overlap = 0.5 * (b.diameters[i] + b.diameters[j]) - per.separation(c, b.centres[j]).norm();
      EXPECT_LT(overlap, tol_d * d_min) << "spheres " << i << " and " << j;
    }
  }
}

double central_void_fraction(const Bed& b) {
  return analysis::void_fraction_summary(b, analysis::AnalysisParams{})["central_slab"].get<double>();
}

class BothModes : public ::testing::TestWithParam<SoftSphereParams::Mode> {};
INSTANTIATE_TEST_SUITE_P(Packer, BothModes,
                         ::testing::Values(SoftSphereParams::Mode::accelerated, SoftSphereParams::Mode::faithful),
                         [](const auto& info) {
                           return info.param == SoftSphereParams::Mode::faithful ? "faithful" : "accelerated";
                         });

}  // namespace

TEST_P(BothModes, OneSphereRestsOnTheFloor) {
  const auto r = pack(3.0, 1, 1, mode(GetParam()));
  ASSERT_EQ(r.bed.size(), 1u);
  EXPECT_NEAR(r.bed.centres[0].z(), 0.5, 1e-12);
  expect_valid(r);
}

TEST_P(BothModes, SingleFileColumnStacksSpheresOnTheAxis) {
  // a = 1 exactly: the only packing is a vertical stack, centres at (k + 1/2) d.
  const auto r = pack(1.0, 6, 3, mode(GetParam()));
  std::vector<double> z;
  for (const auto& c : r.bed.centres) {
    EXPECT_LT(std::hypot(c.x(), c.y()), 1e-4);
    z.push_back(c.z());
  }
  std::sort(z.begin(), z.end());
  for (size_t k = 0; k < z.size(); ++k) EXPECT_NEAR(z[k], k + 0.5, (k + 1) * 1e-4) << "sphere " << k;
  expect_valid(r);
}

TEST_P(BothModes, TwoSpheresInANarrowTube) {
  // a = 1.5: the upper sphere leans on the lower one and the wall, centres 0.5 d off-axis
  // in opposite directions, height difference sqrt(1 - 0.5^2) d.
  const auto r = pack(1.5, 2, 2, mode(GetParam()));
  expect_valid(r);
  const auto& p = r.bed.centres;
  const auto& lo = p[0].z() < p[1].z() ? p[0] : p[1];
  const auto& hi = p[0].z() < p[1].z() ? p[1] : p[0];
  EXPECT_NEAR(lo.z(), 0.5, 1e-9);
  EXPECT_NEAR(hi.z() - lo.z(), std::sqrt(0.75), 2e-4);
  EXPECT_NEAR(std::hypot(hi.x() - lo.x(), hi.y() - lo.y()), 0.5, 2e-4);
}

TEST_P(BothModes, AnnulusAndPeriodicBox) {
  // The containers of the Monte Carlo issue: a narrow annulus (gap 2.5 d) and a box periodic
  // on both sides, where pairs act across the sides.
  Progress quiet("test", false);
  SoftSphereParams p = mode(GetParam());
  const auto ann = packer::pack_soft_sphere(p, equal_spheres(), Annulus(4.0, 1.5), 150, 2, quiet);
  expect_valid(ann);
  const auto box = packer::pack_soft_sphere(p, equal_spheres(), Box(4.0, 4.0, true, true), 150, 2, quiet);
  expect_valid(box);
  int across = 0;  // pairs in contact only through a periodic side
  const Periodicity per = box.bed.container->periodicity();
  for (size_t i = 0; i < box.bed.size(); ++i)
    for (size_t j = i + 1; j < box.bed.size(); ++j)
      across += (box.bed.centres[i] - box.bed.centres[j]).norm() > 1.01 &&
                per.separation(box.bed.centres[i], box.bed.centres[j]).norm() < 1.0001;
  EXPECT_GT(across, 5);
}

TEST(SoftSphere, PeriodicSectionOfATube) {
  // A tube periodic along its axis (a = 5, period 5 d, 102 spheres: void fraction 0.456, which
  // seeds 1-6 all reach; at 0.443 a section this short can jam first, docs/findings.md): no
  // floor, and pairs act across the period.
  const auto r = pack_section(5.0, 102, 3);
  expect_valid(r);
  const Periodicity per = r.bed.container->periodicity();
  ASSERT_EQ(per.lz, 5.0);
  int across = 0;  // pairs in contact only through the period
  for (size_t i = 0; i < r.bed.size(); ++i) {
    EXPECT_GE(r.bed.centres[i].z(), 0.0);  // stored in one period, [0, H)
    EXPECT_LT(r.bed.centres[i].z(), 5.0);
    for (size_t j = i + 1; j < r.bed.size(); ++j)
      across += (r.bed.centres[i] - r.bed.centres[j]).norm() > 1.01 &&
                per.separation(r.bed.centres[i], r.bed.centres[j]).norm() < 1.0001;
  }
  EXPECT_GT(across, 5);
  // The same seed gives the same section.
  const auto again = pack_section(5.0, 102, 3);
  EXPECT_EQ(again.bed.centres, r.bed.centres);
}

TEST(SoftSphere, PeriodicSectionThatJamsFirstIsTapped) {
  // a = 5, period 10 d, 212 spheres (void fraction 0.435, that of full a = 5 beds' central
  // slab): with seed 2 the compression jams first (it stopped there before taps existed,
  // docs/findings.md); tapped, it reaches the period with every overlap within the tolerance.
  const auto r = pack_section(10.0, 212, 2);
  expect_valid(r);
  EXPECT_GE(r.info["recoveries"].size(), 1u);
  EXPECT_EQ(r.bed.container->axial_period(), 10.0);
}

TEST(SoftSphere, ASliceAtTheFullBedsVoidFractionIsReachedByItsTaps) {
  // a = 5, 105 spheres at the full a = 5 beds' central void fraction (0.4341, a period of
  // 4.95 d): with taps of 0.1 d seeds 2 and 3 jammed at 0.4414 and 0.4369 (6 of seeds 1-9 did);
  // with taps of 0.3 d all nine reach it (docs/findings.md, 2026-12-01).
  SoftSphereParams p;
  p.target_void_fraction = 0.434059;
  for (std::uint64_t seed : {2, 3}) {
    Progress quiet("test", false);
    const auto r = packer::pack_soft_sphere(p, equal_spheres(), Cylinder(2.5), 105, seed, quiet);
    expect_valid(r);
    EXPECT_NEAR(r.bed.container->axial_period(), 105.0 / 6.0 / ((1.0 - 0.434059) * 6.25), 1e-9) << "seed " << seed;
  }
}

TEST(SoftSphere, ATargetBeyondTheJamNamesTheVoidFractionItJammedAt) {
  // a = 4 at 0.40, looser than a tube this narrow packs (full beds' central slab: 0.44): the
  // error names the void fraction to raise the target to, above the one asked for.
  SoftSphereParams p;
  p.target_void_fraction = 0.40;
  p.max_recoveries = 2;
  Progress quiet("test", false);
  try {
    packer::pack_soft_sphere(p, equal_spheres(), Cylinder(2.0), 150, 1, quiet);
    ADD_FAILURE() << "a = 4 was packed to 0.40";
  } catch (const ConvergenceError& e) {
    const std::string m = e.what();
    const auto at = m.find("void fraction "), above = m.find("target_void_fraction above ");
    ASSERT_NE(at, std::string::npos) << m;
    ASSERT_NE(above, std::string::npos) << m;
    const double jammed = std::stod(m.substr(at + 14)), advised = std::stod(m.substr(above + 27));
    EXPECT_GT(jammed, 0.40) << m;
    EXPECT_NEAR(advised, jammed, 1e-4) << m;
  }
}

TEST(SoftSphere, PeriodicSectionThatCannotHoldItsSpheres) {
  // 0.70 solid in the period, beyond random close packing: the packer says so instead of
  // returning overlapping spheres (the scene reader refuses it earlier, for equal spheres).
  SoftSphereParams p;
  p.max_iterations = 400'000;
  try {
    pack_section(4.0, 105, 1, p);
    ADD_FAILURE() << "a period 0.70 full was packed";
  } catch (const ConvergenceError& e) {
    SUCCEED() << e.what();
  }
}

TEST(SoftSphere, ZigZagColumnAndAWideShallowBed) {
  expect_valid(pack(1.5, 30, 1, SoftSphereParams{}));
  const auto wide = pack(50.0, 400, 1, SoftSphereParams{});
  expect_valid(wide);
  // 400 spheres cover a 50 d wide floor in less than one layer: nothing may stay stacked high.
  double top = 0;
  for (const auto& c : wide.bed.centres) top = std::max(top, c.z());
  EXPECT_LT(top, 1.5);
}

TEST(SoftSphere, ExtremeInitialVoidFractions) {
  for (double eps0 : {0.30, 0.60}) {
    SoftSphereParams p;
    p.initial_void_fraction = eps0;
    expect_valid(pack(5.0, 200, 4, p));
  }
}

TEST(SoftSphere, WideMixtureDiameterRatioFive) {
  SizeDistribution s;
  s.kind = SizeDistribution::Kind::discrete;
  s.diameters_m = {0.001, 0.005};
  s.number_fractions = {0.9, 0.1};
  const auto r = pack(6.0, 400, 5, SoftSphereParams{}, s);
  expect_valid(r);  // tolerance relative to the small spheres
}

TEST(SoftSphere, StepBeyondTheStabilityLimitIsDetectedAndRecovered) {
  // C_k = 1 makes Eq. (4) oscillate without converging; the packer must notice, halve the step
  // and still deliver a valid bed, and say so in the report.
  SoftSphereParams p = mode(SoftSphereParams::Mode::faithful);
  p.stiffness_step = 1.0;
  const auto r = pack(3.0, 40, 1, p);
  expect_valid(r);
  ASSERT_FALSE(r.info["recoveries"].empty());
  EXPECT_LT(r.info["end_state"]["C_k"].get<double>(), 1.0);
}

TEST(SoftSphere, AbsurdStepEndsInAClearErrorFaithfulAndAValidBedAccelerated) {
  // Faithful: C_k is the published parameter, so the packer halves it after each detected
  // divergence and, at 500 (over 1000 times the published 0.3), gives up with a message naming
  // it; the packer is deterministic, so this seed always takes that branch. Accelerated: the
  // step is held below the measured stability limit, so the bed must come out valid.
  SoftSphereParams faithful = mode(SoftSphereParams::Mode::faithful);
  faithful.stiffness_step = 500.0;
  try {
    pack(3.0, 40, 1, faithful);
    ADD_FAILURE() << "the faithful packer accepted C_k = 500";
  } catch (const ConvergenceError& e) {
    EXPECT_NE(std::string(e.what()).find("stiffness_step"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("diverged"), std::string::npos) << e.what();
  }
  SoftSphereParams accelerated;
  accelerated.stiffness_step = 500.0;
  const auto r = pack(3.0, 40, 1, accelerated);
  expect_valid(r);
  EXPECT_LT(r.info["end_state"]["smallest_C_k"].get<double>(), 1.0);
}

TEST(SoftSphere, IterationCapStopsWithAMessage) {
  SoftSphereParams p;
  p.max_iterations = 500;
  try {
    pack(5.0, 200, 1, p);
    FAIL() << "no error at the iteration cap";
  } catch (const ConvergenceError& e) {
    EXPECT_NE(std::string(e.what()).find("max_iterations = 500"), std::string::npos) << e.what();
  }
}

// Above bedforge::kParallelMinItems, so that the particle loops do run on two threads (the
// packer may also change its thread count mid-run, core/thread_governor.hpp).
TEST(SoftSphere, SameSeedSameBedWhateverTheThreadCount) {
  constexpr long kSpheres = 600;
  static_assert(kSpheres >= static_cast<long>(bedforge::kParallelMinItems));
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const auto one = pack(5.0, kSpheres, 9, SoftSphereParams{});
  omp_set_num_threads(std::max(2, threads));
  const auto two = pack(5.0, kSpheres, 9, SoftSphereParams{});
  omp_set_num_threads(threads);
  ASSERT_EQ(one.bed.size(), two.bed.size());
  for (size_t i = 0; i < one.bed.size(); ++i) ASSERT_EQ(one.bed.centres[i], two.bed.centres[i]) << "sphere " << i;
  const auto other = pack(5.0, kSpheres, 10, SoftSphereParams{});
  EXPECT_NE(other.bed.centres[0], one.bed.centres[0]);
}

TEST(SoftSphere, FinalMomentumBoundChangesHowTheBedSettlesNotTheBed) {
  // The bound acts in the final stage only, after compaction has fixed the structure: beds made
  // with and without it keep the same void fraction (on the paper's case over 10 seeds they
  // differed by at most 0.0006, docs/validation.md), and both end in force balance.
  SoftSphereParams unbounded;
  unbounded.final_momentum_bound = 0.0;
  for (std::uint64_t seed : {3, 4}) {
    const auto with = pack(5.0, 300, seed, SoftSphereParams{});
    const auto without = pack(5.0, 300, seed, unbounded);
    expect_valid(with);
    expect_valid(without);
    EXPECT_NEAR(central_void_fraction(with.bed), central_void_fraction(without.bed), 0.002) << "seed " << seed;
    EXPECT_LT(with.info["force_residual_rms"].get<double>(), 0.3) << "seed " << seed;
  }
}

TEST(SoftSphere, UnitsDoNotChangeTheBedInDiameters) {
  const auto small = pack(4.0, 120, 2, SoftSphereParams{}, equal_spheres(1e-6));
  const auto large = pack(4.0, 120, 2, SoftSphereParams{}, equal_spheres(1.0));
  for (size_t i = 0; i < small.bed.size(); ++i)
    EXPECT_NEAR((small.bed.centres[i] / 1e-6 - large.bed.centres[i]).norm(), 0.0, 1e-9);
}

// Validation, small version of tools/validate_packer.py: a = 5, N = 500, eps_0 = 0.47.
// Salvat et al. (2005) report eps_F = 0.433 (Sec. 5, Fig. 1), and eps_F in [0.43, 0.44] for
// eps_0 in [0.30, 0.55] (Sec. 4.1). Our faithful runs over 10 seeds spread by about +-0.006
// (docs/validation.md), so single runs are held to 0.433 +- 0.015.
TEST(SoftSphereValidation, FaithfulReproducesSalvatAtAspectRatioFive) {
  const auto r = pack(5.0, 500, 1, mode(SoftSphereParams::Mode::faithful));
  expect_valid(r);
  EXPECT_NEAR(central_void_fraction(r.bed), 0.433, 0.015);
  // The published schedule needs a few 1e5 iterations whatever N is.
  EXPECT_GT(r.info["iterations"].get<long>(), 100000);
}

TEST(SoftSphereValidation, AcceleratedMatchesSalvatAtAspectRatioFive) {
  double mean = 0;
  for (std::uint64_t seed : {1, 2, 3}) {
    const auto r = pack(5.0, 500, seed, SoftSphereParams{});
    expect_valid(r);
    mean += central_void_fraction(r.bed) / 3;
  }
  EXPECT_NEAR(mean, 0.433, 0.01);
}

// Contact structure, accelerated against faithful (issue 25 item 3). At the default force
// tolerance (0.2 rms of the own weight) the accelerated mode stops while the last spheres are
// still settling onto their supports, which leaves more rattlers and fewer contacts
// (docs/validation.md, "Contacts"). With the stopping test at 0.1 the central slab's contacts
// per sphere and its rattlers must agree with the faithful mode's within twice the standard
// error of the difference, taken from the six seeds' own spread. Contacts are gaps below
// 1e-3 d, as in the DEM comparison of the issue.
TEST(SoftSphereValidation, AcceleratedContactsMatchFaithfulWithTheTighterStoppingTest) {
  struct Spread {
    double mean = 0, se2 = 0;  // mean and squared standard error over seeds
  };
  auto spread = [](const std::vector<double>& v) {
    Spread s;
    for (double x : v) s.mean += x / static_cast<double>(v.size());
    for (double x : v) s.se2 += (x - s.mean) * (x - s.mean) / static_cast<double>((v.size() - 1) * v.size());
    return s;
  };
  auto measure = [&](const SoftSphereParams& p) {
    std::vector<double> contacts, rattlers;
    for (std::uint64_t seed = 1; seed <= 6; ++seed) {
      const auto r = pack(5.0, 500, seed, p);
      const auto slab = analysis::void_fraction_summary(r.bed, analysis::AnalysisParams{})["central_slab_m"];
      const auto c = analysis::slab_coordination(r.bed, analysis::contact_statistics(r.bed, 1e-3), slab[0].get<double>(),
                                                 slab[1].get<double>());
      contacts.push_back(c.mean_sphere_contacts);
      rattlers.push_back(static_cast<double>(c.rattlers));
    }
    return std::pair{spread(contacts), spread(rattlers)};
  };
  SoftSphereParams tight;
  tight.force_tolerance = 0.1;
  const auto [zf, rf] = measure(mode(SoftSphereParams::Mode::faithful));
  const auto [za, ra] = measure(tight);
  EXPECT_LE(std::abs(za.mean - zf.mean), 2.0 * std::sqrt(za.se2 + zf.se2))
      << "contacts per sphere: accelerated " << za.mean << ", faithful " << zf.mean;
  EXPECT_LE(std::abs(ra.mean - rf.mean), 2.0 * std::sqrt(ra.se2 + rf.se2))
      << "rattlers in the slab: accelerated " << ra.mean << ", faithful " << rf.mean;
}
