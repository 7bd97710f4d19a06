// The Monte Carlo packer's schedule end to end on small beds: validity, containers, errors.
#include "packer/monte_carlo.hpp"

#include <gtest/gtest.h>

#include "analysis/contact_statistics.hpp"
#include "analysis/segregation.hpp"
#include "analysis/void_fraction.hpp"
#include "core/error.hpp"

using namespace bedforge;
using packer::MonteCarloParams;

namespace {

SizeDistribution spheres(std::vector<double> d, std::vector<double> fractions = {1.0}) {
  SizeDistribution s;
  s.kind = d.size() > 1 ? SizeDistribution::Kind::discrete : SizeDistribution::Kind::monodisperse;
  s.diameters_m = std::move(d);
  s.number_fractions = std::move(fractions);
  return s;
}

MonteCarloParams short_schedule() {
  MonteCarloParams p;
  p.mixing_cycles = 200;
  p.shakes = 2;  // the first shake's settling is the fall from the mixing height
  p.settling_cycles = 1000;
  return p;
}

packer::PackResult pack(const Container& c, long long n, std::uint64_t seed = 1, MonteCarloParams p = short_schedule(),
                        const SizeDistribution& s = spheres({0.001})) {
  Progress quiet("test", false);
  return packer::pack_monte_carlo(p, s, c, n, seed, quiet);
}

void expect_valid(const Bed& bed) {
  const auto st = analysis::contact_statistics(bed, 0.0);
  EXPECT_EQ(st.max_pair_overlap, 0.0);
  EXPECT_EQ(st.max_wall_overlap, 0.0);
  EXPECT_EQ(st.max_floor_penetration, 0.0);
}

}  // namespace

TEST(MonteCarlo, SettledCylinderBedIsValidAndDense) {
  const Cylinder c(0.0025);  // a = 5
  const auto r = pack(c, 200);
  ASSERT_EQ(r.bed.size(), 200u);
  expect_valid(r.bed);
  // Below its rough top (2 d) the settled bed lies between random close packing (0.36) and
  // loose random packing at a = 5 (Zou & Yu, loose: 0.475); it fell from a void fraction of 0.88.
  const double eps = analysis::void_fraction(r.bed, 0.0, bed_height(r.bed) - 0.002);
  EXPECT_GT(eps, 0.36);
  EXPECT_LT(eps, 0.475);
  for (const auto& s : r.info["shakes"]) EXPECT_TRUE(s["settled"].get<bool>());
  // The reported rate is the cycles over the packer's own time (not a rate of something else).
  EXPECT_NEAR(r.info["cycles_per_second"].get<double>() * r.info["time_s"].get<double>(),
              r.info["cycles"].get<double>(), 1e-3 * r.info["cycles"].get<double>());
  EXPECT_EQ(r.info["shakes"].size(), 2u);
}

TEST(MonteCarlo, AnnulusAndPeriodicBoxBeds) {
  const Annulus annulus(0.005, 0.002);
  const Box box(0.004, 0.004, true, true);
  for (const Container* c : {static_cast<const Container*>(&annulus), static_cast<const Container*>(&box)}) {
    const auto r = pack(*c, 150);
    expect_valid(r.bed);
    for (const auto& x : r.bed.centres) {  // stored in the central periodic cell
      EXPECT_LE(std::abs(x.x()), 0.005);
      EXPECT_LE(std::abs(x.y()), 0.005);
    }
  }
}

TEST(MonteCarlo, ReproducibleBySeed) {
  const Cylinder c(0.002);
  MonteCarloParams p = short_schedule();
  p.settling_cycles = 100;
  const auto a = pack(c, 60, 7, p), b = pack(c, 60, 7, p), other = pack(c, 60, 8, p);
  EXPECT_EQ(a.bed.centres, b.bed.centres);
  EXPECT_NE(a.bed.centres, other.bed.centres);
}

TEST(MonteCarlo, ImpossibleInputsAreClearErrors) {
  const Cylinder c(0.002);
  auto message = [&](MonteCarloParams p, const SizeDistribution& s = spheres({0.001})) {
    try {
      pack(c, 100, 1, p, s);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  MonteCarloParams low = short_schedule();
  low.mixing_height_d = 5.0;  // 100 spheres below 5 d in a = 4: solid fraction 0.83
  EXPECT_NE(message(low).find("mixing_height_d"), std::string::npos);
  MonteCarloParams three = short_schedule();
  three.particle_density = {1000, 2000, 3000};
  EXPECT_NE(message(three, spheres({0.001, 0.0012}, {0.5, 0.5})).find("particle_densities"), std::string::npos);

  auto read = [](const std::string& text) {
    const toml::table t = toml::parse(text);
    SceneSection s(t["mc"].as_table(), "packing.monte_carlo");
    return packer::read_monte_carlo_params(s);
  };
  auto read_message = [&](const std::string& text) {
    try {
      read(text);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(read_message("[mc]\ntemperature = 0").find("temperature"), std::string::npos);
  EXPECT_NE(read_message("[mc]\nparticle_density = 0.5").find("particle_density"), std::string::npos);
  EXPECT_NE(read_message("[mc]\nparticle_densities = [1000, 1.0]").find("particle_densities[1]"), std::string::npos);
  EXPECT_NE(read_message("[mc]\ninitial_void_fraction = 0.5").find("initial_void_fraction"), std::string::npos);
}

TEST(MonteCarlo, DenserSpeciesSinks) {
  // Equal sizes, densities 1000 and 3000 kg/m3: at a temperature where the light species is
  // mobile, the heavy one gathers lower (the effective masses differ threefold).
  const Cylinder c(0.003);
  MonteCarloParams p = short_schedule();
  p.particle_density = {1000.0, 3000.0};
  p.temperature = 0.5;
  p.settling_cycles = 3000;
  Progress quiet("test", false);
  const auto r = packer::pack_monte_carlo(p, spheres({0.001, 0.0010001}, {0.5, 0.5}), c, 120, 3, quiet);
  double z_light = 0, z_heavy = 0;
  for (size_t i = 0; i < r.bed.size(); ++i)
    (r.bed.diameters[i] > 0.00100005 ? z_heavy : z_light) += r.bed.centres[i].z() / 60.0;
  EXPECT_LT(z_heavy, z_light);
}

TEST(MonteCarlo, ShakenBinaryMixtureSegregatesLargeOnTop) {
  // Abreu et al. (1999), Fig. 7: spheres of diameter ratio 1.2 in equal numbers segregate almost
  // completely after 100 shakes (docs/monte_carlo_validation.md: 1000 spheres, intensity about
  // 0.7). Here a smaller bed and 40 shakes: the large spheres must rise clearly above the small
  // ones, and the intensity must stand well above that of the same bed after its fall alone (a
  // random mixture sampled in layers of a few tens of spheres: a few hundredths).
  const Cylinder c(0.0035);  // a = 7 in small diameters
  MonteCarloParams p = short_schedule();
  Progress quiet("test", false);
  const auto mixture = spheres({0.0012, 0.001}, {0.5, 0.5});
  auto segregation_after = [&](long shakes) {
    p.shakes = shakes;
    const auto r = packer::pack_monte_carlo(p, mixture, c, 400, 2, quiet);
    expect_valid(r.bed);
    return analysis::axial_segregation(r.bed, 0.0012, bed_height(r.bed));
  };
  const auto fallen = segregation_after(1);  // the first shake's settling is the fall
  const auto shaken = segregation_after(40);
  ASSERT_EQ(shaken.mean_height.size(), 2u);
  EXPECT_GT(shaken.mean_height[0], shaken.mean_height[1] + 0.002);  // 2 small diameters higher
  EXPECT_LT(fallen.intensity, 0.1);
  EXPECT_GT(shaken.intensity, 0.2);
  EXPECT_GT(shaken.intensity, 3 * fallen.intensity) << "fallen " << fallen.intensity << ", shaken " << shaken.intensity;
}

TEST(MonteCarlo, DefaultShakesFollowThePaper) {
  // Abreu et al. (1999), step (b): 10 shakes for equal spheres, 100 for binary mixtures; a
  // number in the scene wins.
  const Cylinder c(0.002);
  MonteCarloParams p;
  p.mixing_cycles = 20;
  p.settling_cycles = 20;
  p.max_settle_cycles = 200;
  auto shakes = [&](const SizeDistribution& s) { return pack(c, 20, 1, p, s).info["shakes"].size(); };
  EXPECT_EQ(shakes(spheres({0.001})), 10u);
  EXPECT_EQ(shakes(spheres({0.0012, 0.001}, {0.5, 0.5})), 100u);
  p.particle_density = {1000.0, 2000.0};
  EXPECT_EQ(shakes(spheres({0.001, 0.0010001}, {0.5, 0.5})), 100u);  // a mixture of densities
  p.particle_density = {1000.0};
  p.shakes = 3;
  EXPECT_EQ(shakes(spheres({0.0012, 0.001}, {0.5, 0.5})), 3u);
}

TEST(MonteCarlo, PeriodicSectionIsCompressedToItsPeriod) {
  // a = 5, period 10 d, 200 spheres: a solid fraction of 0.533, below the 0.575 that the packer
  // reached at 215 spheres (docs/monte_carlo.md); no floor, pairs across the period.
  Cylinder c(0.0025);
  c.set_axial_period(0.01);
  MonteCarloParams p;
  p.mixing_cycles = 200;
  const auto r = pack(c, 200, 4, p);
  expect_valid(r.bed);
  ASSERT_EQ(r.bed.container->axial_period(), 0.01);
  const Periodicity per = r.bed.container->periodicity();
  int across = 0;  // pairs within 0.01 d of touching only through the period
  for (size_t i = 0; i < r.bed.size(); ++i) {
    EXPECT_GE(r.bed.centres[i].z(), 0.0);
    EXPECT_LT(r.bed.centres[i].z(), 0.01);
    for (size_t j = i + 1; j < r.bed.size(); ++j)
      across += (r.bed.centres[i] - r.bed.centres[j]).norm() > 0.00101 &&
                per.separation(r.bed.centres[i], r.bed.centres[j]).norm() < 0.00101;
  }
  EXPECT_GT(across, 0);
  EXPECT_EQ(r.info["shakes"].size(), 0u);
  EXPECT_TRUE(r.info["stages"].contains("compression"));
  EXPECT_GT(r.info["placed_period_d"].get<double>(), 10.0);
  EXPECT_EQ(pack(c, 200, 4, p).bed.centres, r.bed.centres);  // the same seed, the same section
}

TEST(MonteCarlo, PeriodicSectionThatJamsStopsWithItsSolidFraction) {
  // 230 spheres in 10 d of an a = 5 tube (solid fraction 0.613) within 2000 compression cycles:
  // a clear error naming the fraction reached and the keys to change, not a hang.
  Cylinder c(0.0025);
  c.set_axial_period(0.01);
  MonteCarloParams p;
  p.mixing_cycles = 20;
  p.settling_cycles = 2000;
  try {
    pack(c, 230, 1, p);
    FAIL() << "accepted";
  } catch (const ConvergenceError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("solid fraction of 0."), std::string::npos) << m;
    EXPECT_NE(m.find("settling_cycles"), std::string::npos) << m;
    EXPECT_NE(m.find("container.period_z_d"), std::string::npos) << m;
  }
}
