#include "packer/soft_sphere_faithful.hpp"

#include <cmath>

#include "core/parallel.hpp"
#include "packer/mass_centre_monitor.hpp"

namespace bedforge::packer {

namespace {

enum class Stage { initial, intermediate, final_ };
const char* name(Stage s) { return s == Stage::initial ? "initial" : s == Stage::intermediate ? "intermediate" : "final"; }

// Everything the iteration depends on besides the positions, so a divergence can return to a
// known good state (with the positions saved beside it).
struct State {
  Stage stage = Stage::initial;
  double cg = 0.0;
  long stage_iterations = 0;
  MassCentreMonitor mass_centre;
};

}  // namespace

nlohmann::json run_faithful(Spheres& s, const Container& container, const SoftSphereSettings& p, RunLog& log) {
  const SoftSphereParams& g = p.given;
  const std::size_t n = s.size();
  const double total_weight = deterministic_sum(n, [&](std::size_t i) { return s.w[i]; });
  NeighbourList nl(p.skin);
  Contacts con;
  double ck = g.stiffness_step;

  State st{Stage::initial, 0.0, 0, MassCentreMonitor(g.mass_centre_samples, g.mass_centre_tolerance)};
  State checkpoint = st;
  std::vector<Eigen::Vector3d> checkpoint_x = s.x;
  int rising = 0;  // iterations of the current window in which Phi rose
  double prev_energy = 0.0, prev_height = 0.0, prev_cg = 0.0;
  bool have_prev = false;
  log.begin_stage(name(st.stage));

  for (long window_pos = 0;; ++window_pos) {
    nl.update(s.x, s.r, container);
    evaluate_contacts(s, nl, container, con);
    const double height = deterministic_sum(n, [&](std::size_t i) { return s.w[i] * s.x[i].z(); });
    const bool finite = std::isfinite(con.elastic_energy) && std::isfinite(height);
    if (have_prev && finite) {
      const double before = ck * prev_energy + prev_cg * prev_height;
      const double after = ck * con.elastic_energy + prev_cg * height;
      if (after > before + 1e-11 * (std::abs(before) + 1e-300)) ++rising;
    }

    // Window boundary: judge stability, keep a checkpoint, sample the mass centre.
    if (!finite || window_pos % g.mass_centre_interval == 0) {
      if (!finite || rising > g.mass_centre_interval * 3 / 10) {
        if (static_cast<int>(log.recoveries()) >= g.max_recoveries)
          throw ConvergenceError(fmt::format(
              "the faithful packer diverged {} times in the {} stage (C_k reduced to {:.3g}); lower "
              "packing.soft_sphere.stiffness_step (published value 0.3)",
              log.recoveries() + 1, name(st.stage), ck));
        log.recovery({{"reason", finite ? "mass-weighted energy kept rising: step beyond the stability limit"
                                        : "non-finite positions"},
                      {"C_k_before", ck},
                      {"C_k_after", ck / 2}});
        ck /= 2;
        st = checkpoint;
        s.x = checkpoint_x;
        if (log.stage() != name(st.stage)) log.begin_stage(name(st.stage));
        rising = 0;
        have_prev = false;
        window_pos = 0;
        continue;
      }
      checkpoint = st;
      checkpoint_x = s.x;
      rising = 0;
    }
    if (st.stage_iterations % g.mass_centre_interval == 0) {
      st.mass_centre.add(height / total_weight);
      log.record({{"max_pair_overlap_d", con.max_pair_overlap / p.d_min},
                  {"max_wall_overlap_d", con.max_wall_overlap / p.d_min},
                  {"mass_centre", height / total_weight},
                  {"C_g", st.cg}});
      log.show(fmt::format("faithful, {} stage, iteration {}, max overlap {:.2e} d, C_g {:.3g}", name(st.stage),
                           log.iterations(), con.max_pair_overlap / p.d_min, st.cg));
    }

    // Stage transitions.
    const bool overlaps_ok = con.max_pair_overlap < p.tolerance && con.max_wall_overlap < p.tolerance;
    const bool settled = st.stage_iterations % g.mass_centre_interval == 0 && st.mass_centre.settled();
    auto enter = [&](Stage next, double cg) {
      st.stage = next;
      st.cg = cg;
      st.stage_iterations = 0;
      st.mass_centre.clear();
      if (log.stage() != name(next)) log.begin_stage(name(next));
    };
    if (st.stage == Stage::initial && overlaps_ok) {
      enter(Stage::intermediate, 0.0);
    } else if (st.stage == Stage::initial && settled) {
      // Stalled with overlaps left: an unstable equilibrium (see lift_floor_spheres).
      const std::size_t lifted = lift_floor_spheres(s, 0.01 * p.d_min, log.iterations());
      st.mass_centre.clear();
      log.recovery({{"reason", "stalled at an unstable equilibrium with overlaps: floor spheres lifted"}, {"spheres", lifted}});
      if (static_cast<int>(log.recoveries()) > 10 * g.max_recoveries)
        throw ConvergenceError("the faithful initial stage keeps stalling with overlapping spheres");
    } else if (st.stage == Stage::intermediate && settled) {
      enter(Stage::final_, 0.5 * st.cg);
    } else if (st.stage == Stage::final_ && settled) {
      if (overlaps_ok) break;
      enter(Stage::final_, 0.5 * st.cg);
    }

    // Eq. (4), Jacobi update, then the rigid floor.
    log.tick([&] {
      return fmt::format("the faithful {} stage (max overlap {:.3g} d, C_g {:.3g})", name(st.stage),
                         con.max_pair_overlap / p.d_min, st.cg);
    });
    const double cg = st.cg;
    parallel_for(n, [&](std::size_t i) {
      Eigen::Vector3d& xi = s.x[i];
      xi += ck * con.push[i];
      xi.z() -= cg * s.w[i];
      xi.z() = std::max(xi.z(), s.r[i]);
    });
    prev_energy = con.elastic_energy;
    prev_height = height;
    prev_cg = cg;
    have_prev = true;
    ++st.stage_iterations;
    if (st.stage == Stage::intermediate) {  // Eq. (7)
      if (con.max_pair_overlap < p.band_lower) st.cg += g.gravity_step_increment;
      else if (con.max_pair_overlap > p.band_upper) st.cg = std::max(0.0, st.cg - g.gravity_step_increment);
    }
  }
  const double kappa = st.cg > 0 ? ck / st.cg : 0.0;
  return {{"C_k", ck}, {"C_g", st.cg}, {"stiffness_ratio", kappa}};
}

}  // namespace bedforge::packer
