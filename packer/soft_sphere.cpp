#include "packer/soft_sphere.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>

#include "core/error.hpp"
#include "packer/contact_forces.hpp"
#include "packer/generation.hpp"
#include "packer/soft_sphere_faithful.hpp"
#include "packer/soft_sphere_accelerated.hpp"

namespace bedforge::packer {

SoftSphereParams read_soft_sphere_params(SceneSection& s) {
  SoftSphereParams p;
  const Range positive = Range::positive();
  p.mode = s.choice("mode", "accelerated", {"accelerated", "faithful"}) == "faithful" ? SoftSphereParams::Mode::faithful
                                                                                        : SoftSphereParams::Mode::accelerated;
  p.initial_void_fraction = s.number("initial_void_fraction", p.initial_void_fraction, Range::open(0.0, 1.0));
  p.stiffness_step = s.number("stiffness_step", p.stiffness_step, positive);
  p.gravity_step_increment = s.number("gravity_step_increment", p.gravity_step_increment, positive);
  p.overlap_band_lower_d = s.number("overlap_band_lower_d", p.overlap_band_lower_d, Range::open(0.0, 0.5));
  p.overlap_band_upper_d = s.number("overlap_band_upper_d", p.overlap_band_upper_d, Range::open(0.0, 0.5));
  p.overlap_tolerance_d = s.number("overlap_tolerance_d", p.overlap_tolerance_d, Range::open(0.0, 0.1));
  p.mass_centre_interval = s.integer("mass_centre_interval", p.mass_centre_interval, 1, 1'000'000);
  p.mass_centre_samples = static_cast<int>(s.integer("mass_centre_samples", p.mass_centre_samples, 2, 10'000));
  p.mass_centre_tolerance = s.number("mass_centre_tolerance", p.mass_centre_tolerance, positive);
  p.force_tolerance = s.number("force_tolerance", p.force_tolerance, positive);
  p.final_momentum_bound = s.number("final_momentum_bound", p.final_momentum_bound, Range::non_negative(),
                                    "100 at the default tolerance, x 1e-4 d / tolerance below it");
  if (p.final_momentum_bound > 0.0 && p.final_momentum_bound < 1.0)
    throw InputError(fmt::format("{}: final_momentum_bound = {} is not allowed; allowed: 0 (no bound) or >= 1 "
                                 "(Nesterov's t starts at 1)",
                                 s.name(), p.final_momentum_bound));
  p.max_iterations = s.integer("max_iterations", p.max_iterations, 1, 1'000'000'000'000);
  p.max_recoveries = static_cast<int>(s.integer("max_recoveries", p.max_recoveries, 0, 60));
  // At most half a diameter, so a periodic side of 3 diameters holds each pair once.
  p.neighbour_skin_d = s.number("neighbour_skin_d", p.neighbour_skin_d, Range{0.0, 0.5, true, false});
  // Random close packing (0.36) is as far as compression from random positions goes.
  p.target_void_fraction = s.number("target_void_fraction", p.target_void_fraction, Range{0.36, 1.0, false, true},
                                    "none (the period is container.period_z_d)");
  if (p.overlap_band_lower_d >= p.overlap_band_upper_d)
    throw InputError(fmt::format("{}: overlap_band_lower_d = {} is not below overlap_band_upper_d = {}; allowed: "
                                 "lower < upper",
                                 s.name(), p.overlap_band_lower_d, p.overlap_band_upper_d));
  if (p.overlap_tolerance_d >= p.overlap_band_lower_d)
    throw InputError(fmt::format("{}: overlap_tolerance_d = {} is not below overlap_band_lower_d = {}; allowed: "
                                 "tolerance < lower band",
                                 s.name(), p.overlap_tolerance_d, p.overlap_band_lower_d));
  return p;
}

nlohmann::json to_json(const SoftSphereParams& p) {
  return {{"mode", p.mode == SoftSphereParams::Mode::faithful ? "faithful" : "accelerated"},
          {"initial_void_fraction", p.initial_void_fraction},
          {"stiffness_step", p.stiffness_step},
          {"gravity_step_increment", p.gravity_step_increment},
          {"overlap_band_lower_d", p.overlap_band_lower_d},
          {"overlap_band_upper_d", p.overlap_band_upper_d},
          {"overlap_tolerance_d", p.overlap_tolerance_d},
          {"mass_centre_interval", p.mass_centre_interval},
          {"mass_centre_samples", p.mass_centre_samples},
          {"mass_centre_tolerance", p.mass_centre_tolerance},
          {"force_tolerance", p.force_tolerance},
          {"final_momentum_bound", p.final_momentum_bound},
          {"max_iterations", p.max_iterations},
          {"max_recoveries", p.max_recoveries},
          {"neighbour_skin_d", p.neighbour_skin_d},
          {"target_void_fraction", p.target_void_fraction > 0.0 ? nlohmann::json(p.target_void_fraction) : nullptr}};
}

SoftSphereSettings resolve(const SoftSphereParams& p, double d_ref_m, double d_min_m) {
  const double d_min = d_min_m / d_ref_m;  // smallest diameter in packing units
  return {p, p.overlap_band_lower_d * d_min, p.overlap_band_upper_d * d_min, p.overlap_tolerance_d * d_min,
          p.neighbour_skin_d * d_min, d_min};
}

PackResult pack_soft_sphere(const SoftSphereParams& params, const SizeDistribution& sizes, const Container& container,
                            long long count, std::uint64_t seed, Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const double d_ref = sizes.sauter_mean();
  const SoftSphereSettings p = resolve(params, d_ref, sizes.smallest());
  const auto box = container.scaled(1.0 / d_ref);

  Rng rng(seed);
  const std::vector<double> d = sizes.sample(count, rng);
  Spheres s;
  for (double di : d) {
    s.r.push_back(0.5 * di / d_ref);
    s.w.push_back(std::pow(di / d_ref, 3));
  }
  // A periodic section starts in a period long enough for the initial void fraction and is
  // compressed to its own, or to the one that gives the spheres drawn the target void fraction.
  const double period = params.target_void_fraction > 0.0
                            ? total_volume(s) / ((1.0 - params.target_void_fraction) * box->cross_section_area())
                            : box->axial_period();
  if (period > 0.0) box->set_axial_period(std::max(period, initial_height(s, *box, params.initial_void_fraction)));
  const Generated gen = generate_initial_bed(s, *box, params.initial_void_fraction, rng);

  RunLog log(params.max_iterations, progress);
  const nlohmann::json end = params.mode == SoftSphereParams::Mode::faithful ? run_faithful(s, *box, p, log)
                                                                              : run_accelerated(s, *box, period, p, log);
  progress.finish();

  // Check what the bed promises before anyone sees it.
  NeighbourList nl(p.skin);
  nl.build(s.x, s.r, *box);
  Contacts con;
  evaluate_contacts(s, nl, *box, con);
  const bool periodic_axis = box->axial_period() > 0.0;
  double floor_gap = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!s.x[i].allFinite()) throw ConvergenceError(fmt::format("sphere {} has a non-finite position", i));
    if (!periodic_axis) floor_gap = std::max(floor_gap, s.r[i] - s.x[i].z());
  }
  if (!(con.max_pair_overlap < p.tolerance && con.max_wall_overlap < p.tolerance && floor_gap < p.tolerance))
    throw ConvergenceError(fmt::format("packed bed fails its tolerance {} d: pair overlap {:.3g} d, wall overlap "
                                       "{:.3g} d, floor penetration {:.3g} d",
                                       params.overlap_tolerance_d, con.max_pair_overlap / p.d_min,
                                       con.max_wall_overlap / p.d_min, floor_gap / p.d_min));
  // Without gravity (a periodic section) there is no weight to balance: the residual is 0 by definition.
  const double kappa = end.value("stiffness_ratio", 0.0);
  const auto [res_rms, res_max] = periodic_axis ? std::pair{0.0, 0.0} : force_residual(s, con, kappa);

  PackResult out;
  std::unique_ptr<Container> packed = container.scaled(1.0);
  if (params.target_void_fraction > 0.0) packed->set_axial_period(period * d_ref);
  out.bed.container = std::move(packed);
  for (std::size_t i = 0; i < s.size(); ++i) {
    out.bed.centres.push_back(box->periodicity().wrapped(s.x[i]) * d_ref);
    out.bed.diameters.push_back(d[gen.order[i]]);
  }
  nlohmann::json run = log.to_json();
  out.info = {{"algorithm", "soft-sphere"},
              {"parameters", to_json(params)},
              {"reference_diameter_m", d_ref},
              {"smallest_diameter_m", sizes.smallest()},
              {"initial_height_d", gen.initial_height},
              {"iterations", run["iterations"]},
              {"stages", run["stages"]},
              {"recoveries", run["recoveries"]},
              {"threads", run["threads"]},
              {"history", run["history"]},
              {"end_state", end},
              {"max_pair_overlap_d", con.max_pair_overlap / p.d_min},
              {"max_wall_overlap_d", con.max_wall_overlap / p.d_min},
              {"overlap_tolerance_d", params.overlap_tolerance_d},
              {"force_residual_rms", res_rms},
              {"force_residual_max", res_max},
              {"time_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}};
  out.summary = fmt::format("pack (soft-sphere {}): {} spheres, {} iterations, max overlap {:.2g} d (tol {:.2g}), "
                            "residual {:.2g}",
                            params.mode == SoftSphereParams::Mode::faithful ? "faithful" : "accelerated", s.size(),
                            run["iterations"].get<long>(), con.max_pair_overlap / p.d_min, params.overlap_tolerance_d,
                            res_rms);
  return out;
}

}  // namespace bedforge::packer
