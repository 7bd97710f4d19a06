#include "core/container.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "core/error.hpp"

namespace bedforge {

double Cylinder::cross_section_area() const { return std::numbers::pi * radius_ * radius_; }

int Cylinder::wall_contacts(const Eigen::Vector3d& c, double r, WallContact* out) const {
  const double rho = std::sqrt(c.x() * c.x() + c.y() * c.y());  // hypot's overflow care costs 10 % of a packing
  const double overlap = rho + r - radius_;
  if (overlap <= 0.0) return 0;
  // A centre exactly on the axis only overlaps when the sphere is wider than the tube, which the
  // scene check forbids; any direction is then as good as another.
  const Eigen::Vector3d n = rho > 0.0 ? Eigen::Vector3d(-c.x() / rho, -c.y() / rho, 0.0) : Eigen::Vector3d(1, 0, 0);
  out[0] = {overlap, n};
  return 1;
}

Eigen::Vector2d Cylinder::sample_centre(Rng& rng, double r) const {
  // Salvat et al. (2005), generation stage: rho = (R - d/2) sqrt(Rnd), theta = 2 pi Rnd.
  const double rho = std::max(radius_ - r, 0.0) * std::sqrt(rng.uniform());
  const double theta = 2.0 * std::numbers::pi * rng.uniform();
  return {rho * std::cos(theta), rho * std::sin(theta)};
}

std::unique_ptr<Container> Cylinder::scaled(double factor) const { return std::make_unique<Cylinder>(radius_ * factor); }

nlohmann::json Cylinder::to_json() const { return {{"type", "cylinder"}, {"diameter", 2.0 * radius_}}; }

std::unique_ptr<Container> read_container(SceneSection& s, double d_ref_m, double d_max_m) {
  const std::string type = s.choice("type", "cylinder", {"cylinder"});
  const auto diameter = s.optional_length("diameter", Range::positive());
  if (!diameter)
    throw InputError(fmt::format("{0}.diameter_d (aspect ratio D/d) or {0}.diameter_m is required", s.name()));
  const double D = diameter->metres(d_ref_m);
  if (D < d_max_m * (1.0 - 1e-12))
    throw InputError(fmt::format("{}: the container ({} m, D/d = {}) is narrower than the largest particle ({} m); "
                                 "allowed: D >= largest diameter",
                                 s.key_path(diameter->unit == Length::Unit::metres ? "diameter_m" : "diameter_d"), D,
                                 D / d_ref_m, d_max_m));
  return std::make_unique<Cylinder>(0.5 * D);
}

std::unique_ptr<Container> container_from_json(const nlohmann::json& j) {
  const std::string type = j.value("type", "");
  if (type == "cylinder" && j.contains("diameter") && j["diameter"].is_number() && j["diameter"].get<double>() > 0)
    return std::make_unique<Cylinder>(0.5 * j["diameter"].get<double>());
  throw InputError(fmt::format("unrecognised container record {}; allowed: {{\"type\":\"cylinder\",\"diameter\":D>0}}",
                               j.dump()));
}

}  // namespace bedforge
