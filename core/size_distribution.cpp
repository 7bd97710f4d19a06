#include "core/size_distribution.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "core/error.hpp"

namespace bedforge {

namespace {

constexpr double kPi = std::numbers::pi;

double normal_pdf(double x, double mu, double sigma) {
  const double t = (x - mu) / sigma;
  return std::exp(-0.5 * t * t);
}

// Unnormalised density of the untruncated continuous distribution, and its parameters.
struct Density {
  bool log;
  double mu, sigma;
  double operator()(double d) const {
    if (!log) return normal_pdf(d, mu, sigma);
    return d > 0 ? normal_pdf(std::log(d), mu, sigma) / d : 0.0;
  }
};

Density density_of(const SizeDistribution& s) {
  if (s.kind == SizeDistribution::Kind::normal) return {false, s.mean_m, s.std_m};
  const double var_log = std::log1p((s.std_m * s.std_m) / (s.mean_m * s.mean_m));
  return {true, std::log(s.mean_m) - 0.5 * var_log, std::sqrt(var_log)};
}

// E[D^k] of the truncated distribution by composite Gauss-Legendre (smooth integrand: the
// error is far below anything a bed can resolve).
double truncated_moment(const SizeDistribution& s, int k) {
  static constexpr double x[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static constexpr double w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  const Density f = density_of(s);
  const int panels = 400;
  const double h = (s.max_m - s.min_m) / panels;
  double num = 0, den = 0;
  for (int p = 0; p < panels; ++p) {
    const double c = s.min_m + (p + 0.5) * h;
    for (int q = 0; q < 4; ++q) {
      const double d = c + 0.5 * h * x[q];
      const double fd = f(d) * w[q];
      num += fd * std::pow(d, k);
      den += fd;
    }
  }
  return num / den;
}

double discrete_moment(const SizeDistribution& s, int k) {
  double m = 0;
  for (size_t i = 0; i < s.diameters_m.size(); ++i) m += s.number_fractions[i] * std::pow(s.diameters_m[i], k);
  return m;
}

double moment(const SizeDistribution& s, int k) {
  switch (s.kind) {
    case SizeDistribution::Kind::monodisperse:
    case SizeDistribution::Kind::discrete:
      return discrete_moment(s, k);
    default:
      return truncated_moment(s, k);
  }
}

}  // namespace

const char* SizeDistribution::kind_name() const {
  switch (kind) {
    case Kind::monodisperse: return "monodisperse";
    case Kind::discrete: return "discrete";
    case Kind::normal: return "normal";
    case Kind::lognormal: return "lognormal";
  }
  return "?";
}

double SizeDistribution::sauter_mean() const { return moment(*this, 3) / moment(*this, 2); }

double SizeDistribution::smallest() const {
  if (kind == Kind::normal || kind == Kind::lognormal) return min_m;
  return *std::min_element(diameters_m.begin(), diameters_m.end());
}

double SizeDistribution::largest() const {
  if (kind == Kind::normal || kind == Kind::lognormal) return max_m;
  return *std::max_element(diameters_m.begin(), diameters_m.end());
}

double SizeDistribution::mean_volume() const { return kPi / 6.0 * moment(*this, 3); }

std::vector<double> SizeDistribution::sample(long long count, Rng& rng) const {
  std::vector<double> d;
  d.reserve(static_cast<size_t>(count));
  if (kind == Kind::monodisperse || kind == Kind::discrete) {
    // Largest-remainder rounding: counts sum to `count` and each is within 1 of count * fraction.
    const size_t k = diameters_m.size();
    std::vector<long long> n(k);
    std::vector<std::pair<double, size_t>> remainder(k);
    long long assigned = 0;
    for (size_t i = 0; i < k; ++i) {
      const double exact = static_cast<double>(count) * number_fractions[i];
      n[i] = static_cast<long long>(std::floor(exact));
      assigned += n[i];
      remainder[i] = {exact - std::floor(exact), i};
    }
    std::stable_sort(remainder.begin(), remainder.end(), [](auto a, auto b) { return a.first > b.first; });
    for (size_t r = 0; assigned < count; ++r, ++assigned) ++n[remainder[r % k].second];
    for (size_t i = 0; i < k; ++i) d.insert(d.end(), static_cast<size_t>(n[i]), diameters_m[i]);
    for (size_t i = d.size(); i > 1; --i) std::swap(d[i - 1], d[rng.below(i)]);  // Fisher-Yates
    return d;
  }
  const Density f = density_of(*this);
  while (static_cast<long long>(d.size()) < count) {
    const double z = f.mu + f.sigma * rng.normal();
    const double v = f.log ? std::exp(z) : z;
    if (v >= min_m && v <= max_m) d.push_back(v);
  }
  return d;
}

nlohmann::json SizeDistribution::to_json() const {
  nlohmann::json j{{"distribution", kind_name()}, {"sauter_mean_m", sauter_mean()}, {"smallest_m", smallest()},
                   {"largest_m", largest()}};
  if (kind == Kind::monodisperse || kind == Kind::discrete) {
    j["diameters_m"] = diameters_m;
    j["number_fractions"] = number_fractions;
  } else {
    j["mean_m"] = mean_m;
    j["std_m"] = std_m;
    j["min_m"] = min_m;
    j["max_m"] = max_m;
  }
  return j;
}

SizeDistribution read_size_distribution(SceneSection& p) {
  SizeDistribution s;
  const std::string kind = p.choice("distribution", "monodisperse", {"monodisperse", "discrete", "normal", "lognormal"});
  const Range positive = Range::positive();
  if (kind == "monodisperse") {
    s.kind = SizeDistribution::Kind::monodisperse;
    s.diameters_m = {p.number("diameter_m", 1e-3, positive)};
    s.number_fractions = {1.0};
  } else if (kind == "discrete") {
    s.kind = SizeDistribution::Kind::discrete;
    s.diameters_m = p.numbers("diameters_m", positive);
    if (s.diameters_m.empty())
      throw InputError(fmt::format("{} is required for a discrete mixture: an array of diameters in metres",
                                   p.key_path("diameters_m")));
    const bool by_number = p.has("number_fractions"), by_volume = p.has("volume_fractions");
    if (by_number == by_volume)
      throw InputError(fmt::format("{}: give exactly one of number_fractions or volume_fractions (one per diameter)",
                                   p.name()));
    const std::string key = by_number ? "number_fractions" : "volume_fractions";
    std::vector<double> f = p.numbers(key, Range::non_negative());
    if (f.size() != s.diameters_m.size())
      throw InputError(fmt::format("{}: got {} values for {} diameters; allowed: one fraction per diameter",
                                   p.key_path(key), f.size(), s.diameters_m.size()));
    const double sum = std::accumulate(f.begin(), f.end(), 0.0);
    if (std::abs(sum - 1.0) > 1e-6)
      throw InputError(fmt::format("{}: fractions sum to {}; allowed: fractions that sum to 1 (within 1e-6)",
                                   p.key_path(key), sum));
    if (by_volume)  // a volume fraction phi_k holds phi_k / d_k^3 spheres per unit volume
      for (size_t i = 0; i < f.size(); ++i) f[i] /= std::pow(s.diameters_m[i], 3);
    const double norm = std::accumulate(f.begin(), f.end(), 0.0);
    for (double& v : f) v /= norm;
    s.number_fractions = f;
  } else {
    s.kind = kind == "normal" ? SizeDistribution::Kind::normal : SizeDistribution::Kind::lognormal;
    s.mean_m = p.number("mean_m", 0.0, positive, "none (required)");
    s.std_m = p.number("std_m", 0.0, positive, "none (required)");
    if (!p.has("mean_m") || !p.has("std_m"))
      throw InputError(fmt::format("{}: a {} distribution needs mean_m and std_m (metres, > 0)", p.name(), kind));
    s.min_m = p.number("min_m", std::max(s.mean_m - 3 * s.std_m, 0.1 * s.mean_m), positive,
                       "mean_m - 3 std_m, at least 0.1 mean_m");
    s.max_m = p.number("max_m", s.mean_m + 3 * s.std_m, positive, "mean_m + 3 std_m");
    if (s.min_m >= s.max_m)
      throw InputError(fmt::format("{}: min_m = {} is not below max_m = {}; allowed: 0 < min_m < max_m", p.name(),
                                   s.min_m, s.max_m));
    // The cut-offs must keep a usable part of the distribution, or sampling would never end.
    const Density f = density_of(s);
    double inside = 0, total = 0;
    const double lo = std::min(s.min_m, s.mean_m - 8 * s.std_m), hi = std::max(s.max_m, s.mean_m + 8 * s.std_m);
    for (int i = 0; i < 20000; ++i) {
      const double d = lo + (i + 0.5) * (hi - lo) / 20000;
      total += f(d);
      if (d >= s.min_m && d <= s.max_m) inside += f(d);
    }
    if (!(inside > 1e-4 * total))
      throw InputError(fmt::format("{}: cut-offs [{}, {}] m keep almost none of the distribution (mean {} m, std {} m);"
                                   " allowed: cut-offs that contain at least 0.01 % of it",
                                   p.name(), s.min_m, s.max_m, s.mean_m, s.std_m));
  }
  return s;
}

}  // namespace bedforge
