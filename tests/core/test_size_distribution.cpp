#include "core/size_distribution.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "core/error.hpp"

using namespace bedforge;

namespace {

SizeDistribution read(const char* text) {
  const auto t = parse_scene_text(text, "test.toml");
  SceneSection s(t["particles"].as_table(), "particles");
  SizeDistribution d = read_size_distribution(s);
  s.finish();
  return d;
}

}  // namespace

TEST(SizeDistribution, MonodisperseIsItsOwnReference) {
  const auto d = read("[particles]\ndiameter_m = 0.003\n");
  EXPECT_DOUBLE_EQ(d.sauter_mean(), 0.003);
  EXPECT_DOUBLE_EQ(d.smallest(), 0.003);
  EXPECT_NEAR(d.mean_volume(), M_PI / 6 * 27e-9, 1e-20);
}

TEST(SizeDistribution, DiscreteSauterMeanFromNumberFractions) {
  // d32 = sum n d^3 / sum n d^2 = (0.5 * 1 + 0.5 * 8) / (0.5 * 1 + 0.5 * 4) = 4.5 / 2.5.
  const auto d = read("[particles]\ndistribution = \"discrete\"\ndiameters_m = [1.0, 2.0]\nnumber_fractions = [0.5, 0.5]\n");
  EXPECT_NEAR(d.sauter_mean(), 1.8, 1e-12);
}

TEST(SizeDistribution, VolumeFractionsBecomeNumberFractions) {
  // Equal volumes of d = 1 and d = 2: eight small spheres per large one.
  const auto d = read("[particles]\ndistribution = \"discrete\"\ndiameters_m = [1.0, 2.0]\nvolume_fractions = [0.5, 0.5]\n");
  EXPECT_NEAR(d.number_fractions[0], 8.0 / 9.0, 1e-12);
  EXPECT_NEAR(d.number_fractions[1], 1.0 / 9.0, 1e-12);
}

TEST(SizeDistribution, DiscreteSampleHasExactCounts) {
  const auto d = read("[particles]\ndistribution = \"discrete\"\ndiameters_m = [1.0, 2.0, 3.0]\nnumber_fractions = [0.2, 0.3, 0.5]\n");
  Rng rng(5);
  const auto s = d.sample(101, rng);
  std::map<double, int> n;
  for (double v : s) ++n[v];
  EXPECT_EQ(s.size(), 101u);
  EXPECT_NEAR(n[1.0], 20.2, 1.0);
  EXPECT_NEAR(n[2.0], 30.3, 1.0);
  EXPECT_NEAR(n[3.0], 50.5, 1.0);
}

TEST(SizeDistribution, FractionsMustSumToOne) {
  EXPECT_THROW(read("[particles]\ndistribution = \"discrete\"\ndiameters_m = [1.0, 2.0]\nnumber_fractions = [0.5, 0.6]\n"),
               InputError);
  EXPECT_THROW(read("[particles]\ndistribution = \"discrete\"\ndiameters_m = [1.0, 2.0]\nnumber_fractions = [1.0]\n"),
               InputError);
  EXPECT_THROW(read("[particles]\ndistribution = \"discrete\"\ndiameters_m = [1.0, 2.0]\n"), InputError);
}

TEST(SizeDistribution, NonPositiveDiameterIsRejected) {
  EXPECT_THROW(read("[particles]\ndiameter_m = 0.0\n"), InputError);
  EXPECT_THROW(read("[particles]\ndiameter_m = -1e-3\n"), InputError);
}

TEST(SizeDistribution, SymmetricTruncatedNormalKeepsItsMean) {
  const auto d = read("[particles]\ndistribution = \"normal\"\nmean_m = 2.0\nstd_m = 0.3\nmin_m = 1.4\nmax_m = 2.6\n");
  Rng rng(11);
  const auto s = d.sample(20000, rng);
  double mean = 0;
  for (double v : s) {
    ASSERT_GE(v, 1.4);
    ASSERT_LE(v, 2.6);
    mean += v / s.size();
  }
  // Standard error of the mean: below 0.3 / sqrt(20000) = 0.0021; allow 4 of them.
  EXPECT_NEAR(mean, 2.0, 0.0085);
  // Sample Sauter mean agrees with the distribution's (quadrature) value.
  double s3 = 0, s2 = 0;
  for (double v : s) s3 += v * v * v, s2 += v * v;
  EXPECT_NEAR(s3 / s2, d.sauter_mean(), 0.01);
}

TEST(SizeDistribution, LognormalMatchesGivenMeanWhenBarelyCut) {
  const auto d = read("[particles]\ndistribution = \"lognormal\"\nmean_m = 1.0\nstd_m = 0.2\nmin_m = 0.2\nmax_m = 5.0\n");
  Rng rng(3);
  const auto s = d.sample(20000, rng);
  double mean = 0, var = 0;
  for (double v : s) mean += v / s.size();
  for (double v : s) var += (v - mean) * (v - mean) / s.size();
  EXPECT_NEAR(mean, 1.0, 0.006);
  EXPECT_NEAR(std::sqrt(var), 0.2, 0.006);
}

TEST(SizeDistribution, CutOffsThatExcludeEverythingAreRejected) {
  EXPECT_THROW(read("[particles]\ndistribution = \"normal\"\nmean_m = 1.0\nstd_m = 0.01\nmin_m = 2.0\nmax_m = 3.0\n"),
               InputError);
  EXPECT_THROW(read("[particles]\ndistribution = \"normal\"\nmean_m = 1.0\nstd_m = 0.1\nmin_m = 1.2\nmax_m = 1.1\n"),
               InputError);
}

TEST(SizeDistribution, SameSeedSameSample) {
  const auto d = read("[particles]\ndistribution = \"normal\"\nmean_m = 1.0\nstd_m = 0.1\n");
  Rng a(42), b(42);
  EXPECT_EQ(d.sample(50, a), d.sample(50, b));
}
