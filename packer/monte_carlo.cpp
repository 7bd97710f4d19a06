#include "packer/monte_carlo.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

#include "core/error.hpp"
#include "core/neighbour_list.hpp"
#include "core/random.hpp"
#include "packer/hard_sphere_chain.hpp"
#include "packer/run_log.hpp"

namespace bedforge::packer {

MonteCarloParams read_monte_carlo_params(SceneSection& s) {
  MonteCarloParams p;
  const Range positive = Range::positive();
  p.temperature = s.number("temperature", p.temperature, positive);
  if (s.has("particle_densities")) {
    if (s.has("particle_density"))
      throw InputError(fmt::format("{0}: give particle_density (one value) or particle_densities (one per species), "
                                   "not both",
                                   s.name()));
    p.particle_density = s.numbers("particle_densities", positive);
  } else {
    p.particle_density = {s.number("particle_density", p.particle_density[0], positive)};
  }
  p.fluid_density = s.number("fluid_density", p.fluid_density, Range::non_negative());
  for (std::size_t k = 0; k < p.particle_density.size(); ++k)
    if (p.particle_density[k] <= p.fluid_density)
      throw InputError(fmt::format("{}: particle density {} kg/m3 is not above fluid_density = {} kg/m3; allowed: "
                                   "particles denser than the fluid (they would float)",
                                   s.key_path(p.particle_density.size() > 1 ? fmt::format("particle_densities[{}]", k)
                                                                            : std::string("particle_density")),
                                   p.particle_density[k], p.fluid_density));
  p.initial_void_fraction = s.number("initial_void_fraction", p.initial_void_fraction, Range{0.7, 1.0, false, true});
  p.mixing_height_d = s.optional_number("mixing_height_d", positive);
  p.mixing_cycles = s.integer("mixing_cycles", p.mixing_cycles, 0, 1'000'000'000);
  const long long shakes = s.integer("shakes", -1, 0, 1'000'000, "10 for equal spheres, 100 for mixtures");
  if (shakes >= 0) p.shakes = shakes;
  p.shake_amplitude_d = s.number("shake_amplitude_d", p.shake_amplitude_d, Range::non_negative());
  p.shake_dilation = s.number("shake_dilation", p.shake_dilation, Range::closed(0.0, 100.0));
  p.settle_block_cycles = s.integer("settle_block_cycles", p.settle_block_cycles, 1, 1'000'000);
  p.settle_tolerance_d = s.number("settle_tolerance_d", p.settle_tolerance_d, positive);
  p.max_settle_cycles = s.integer("max_settle_cycles", p.max_settle_cycles, 1, 1'000'000'000);
  p.settling_cycles = s.integer("settling_cycles", p.settling_cycles, 0, 1'000'000'000);
  p.target_acceptance = s.number("target_acceptance", p.target_acceptance, Range::open(0.0, 1.0));
  p.max_displacement_d = s.number("max_displacement_d", p.max_displacement_d, Range{0.0, 1.0, true, false});
  return p;
}

nlohmann::json to_json(const MonteCarloParams& p) {
  return {{"temperature", p.temperature},
          {"particle_density", p.particle_density},
          {"fluid_density", p.fluid_density},
          {"initial_void_fraction", p.initial_void_fraction},
          {"mixing_height_d", p.mixing_height_d ? nlohmann::json(*p.mixing_height_d) : nlohmann::json()},
          {"mixing_cycles", p.mixing_cycles},
          {"shakes", p.shakes ? nlohmann::json(*p.shakes) : nlohmann::json(nullptr)},
          {"shake_amplitude_d", p.shake_amplitude_d},
          {"shake_dilation", p.shake_dilation},
          {"settle_block_cycles", p.settle_block_cycles},
          {"settle_tolerance_d", p.settle_tolerance_d},
          {"max_settle_cycles", p.max_settle_cycles},
          {"settling_cycles", p.settling_cycles},
          {"target_acceptance", p.target_acceptance},
          {"max_displacement_d", p.max_displacement_d}};
}

namespace {

// Random sequential placement below the lid stops working near a solid fraction of 0.38 (its
// jamming limit); 0.30 leaves room for the walls' excluded volume.
constexpr double kMaxPlacementSolidFraction = 0.30;
// A periodic section's compression: cycles without gravity between two compressions, and the
// share of moves accepted they aim at (small moves that often succeed even out the gaps along z
// faster than the settling's large ones; docs/monte_carlo.md, periodic sections).
constexpr long kCompressionBlockCycles = 5;
constexpr double kCompressionAcceptance = 0.3;

}  // namespace

PackResult pack_monte_carlo(const MonteCarloParams& params, const SizeDistribution& sizes, const Container& container,
                            long long count, std::uint64_t seed, Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const double d_ref = sizes.sauter_mean(), d_min = sizes.smallest() / d_ref;
  const auto box = container.scaled(1.0 / d_ref);

  // Species and their buoyancy-corrected masses, relative to a sphere of d_ref of the first density.
  const bool per_species = params.particle_density.size() > 1;
  if (per_species && (sizes.kind != SizeDistribution::Kind::discrete ||
                      sizes.diameters_m.size() != params.particle_density.size()))
    throw InputError(fmt::format("packing.monte_carlo.particle_densities has {} values; allowed: one per diameter of "
                                 "a discrete mixture (particles.diameters has {})",
                                 params.particle_density.size(),
                                 sizes.kind == SizeDistribution::Kind::discrete ? sizes.diameters_m.size() : 0));
  // The paper's schedule unless the scene sets the shakes: 10 for equal spheres, 100 for
  // mixtures of sizes or densities (Abreu et al. 1999, step b). The report records the number.
  const bool equal_spheres = !per_species && sizes.smallest() == sizes.largest();
  const long shake_count = params.shakes.value_or(equal_spheres ? 10 : 100);
  MonteCarloParams resolved = params;
  resolved.shakes = shake_count;
  Rng rng(seed);
  std::vector<double> d = sizes.sample(count, rng);
  // Largest first: random placement finds room for them while the container is still empty.
  std::stable_sort(d.begin(), d.end(), std::greater<>());
  auto density_of = [&](double di) {
    if (!per_species) return params.particle_density[0];
    std::size_t k = 0;
    for (std::size_t s = 1; s < sizes.diameters_m.size(); ++s)
      if (std::abs(sizes.diameters_m[s] - di) < std::abs(sizes.diameters_m[k] - di)) k = s;
    return params.particle_density[k];
  };
  const double ref_excess = params.particle_density[0] - params.fluid_density;
  std::vector<double> r, w;
  double solid = 0.0;
  for (double di : d) {
    r.push_back(0.5 * di / d_ref);
    w.push_back((density_of(di) - params.fluid_density) / ref_excess * std::pow(di / d_ref, 3));
    solid += std::numbers::pi / 6.0 * std::pow(di / d_ref, 3);
  }

  // (a) Placement below the lid, then mixing without gravity. A periodic section has no floor to
  // settle on: its spheres are placed in a period long enough for random placement, mixed, and
  // compressed to the asked period instead of shaken (b').
  const double period = box->axial_period();
  if (period > 0.0) {
    resolved.shakes = 0;
    box->set_axial_period(std::max(period, solid / (box->cross_section_area() * kMaxPlacementSolidFraction)));
  }
  const double lid = period > 0.0             ? box->axial_period()
                     : params.mixing_height_d ? *params.mixing_height_d
                                              : solid / (box->cross_section_area() * (1.0 - params.initial_void_fraction));
  const double fraction = solid / (box->cross_section_area() * lid);
  if (period == 0.0 && fraction > kMaxPlacementSolidFraction)
    throw InputError(fmt::format("packing.monte_carlo.{}: {} spheres fill {:.3f} of the volume below the mixing lid "
                                 "({:.4g} d high); allowed: at most {} (random placement jams near 0.38), so raise "
                                 "it",
                                 params.mixing_height_d ? "mixing_height_d" : "initial_void_fraction", count, fraction,
                                 lid, kMaxPlacementSolidFraction));
  const double amplitude = params.shake_amplitude_d * d_min;
  HardSphereChain chain(*box, 2.0 * r.front(), lid + 2.0 * amplitude + 2.0, lid, seed ^ 0x5DEECE66DULL);
  for (std::size_t i = 0; i < r.size(); ++i) {
    bool placed = false;
    for (int attempt = 0; attempt < 100'000 && !placed; ++attempt) {
      // A period with no room left (the walls' excluded volume) is stretched by a tenth.
      if (period > 0.0 && attempt > 0 && attempt % 1000 == 0) chain.compress_to(1.1 * chain.period());
      const Eigen::Vector2d xy = box->sample_centre(rng, r[i]);
      const double z = period > 0.0 ? chain.period() * rng.uniform() : r[i] + (lid - 2.0 * r[i]) * rng.uniform();
      placed = chain.add({xy.x(), xy.y(), z}, r[i], w[i]);
    }
    if (!placed)
      throw InputError(fmt::format("could not place sphere {} of {} (d = {:.4g} m) below the mixing lid in 100000 "
                                   "random trials; raise packing.monte_carlo.initial_void_fraction or mixing_height_d",
                                   i + 1, count, d[i]));
  }

  const double placed_period = chain.period();
  const double t_star = params.temperature, target = period > 0.0 ? kCompressionAcceptance : params.target_acceptance;
  const double delta_lo = 1e-4 * d_min, delta_hi = params.max_displacement_d * d_min;
  chain.set_displacement(delta_hi);
  const long total_cycles = params.mixing_cycles + params.settling_cycles + resolved.shakes.value() * params.max_settle_cycles;
  long cycles = 0;
  nlohmann::json history = nlohmann::json::array(), shakes = nlohmann::json::array();
  nlohmann::json stages = nlohmann::json::object();
  double acceptance_sum = 0.0;
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  auto run = [&](bool gravity, const char* stage) {
    const double a = chain.cycle(t_star, gravity);
    chain.adapt_displacement(a, target, delta_lo, delta_hi);
    acceptance_sum += a;
    if (++cycles % 100 == 0) {
      history.push_back({{"cycle", cycles},
                         {"time_s", elapsed()},
                         {"stage", stage},
                         {"mass_centre_d", chain.mass_centre()},
                         {"acceptance", a},
                         {"max_displacement_d", chain.displacement() / d_min}});
      if (period > 0.0) history.back()["period_d"] = chain.period();
      const std::string where = period > 0.0 ? fmt::format("period {:.4f} d", chain.period())
                                             : fmt::format("mass centre {:.4f} d", chain.mass_centre());
      progress.update(fmt::format("monte carlo, {} stage, cycle {}, {}, acceptance {:.2f}", stage, cycles, where, a),
                      std::min(1.0, static_cast<double>(cycles) / static_cast<double>(std::max(1L, total_cycles))));
    }
  };
  auto timed = [&](const char* stage, auto body) {
    const auto s0 = std::chrono::steady_clock::now();
    const long c0 = cycles;
    body();
    stages[stage] = {{"cycles", cycles - c0},
                     {"time_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count()}};
  };
  timed("mixing", [&] {
    for (long c = 0; c < params.mixing_cycles; ++c) run(false, "mixing");
  });
  chain.set_lid(std::numeric_limits<double>::infinity());

  // (b') A periodic section: blocks of cycles without gravity, each followed by the period's
  // shrinking halfway to where the nearest pair along z would touch, down to the asked period,
  // within settling_cycles.
  if (period > 0.0)
    timed("compression", [&] {
      long used = 0;
      while (chain.period() > period) {
        if (used >= params.settling_cycles) {
          const double reached = solid / (box->cross_section_area() * chain.period());
          throw ConvergenceError(fmt::format(
              "the Monte Carlo periodic section stopped at a solid fraction of {:.4f} (period {:.4g} d) after {} "
              "compression cycles (packing.monte_carlo.settling_cycles), short of the asked {:.4f} (period {:.4g} "
              "d); allowed: fewer spheres (particles.count), a longer container.period_z_d (or period_z_m), or more "
              "settling_cycles",
              reached, chain.period(), used, solid / (box->cross_section_area() * period), period));
        }
        for (long c = 0; c < kCompressionBlockCycles; ++c, ++used) run(false, "compression");
        const double towards = 0.5 * (1.0 + std::max(0.5, chain.feasible_compression()));
        chain.compress_to(std::max(period, chain.period() * towards));
      }
    });

  // (b) Shakes, each settled until the mass centre stops falling.
  const double settle_tol = params.settle_tolerance_d * d_min;
  long unsettled = 0;
  timed("shaking", [&] {
    for (long k = 0; k < resolved.shakes.value(); ++k) {
      chain.lift(amplitude, params.shake_dilation);
      double before = chain.mass_centre();
      long used = 0;
      bool settled = false;
      while (!settled && used < params.max_settle_cycles) {
        for (long c = 0; c < params.settle_block_cycles && used < params.max_settle_cycles; ++c, ++used)
          run(true, "shaking");
        const double now = chain.mass_centre();
        settled = before - now < settle_tol;
        before = now;
      }
      unsettled += !settled;
      shakes.push_back({{"shake", k + 1}, {"cycles", used}, {"settled", settled}, {"mass_centre_d", before}});
    }
  });

  // (c) Final settling cycles under gravity.
  if (period == 0.0)
    timed("settling", [&] {
      for (long c = 0; c < params.settling_cycles; ++c) run(true, "settling");
    });
  progress.finish();

  // Check the promise exactly, with the neighbour list rather than the chain's own grid.
  std::vector<Eigen::Vector3d> x = chain.positions();
  NeighbourList nl(0.01 * d_min);
  nl.build(x, r, *box);
  const Periodicity per = box->periodicity();
  double worst = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (int j : nl.of(i)) worst = std::max(worst, r[i] + r[j] - per.separation(x[i], x[j]).norm());
    WallContact wc[Container::kMaxWallContacts];
    const int nw = box->wall_contacts(x[i], r[i], wc);
    for (int m = 0; m < nw; ++m) worst = std::max(worst, wc[m].overlap);
    if (period == 0.0) worst = std::max(worst, r[i] - x[i].z());
    if (!x[i].allFinite()) worst = std::numeric_limits<double>::infinity();
  }
  if (!(worst <= 1e-12))
    throw ConvergenceError(fmt::format("internal error: the Monte Carlo bed has an overlap of {:.3g} d", worst));

  PackResult out;
  out.bed.container = container.scaled(1.0);
  for (std::size_t i = 0; i < x.size(); ++i) {
    out.bed.centres.push_back(x[i] * d_ref);
    out.bed.diameters.push_back(d[i]);
  }
  const double time = elapsed();
  out.info = {{"algorithm", "monte-carlo"},
              {"parameters", to_json(resolved)},
              {"reference_diameter_m", d_ref},
              {"smallest_diameter_m", sizes.smallest()},
              {period > 0.0 ? "placed_period_d" : "mixing_height_d", period > 0.0 ? placed_period : lid},
              {"mixing_solid_fraction", period > 0.0 ? solid / (box->cross_section_area() * placed_period) : fraction},
              {"cycles", cycles},
              {"moves_per_second", static_cast<double>(cycles) * static_cast<double>(count) / std::max(time, 1e-9)},
              {"cycles_per_second", static_cast<double>(cycles) / std::max(time, 1e-9)},
              {"mean_acceptance", cycles ? acceptance_sum / static_cast<double>(cycles) : 0.0},
              {"stages", stages},
              {"shakes", shakes},
              {"unsettled_shakes", unsettled},
              {"history", thin_history(history)},
              {"max_overlap_d", std::max(0.0, worst) / d_min},
              {"time_s", time}};
  const std::string settled =
      period > 0.0 ? fmt::format("compressed from a period of {:.4g} d to {:.4g} d", placed_period, period)
                   : fmt::format("{} of {} shakes settled", shakes.size() - unsettled, shakes.size());
  out.summary = fmt::format("pack (monte-carlo): {} spheres in a {}, {} cycles ({:.0f} per s), acceptance {:.2f}, {}, "
                            "no overlap",
                            x.size(), container.kind(), cycles, out.info["cycles_per_second"].get<double>(),
                            out.info["mean_acceptance"].get<double>(), settled);
  return out;
}

}  // namespace bedforge::packer
