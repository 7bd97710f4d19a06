#include "packer/soft_sphere_accelerated.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include "core/parallel.hpp"
#include "packer/mass_centre_monitor.hpp"

namespace bedforge::packer {

namespace {

// State of the iterate at a window boundary, where the stopping tests are made.
struct Relaxed {
  Contacts contacts;
  bool settled = false;       // the mass-centre test passed
  double residual_rms = 0.0;  // net force / own weight, rms
};

class AcceleratedDescent {
 public:
  AcceleratedDescent(Spheres& s, const Container& c, const SoftSphereSettings& p, RunLog& log)
      : s_(s), c_(c), p_(p), log_(log), nl_(p.skin), floor_(c.axial_period() == 0.0),
        requested_(0.5 * p.given.stiffness_step), step_(requested_) {}

  // Smallest C_k the stability limit allowed (C_k = 2 x the momentum step).
  double smallest_stiffness_step() const { return 2.0 * smallest_; }
  long neighbour_list_builds() const { return nl_.builds(); }

  // Minimises C_k E_el + C_g sum w_i z_i (C_g = C_k / kappa, or 0 without gravity) until
  // `done`; no sphere moves more than `max_step` in one iteration. Nesterov's t is held at or
  // below `momentum_bound` (0: unbounded, restarts alone reset it).
  Relaxed relax(double kappa, bool gravity, double max_step, double momentum_bound,
                const std::function<bool(const Relaxed&)>& done) {
    const std::size_t n = s_.size();
    const double total_weight = deterministic_sum(n, [&](std::size_t i) { return s_.w[i]; });
    MassCentreMonitor mass_centre(p_.given.mass_centre_samples, p_.given.mass_centre_tolerance);
    std::vector<Eigen::Vector3d> x = s_.x, good = s_.x, next(n);  // iterate x_k; s_.x holds y_k
    std::vector<double> uphill(n);
    double t = 1.0;
    Relaxed r;  // at y, every iteration
    for (long k = 0;; ++k) {
      nl_.update(s_.x, s_.r, c_);
      evaluate_contacts(s_, nl_, c_, r.contacts);
      if (!std::isfinite(r.contacts.elastic_energy)) {
        if (static_cast<int>(log_.recoveries()) >= p_.given.max_recoveries)
          throw ConvergenceError(fmt::format("the accelerated packer diverged {} times in the {} stage; lower "
                                             "packing.soft_sphere.stiffness_step",
                                             log_.recoveries() + 1, log_.stage()));
        log_.recovery({{"reason", "non-finite positions"}, {"C_k_before", step_}, {"C_k_after", step_ / 2}});
        step_ /= 2;
        x = s_.x = good;
        t = 1.0;
        mass_centre.clear();
        continue;
      }
      if (k % kStabilityInterval == 0) limit_step();
      if (k % p_.given.mass_centre_interval == 0) {
        // Judge the iterate x, not the extrapolated y: at high stiffness the momentum step alone
        // would show as force.
        good = x;
        Relaxed at_x;
        std::swap(s_.x, x);
        nl_.update(s_.x, s_.r, c_);
        evaluate_contacts(s_, nl_, c_, at_x.contacts);
        const double height = deterministic_sum(n, [&](std::size_t i) { return s_.w[i] * s_.x[i].z(); }) / total_weight;
        // Along a periodic axis nothing moves the mass centre (the pair forces cancel), so the
        // test watches the elastic energy instead: it stops falling when the spheres cannot part.
        mass_centre.add(floor_ ? height : at_x.contacts.elastic_energy);
        at_x.settled = mass_centre.settled();
        at_x.residual_rms = gravity ? force_residual(s_, at_x.contacts, kappa).first : 0.0;
        std::swap(s_.x, x);
        log_.record({{"max_pair_overlap_d", at_x.contacts.max_pair_overlap / p_.d_min},
                     {"max_wall_overlap_d", at_x.contacts.max_wall_overlap / p_.d_min},
                     {"stiffness_ratio", kappa},
                     {"mass_centre", height},
                     {"force_residual_rms", at_x.residual_rms}});
        log_.show(fmt::format("accelerated, {} stage, iteration {}, max overlap {:.2e} d, residual {:.2e}", log_.stage(),
                              log_.iterations(), at_x.contacts.max_pair_overlap / p_.d_min, at_x.residual_rms));
        if (done(at_x)) {
          s_.x = x;
          return at_x;
        }
      }
      log_.tick([&] {
        return fmt::format("the accelerated {} stage (max overlap {:.3g} d)", log_.stage(),
                           r.contacts.max_pair_overlap / p_.d_min);
      });

      // Descent step from y (Eq. 4 with C_g = C_k / kappa), floor, cap; then momentum.
      const double cg = gravity ? step_ / kappa : 0.0;  // C_g = C_k / kappa
      parallel_for(n, [&](std::size_t i) {
        Eigen::Vector3d move = step_ * r.contacts.push[i];
        move.z() -= cg * s_.w[i];
        const double len = move.norm();
        if (len > max_step) move *= max_step / len;
        next[i] = s_.x[i] + move;
        if (floor_) next[i].z() = std::max(next[i].z(), s_.r[i]);
        uphill[i] = move.dot(next[i] - x[i]);
      });
      // Restart when the step from y disagrees with the direction travelled (gradient restart).
      if (deterministic_sum(n, [&](std::size_t i) { return uphill[i]; }) < 0.0) t = 1.0;
      const double t_next = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * t * t)), beta = (t - 1.0) / t_next;
      t = momentum_bound > 0.0 ? std::min(t_next, momentum_bound) : t_next;
      parallel_for(n, [&](std::size_t i) {
        Eigen::Vector3d y = next[i] + beta * (next[i] - x[i]);
        if (floor_) y.z() = std::max(y.z(), s_.r[i]);
        x[i] = next[i];
        s_.x[i] = y;
      });
    }
  }

 private:
  Spheres& s_;
  const Container& c_;
  const SoftSphereSettings& p_;
  RunLog& log_;
  NeighbourList nl_;
  bool floor_;  // a rigid floor at z = 0 (none along a periodic axis)
  double requested_, step_, smallest_ = requested_;

  // Momentum descent is stable for steps below 1 / lambda_max of the contact stiffness; the
  // contact network changes as the bed moves, so the limit is re-measured every
  // kStabilityInterval iterations and the step kept below it, whatever C_k was asked for.
  static constexpr long kStabilityInterval = 1000;
  void limit_step() {
    const double lambda = contact_stiffness_eigenvalue(s_, nl_, c_, 20);
    const double limit = lambda > 0.0 ? 0.8 / lambda : requested_;
    const double step = std::min(requested_, limit);
    smallest_ = std::min(smallest_, step);
    step_ = step;
  }
};

// Scales the z coordinates with the period, from the container's period to `next`.
void set_period(Spheres& s, Container& container, double next) {
  const double ratio = next / container.axial_period();
  for (auto& x : s.x) x.z() *= ratio;
  container.set_axial_period(next);
}

// A periodic section: no floor and no gravity. The spheres, generated loose in a longer period,
// are parted, then the period is shortened in small steps (the z coordinates scaled with it) and
// the spheres parted again after each, down to the period asked for. A period shortened at once
// jams looser: at a = 5 a single quench stalled with overlaps at void fraction 0.429 and parted
// at 0.44 (docs/findings.md, 2026-11-28, session 37). Where the spheres jam before the period
// asked for, the period is let out by 1 %, every sphere moved by up to kTap along each axis in a fixed
// pseudo-random direction (a tap), and the compression resumed, up to max_recoveries taps.
// kTap = 0.3 d is a calibration: taps of 0.1 d left the spheres in the jam they came from, and
// a = 5 slices of 105 spheres at the full beds' central void fraction jammed for 6 seeds of 9;
// 0.3 d reached all 9 (docs/findings.md, 2026-12-01), and on beds not used to set it more
// seeds reached their targets, none fewer.
nlohmann::json compress_period(Spheres& s, Container& container, double period, const SoftSphereSettings& p,
                               RunLog& log) {
  constexpr double kStep = 0.002;  // relative shortening of the period per round
  constexpr double kLetOut = 0.01, kTap = 0.3;
  const double tol = p.tolerance;
  AcceleratedDescent descent(s, container, p, log);
  log.begin_stage("compression");
  for (int taps = 0;;) {
    const Relaxed e = descent.relax(1.0, false, 0.5 * p.band_upper, 0.0, [&](const Relaxed& q) {
      return (q.contacts.max_pair_overlap < tol && q.contacts.max_wall_overlap < tol) || q.settled;
    });
    const double h = container.axial_period();
    if (e.contacts.max_pair_overlap >= tol || e.contacts.max_wall_overlap >= tol) {
      const double eps = 1.0 - total_volume(s) / (container.cross_section_area() * h);
      if (taps == p.given.max_recoveries)
        throw ConvergenceError(fmt::format(
            "the spheres jammed before the period reached the one asked for: at {:.4g} d (asked {:.4g} d, void "
            "fraction {:.4f}) overlaps of {:.3g} d (pair) and {:.3g} d (wall) stayed above the tolerance {} d after "
            "{} taps; {}",
            h, period, eps, e.contacts.max_pair_overlap / p.d_min, e.contacts.max_wall_overlap / p.d_min,
            p.given.overlap_tolerance_d, taps,
            p.given.target_void_fraction > 0.0
                ? fmt::format("a packing.soft_sphere.target_void_fraction above {:.4f} (the void fraction it "
                              "jammed at)",
                              eps)
                : "fewer spheres (particles.count) or a longer container.period_z"));
      log.recovery({{"reason", "jammed before the period asked for: let out and tapped"},
                    {"period_d", h},
                    {"void_fraction", eps}});
      set_period(s, container, h * (1.0 + kLetOut));
      ++taps;
      const std::uint64_t salt = 3 * static_cast<std::uint64_t>(taps);
      for (std::size_t i = 0; i < s.size(); ++i) {
        const Eigen::Vector3d u(hashed_uniform(i, salt), hashed_uniform(i, salt + 1), hashed_uniform(i, salt + 2));
        s.x[i] += kTap * p.d_min * (2.0 * u - Eigen::Vector3d::Ones());
      }
      continue;
    }
    if (h <= period) break;
    set_period(s, container, std::max(period, h * (1.0 - kStep)));
  }
  return {{"stiffness_ratio", 0.0},
          {"smallest_C_k", descent.smallest_stiffness_step()},
          {"neighbour_list_builds", descent.neighbour_list_builds()}};
}

}  // namespace

nlohmann::json run_accelerated(Spheres& s, Container& container, double period, const SoftSphereSettings& p,
                               RunLog& log) {
  if (period > 0.0) return compress_period(s, container, period, p, log);
  const double tol = p.tolerance;
  AcceleratedDescent descent(s, container, p, log);
  const double max_step = 0.5 * p.band_upper;

  log.begin_stage("expansion");
  for (std::uint64_t stalls = 0;; ++stalls) {
    auto overlaps_ok = [&](const Relaxed& q) {
      return q.contacts.max_pair_overlap < tol && q.contacts.max_wall_overlap < tol;
    };
    const Relaxed e =
        descent.relax(1.0, false, max_step, 0.0, [&](const Relaxed& q) { return overlaps_ok(q) || q.settled; });
    if (overlaps_ok(e)) break;
    // Stalled with overlaps left: an unstable equilibrium (see lift_floor_spheres).
    const std::size_t lifted = lift_floor_spheres(s, 0.01 * p.d_min, stalls);
    log.recovery({{"reason", "stalled at an unstable equilibrium with overlaps: floor spheres lifted"}, {"spheres", lifted}});
    if (stalls > 10 * static_cast<std::uint64_t>(p.given.max_recoveries))
      throw ConvergenceError("the accelerated expansion stage keeps stalling with overlapping spheres");
  }

  // Compaction. The largest contact force of a settled frictionless bed grows with its height H
  // (the column above a bottom sphere), so kappa ~ 5 H / delta starts close to the band; the
  // measured overlap then corrects it.
  log.begin_stage("compaction");
  const double band_mid = 0.5 * (p.band_lower + p.band_upper);
  const double height = total_volume(s) / (0.6 * container.cross_section_area());
  double kappa = 5.0 * std::max(1.0, height) / band_mid;
  Relaxed r;
  for (int round = 0;; ++round) {
    r = descent.relax(kappa, true, max_step, 0.0,
                      [&](const Relaxed& q) { return q.settled || q.residual_rms < p.given.force_tolerance; });
    const double overlap = r.contacts.max_pair_overlap;
    if ((overlap >= p.band_lower && overlap <= p.band_upper) || overlap == 0.0 || round == 8) break;
    kappa *= overlap / band_mid;
  }

  // Final: stiffen so both overlaps fall below half the tolerance, settle, check. Restarts are
  // rare here, so unbounded momentum leaves the slow modes undamped; a bound on t damps them
  // (beta <= 1 - 1.5 / bound), scaled up for tolerances tighter than the default because a
  // stiffer stage needs the momentum to persist longer (measurements: docs/defaults.md).
  const double bound = p.given.final_momentum_bound *
                       std::max(1.0, SoftSphereParams{}.overlap_tolerance_d / p.given.overlap_tolerance_d);
  log.begin_stage("final");
  const double target = 0.5 * tol;
  for (int round = 0;; ++round) {
    const double overlap = std::max(r.contacts.max_pair_overlap, r.contacts.max_wall_overlap);
    if (overlap > target) kappa *= overlap / target;
    // A round ends on the force residual, or on a settled mass centre once the overlaps are within
    // the tolerance: in a tall column (a = 5, N = 1e4) the stiffened bed's mass centre moves too
    // slowly for the monitor while its residual is still 0.5-2 weights, and stiffening again each
    // time it looked settled left the wall overlap at 1.25e-4 d after every round (findings.md).
    r = descent.relax(kappa, true, max_step, bound, [&](const Relaxed& q) {
      return (q.settled && q.contacts.max_pair_overlap < tol && q.contacts.max_wall_overlap < tol) ||
             q.residual_rms < p.given.force_tolerance;
    });
    if (r.contacts.max_pair_overlap < tol && r.contacts.max_wall_overlap < tol) break;
    if (round == 10)
      throw ConvergenceError(fmt::format("the accelerated packer could not bring the overlaps below {} d "
                                         "(pair {:.3g} d, wall {:.3g} d)",
                                         p.given.overlap_tolerance_d, r.contacts.max_pair_overlap / p.d_min,
                                         r.contacts.max_wall_overlap / p.d_min));
  }
  return {{"stiffness_ratio", kappa},
          {"smallest_C_k", descent.smallest_stiffness_step()},
          {"neighbour_list_builds", descent.neighbour_list_builds()}};
}

}  // namespace bedforge::packer
