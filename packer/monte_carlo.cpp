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

// The spheres to pack, largest first (random placement finds room for them while the container
// is still empty): diameters (m); radii and buoyancy-corrected masses relative to a sphere of
// d_ref of the first density, in units of d_ref; their total volume (d_ref^3).
struct DrawnSpheres {
  std::vector<double> d, r, w;
  double solid = 0.0;
};

DrawnSpheres draw_spheres(const MonteCarloParams& params, const SizeDistribution& sizes, long long count, double d_ref,
                     Rng& rng) {
  const bool per_species = params.particle_density.size() > 1;
  if (per_species && (sizes.kind != SizeDistribution::Kind::discrete ||
                      sizes.diameters_m.size() != params.particle_density.size()))
    throw InputError(fmt::format("packing.monte_carlo.particle_densities has {} values; allowed: one per diameter of "
                                 "a discrete mixture (particles.diameters has {})",
                                 params.particle_density.size(),
                                 sizes.kind == SizeDistribution::Kind::discrete ? sizes.diameters_m.size() : 0));
  auto density_of = [&](double di) {
    if (!per_species) return params.particle_density[0];
    std::size_t k = 0;
    for (std::size_t s = 1; s < sizes.diameters_m.size(); ++s)
      if (std::abs(sizes.diameters_m[s] - di) < std::abs(sizes.diameters_m[k] - di)) k = s;
    return params.particle_density[k];
  };
  DrawnSpheres out;
  out.d = sizes.sample(count, rng);
  std::stable_sort(out.d.begin(), out.d.end(), std::greater<>());
  const double ref_excess = params.particle_density[0] - params.fluid_density;
  for (double di : out.d) {
    out.r.push_back(0.5 * di / d_ref);
    out.w.push_back((density_of(di) - params.fluid_density) / ref_excess * std::pow(di / d_ref, 3));
    out.solid += std::numbers::pi / 6.0 * std::pow(di / d_ref, 3);
  }
  return out;
}

// Places `s` at random, one after the other, below `lid` (d_ref units; or anywhere in the
// chain's period, which is stretched by a tenth whenever a sphere finds no room in 1000 trials:
// the walls' excluded volume).
void place_spheres(HardSphereChain& chain, const Container& box, const DrawnSpheres& s, double lid, Rng& rng) {
  const bool periodic = box.axial_period() > 0.0;
  for (std::size_t i = 0; i < s.r.size(); ++i) {
    bool placed = false;
    for (int attempt = 0; attempt < 100'000 && !placed; ++attempt) {
      if (periodic && attempt > 0 && attempt % 1000 == 0) chain.compress_to(1.1 * chain.period());
      const Eigen::Vector2d xy = box.sample_centre(rng, s.r[i]);
      const double z = periodic ? chain.period() * rng.uniform() : s.r[i] + (lid - 2.0 * s.r[i]) * rng.uniform();
      placed = chain.add({xy.x(), xy.y(), z}, s.r[i], s.w[i]);
    }
    if (!placed)
      throw InputError(fmt::format("could not place sphere {} of {} (d = {:.4g} m) below the mixing lid in 100000 "
                                   "random trials; raise packing.monte_carlo.initial_void_fraction or mixing_height_d",
                                   i + 1, s.r.size(), s.d[i]));
  }
}

// Runs the chain's cycles, adapting its step to a target acceptance, and keeps what the report
// and the progress line show of them: a history row every 100 cycles, each stage's cycles and
// time.
class CycleRunner {
 public:
  // `t0`: when the packing started, which the history's times count from.
  CycleRunner(HardSphereChain& chain, Progress& progress, std::chrono::steady_clock::time_point t0, double temperature,
              double target, double delta_lo, double delta_hi, double d_min, long total_cycles)
      : chain_(chain), progress_(progress), t0_(t0), t_star_(temperature), target_(target), delta_lo_(delta_lo),
        delta_hi_(delta_hi), d_min_(d_min), total_(total_cycles), periodic_(chain.period() > 0.0) {
    chain_.set_displacement(delta_hi);
  }
  // One cycle, with or without gravity, of the stage named.
  void run(bool gravity, const char* stage) {
    const double a = chain_.cycle(t_star_, gravity);
    chain_.adapt_displacement(a, target_, delta_lo_, delta_hi_);
    acceptance_sum_ += a;
    if (++cycles_ % 100 == 0) {
      history_.push_back({{"cycle", cycles_},
                          {"time_s", elapsed()},
                          {"stage", stage},
                          {"mass_centre_d", chain_.mass_centre()},
                          {"acceptance", a},
                          {"max_displacement_d", chain_.displacement() / d_min_}});
      if (periodic_) history_.back()["period_d"] = chain_.period();
      const std::string where = periodic_ ? fmt::format("period {:.4f} d", chain_.period())
                                          : fmt::format("mass centre {:.4f} d", chain_.mass_centre());
      progress_.update(fmt::format("monte carlo, {} stage, cycle {}, {}, acceptance {:.2f}", stage, cycles_, where, a),
                       std::min(1.0, static_cast<double>(cycles_) / static_cast<double>(std::max(1L, total_))));
    }
  }
  // `body`, its cycles and time recorded as the stage named.
  template <class Body>
  void timed(const char* stage, Body body) {
    const auto s0 = std::chrono::steady_clock::now();
    const long c0 = cycles_;
    body();
    stages_[stage] = {{"cycles", cycles_ - c0},
                      {"time_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count()}};
  }
  double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }
  long cycles() const { return cycles_; }
  double mean_acceptance() const { return cycles_ ? acceptance_sum_ / static_cast<double>(cycles_) : 0.0; }
  const nlohmann::json& history() const { return history_; }
  const nlohmann::json& stages() const { return stages_; }

 private:
  HardSphereChain& chain_;
  Progress& progress_;
  const std::chrono::steady_clock::time_point t0_;
  const double t_star_, target_, delta_lo_, delta_hi_, d_min_;
  const long total_;
  const bool periodic_;
  long cycles_ = 0;
  double acceptance_sum_ = 0.0;
  nlohmann::json history_ = nlohmann::json::array(), stages_ = nlohmann::json::object();
};

// (b) and (c) for a bed on a floor: `shakes` shakes, each settled until the mass centre stops
// falling, then the settling cycles. Returns one row per shake.
nlohmann::json shake_and_settle(CycleRunner& runner, HardSphereChain& chain, const MonteCarloParams& params,
                                long shakes, double d_min) {
  const double amplitude = params.shake_amplitude_d * d_min, settle_tol = params.settle_tolerance_d * d_min;
  nlohmann::json rows = nlohmann::json::array();
  runner.timed("shaking", [&] {
    for (long k = 0; k < shakes; ++k) {
      chain.lift(amplitude, params.shake_dilation);
      double before = chain.mass_centre();
      long used = 0;
      bool settled = false;
      while (!settled && used < params.max_settle_cycles) {
        for (long c = 0; c < params.settle_block_cycles && used < params.max_settle_cycles; ++c, ++used)
          runner.run(true, "shaking");
        const double now = chain.mass_centre();
        settled = before - now < settle_tol;
        before = now;
      }
      rows.push_back({{"shake", k + 1}, {"cycles", used}, {"settled", settled}, {"mass_centre_d", before}});
    }
  });
  runner.timed("settling", [&] {
    for (long c = 0; c < params.settling_cycles; ++c) runner.run(true, "settling");
  });
  return rows;
}

// (b') A periodic section, which has no floor to settle on: blocks of cycles without gravity,
// each followed by the period's shrinking halfway to where the nearest pair along z would touch,
// down to `period`, within settling_cycles. `solid` and `area` (d_ref units) give the solid
// fraction the error names.
void compress_to_period(CycleRunner& runner, HardSphereChain& chain, const MonteCarloParams& params, double period,
                        double solid, double area) {
  runner.timed("compression", [&] {
    long used = 0;
    while (chain.period() > period) {
      if (used >= params.settling_cycles)
        throw ConvergenceError(fmt::format(
            "the Monte Carlo periodic section stopped at a solid fraction of {:.4f} (period {:.4g} d) after {} "
            "compression cycles (packing.monte_carlo.settling_cycles), short of the asked {:.4f} (period {:.4g} "
            "d); allowed: fewer spheres (particles.count), a longer container.period_z_d (or period_z_m), or more "
            "settling_cycles",
            solid / (area * chain.period()), chain.period(), used, solid / (area * period), period));
      for (long c = 0; c < kCompressionBlockCycles; ++c, ++used) runner.run(false, "compression");
      const double towards = 0.5 * (1.0 + std::max(0.5, chain.feasible_compression()));
      chain.compress_to(std::max(period, chain.period() * towards));
    }
  });
}

// The largest overlap of the packed spheres `x` (radii `r`, d_ref units) with each other, the
// walls and (on a floor) the floor, checked with the neighbour list rather than the chain's own
// grid; infinite when a centre is not finite.
double worst_overlap(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& r, const Container& box,
                     double d_min) {
  NeighbourList nl(0.01 * d_min);
  nl.build(x, r, box);
  const Periodicity per = box.periodicity();
  const bool floor = box.axial_period() == 0.0;
  double worst = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (int j : nl.of(i)) worst = std::max(worst, r[i] + r[j] - per.separation(x[i], x[j]).norm());
    WallContact wc[Container::kMaxWallContacts];
    const int nw = box.wall_contacts(x[i], r[i], wc);
    for (int m = 0; m < nw; ++m) worst = std::max(worst, wc[m].overlap);
    if (floor) worst = std::max(worst, r[i] - x[i].z());
    if (!x[i].allFinite()) worst = std::numeric_limits<double>::infinity();
  }
  return worst;
}

}  // namespace

PackResult pack_monte_carlo(const MonteCarloParams& params, const SizeDistribution& sizes, const Container& container,
                            long long count, std::uint64_t seed, Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const double d_ref = sizes.sauter_mean(), d_min = sizes.smallest() / d_ref;
  const auto box = container.scaled(1.0 / d_ref);
  Rng rng(seed);
  const DrawnSpheres s = draw_spheres(params, sizes, count, d_ref, rng);
  const double area = box->cross_section_area();
  // The paper's schedule unless the scene sets the shakes: 10 for equal spheres, 100 for
  // mixtures of sizes or densities (Abreu et al. 1999, step b); a periodic section is compressed
  // instead (b'). The report records the number.
  const double period = box->axial_period();
  const bool equal_spheres = params.particle_density.size() == 1 && sizes.smallest() == sizes.largest();
  MonteCarloParams resolved = params;
  resolved.shakes = period > 0.0 ? 0 : params.shakes.value_or(equal_spheres ? 10 : 100);

  // (a) Placement below the lid, then mixing without gravity. A periodic section is placed in a
  // period long enough for random placement.
  if (period > 0.0) box->set_axial_period(std::max(period, s.solid / (area * kMaxPlacementSolidFraction)));
  const double lid = period > 0.0             ? box->axial_period()
                     : params.mixing_height_d ? *params.mixing_height_d
                                              : s.solid / (area * (1.0 - params.initial_void_fraction));
  const double fraction = s.solid / (area * lid);
  if (period == 0.0 && fraction > kMaxPlacementSolidFraction)
    throw InputError(fmt::format("packing.monte_carlo.{}: {} spheres fill {:.3f} of the volume below the mixing lid "
                                 "({:.4g} d high); allowed: at most {} (random placement jams near 0.38), so raise "
                                 "it",
                                 params.mixing_height_d ? "mixing_height_d" : "initial_void_fraction", count, fraction,
                                 lid, kMaxPlacementSolidFraction));
  const double amplitude = params.shake_amplitude_d * d_min;
  HardSphereChain chain(*box, 2.0 * s.r.front(), lid + 2.0 * amplitude + 2.0, lid, seed ^ 0x5DEECE66DULL);
  place_spheres(chain, *box, s, lid, rng);
  const double placed_period = chain.period();

  const long total_cycles = params.mixing_cycles + params.settling_cycles + *resolved.shakes * params.max_settle_cycles;
  CycleRunner runner(chain, progress, t0, params.temperature, period > 0.0 ? kCompressionAcceptance : params.target_acceptance,
                     1e-4 * d_min, params.max_displacement_d * d_min, d_min, total_cycles);
  runner.timed("mixing", [&] {
    for (long c = 0; c < params.mixing_cycles; ++c) runner.run(false, "mixing");
  });
  chain.set_lid(std::numeric_limits<double>::infinity());
  nlohmann::json shakes = nlohmann::json::array();
  if (period > 0.0)
    compress_to_period(runner, chain, params, period, s.solid, area);
  else
    shakes = shake_and_settle(runner, chain, params, *resolved.shakes, d_min);
  progress.finish();

  std::vector<Eigen::Vector3d> x = chain.positions();
  const double worst = worst_overlap(x, s.r, *box, d_min);
  if (!(worst <= 1e-12))
    throw ConvergenceError(fmt::format("internal error: the Monte Carlo bed has an overlap of {:.3g} d", worst));

  PackResult out;
  out.bed.container = container.scaled(1.0);
  for (std::size_t i = 0; i < x.size(); ++i) {
    out.bed.centres.push_back(x[i] * d_ref);
    out.bed.diameters.push_back(s.d[i]);
  }
  long unsettled = 0;
  for (const auto& row : shakes) unsettled += !row["settled"].get<bool>();
  const double time = runner.elapsed(), cycles = static_cast<double>(runner.cycles());
  out.info = {{"algorithm", "monte-carlo"},
              {"parameters", to_json(resolved)},
              {"reference_diameter_m", d_ref},
              {"smallest_diameter_m", sizes.smallest()},
              {period > 0.0 ? "placed_period_d" : "mixing_height_d", period > 0.0 ? placed_period : lid},
              {"mixing_solid_fraction", period > 0.0 ? s.solid / (area * placed_period) : fraction},
              {"cycles", runner.cycles()},
              {"moves_per_second", cycles * static_cast<double>(count) / std::max(time, 1e-9)},
              {"cycles_per_second", cycles / std::max(time, 1e-9)},
              {"mean_acceptance", runner.mean_acceptance()},
              {"stages", runner.stages()},
              {"shakes", shakes},
              {"unsettled_shakes", unsettled},
              {"history", thin_history(runner.history())},
              {"max_overlap_d", std::max(0.0, worst) / d_min},
              {"time_s", time}};
  const std::string settled =
      period > 0.0 ? fmt::format("compressed from a period of {:.4g} d to {:.4g} d", placed_period, period)
                   : fmt::format("{} of {} shakes settled", shakes.size() - unsettled, shakes.size());
  out.summary = fmt::format("pack (monte-carlo): {} spheres in a {}, {} cycles ({:.0f} per s), acceptance {:.2f}, {}, "
                            "no overlap",
                            x.size(), container.kind(), runner.cycles(), out.info["cycles_per_second"].get<double>(),
                            out.info["mean_acceptance"].get<double>(), settled);
  return out;
}

}  // namespace bedforge::packer
