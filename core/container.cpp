#include "core/container.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "core/error.hpp"

namespace bedforge {

std::unique_ptr<Container> Container::scaled(double factor) const {
  std::unique_ptr<Container> c = scaled_section(factor);
  c->axial_period_ = axial_period_ * factor;
  return c;
}

nlohmann::json Container::to_json() const {
  nlohmann::json j = section_json();
  if (axial_period_ > 0.0) j["period_z"] = axial_period_;
  return j;
}

double Cylinder::cross_section_area() const { return std::numbers::pi * radius_ * radius_; }
double Cylinder::wall_perimeter() const { return 2.0 * std::numbers::pi * radius_; }

int Cylinder::wall_contacts(const Eigen::Vector3d& c, double r, WallContact* out) const {
  const double rho2 = c.x() * c.x() + c.y() * c.y(), inner = radius_ - r;
  // Most spheres are well inside: skip the square root for them (4 % of a packing's time). The
  // margin keeps spheres at the wall, within rounding, on the exact test below.
  if (inner > 0.0 && rho2 < inner * inner * (1.0 - 1e-9)) return 0;
  const double rho = std::sqrt(rho2);  // hypot's overflow care costs 10 % of a packing
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

std::unique_ptr<Container> Cylinder::scaled_section(double factor) const {
  return std::make_unique<Cylinder>(radius_ * factor);
}

nlohmann::json Cylinder::section_json() const { return {{"type", "cylinder"}, {"diameter", 2.0 * radius_}}; }

double Annulus::cross_section_area() const { return std::numbers::pi * (outer_ * outer_ - inner_ * inner_); }
double Annulus::wall_perimeter() const { return 2.0 * std::numbers::pi * (outer_ + inner_); }

int Annulus::wall_contacts(const Eigen::Vector3d& c, double r, WallContact* out) const {
  const double rho = std::sqrt(c.x() * c.x() + c.y() * c.y());
  // Outward radial unit vector; on the axis (deep inside the inner wall) any direction will do.
  const Eigen::Vector3d e = rho > 0.0 ? Eigen::Vector3d(c.x() / rho, c.y() / rho, 0.0) : Eigen::Vector3d(1, 0, 0);
  int n = 0;
  if (const double o = rho + r - outer_; o > 0.0) out[n++] = {o, -e};
  if (const double o = inner_ + r - rho; o > 0.0) out[n++] = {o, e};
  return n;
}

Eigen::Vector2d Annulus::sample_centre(Rng& rng, double r) const {
  // Uniform over the ring of allowed centres: rho^2 uniform between its bounds.
  const double lo = inner_ + r, hi = std::max(outer_ - r, lo);
  const double rho = std::sqrt(lo * lo + (hi * hi - lo * lo) * rng.uniform());
  const double theta = 2.0 * std::numbers::pi * rng.uniform();
  return {rho * std::cos(theta), rho * std::sin(theta)};
}

std::unique_ptr<Container> Annulus::scaled_section(double factor) const {
  return std::make_unique<Annulus>(outer_ * factor, inner_ * factor);
}

nlohmann::json Annulus::section_json() const {
  return {{"type", "annulus"}, {"diameter", 2.0 * outer_}, {"inner_diameter", 2.0 * inner_}};
}

int Box::wall_contacts(const Eigen::Vector3d& c, double r, WallContact* out) const {
  int n = 0;
  if (!px_) {
    if (const double o = r - (c.x() + 0.5 * lx_); o > 0.0) out[n++] = {o, {1, 0, 0}};
    if (const double o = c.x() + r - 0.5 * lx_; o > 0.0) out[n++] = {o, {-1, 0, 0}};
  }
  if (!py_) {
    if (const double o = r - (c.y() + 0.5 * ly_); o > 0.0) out[n++] = {o, {0, 1, 0}};
    if (const double o = c.y() + r - 0.5 * ly_; o > 0.0) out[n++] = {o, {0, -1, 0}};
  }
  return n;
}

Eigen::Vector2d Box::sample_centre(Rng& rng, double r) const {
  const double hx = px_ ? 0.5 * lx_ : std::max(0.5 * lx_ - r, 0.0), hy = py_ ? 0.5 * ly_ : std::max(0.5 * ly_ - r, 0.0);
  const double x = hx * (2.0 * rng.uniform() - 1.0);
  return {x, hy * (2.0 * rng.uniform() - 1.0)};
}

double Box::max_radius() const {
  const double k = 2.0 * Periodicity::kShortestInDiameters;
  return std::min(px_ ? lx_ / k : 0.5 * lx_, py_ ? ly_ / k : 0.5 * ly_);
}

std::unique_ptr<Container> Box::scaled_section(double factor) const {
  return std::make_unique<Box>(lx_ * factor, ly_ * factor, px_, py_);
}

nlohmann::json Box::section_json() const {
  return {{"type", "box"}, {"size_x", lx_}, {"size_y", ly_}, {"periodic_x", px_}, {"periodic_y", py_}};
}

namespace {

// A required length of [container] in metres.
double required_length(SceneSection& s, const std::string& name, double d_ref_m, const std::string& what) {
  const auto l = s.optional_length(name, Range::positive());
  if (!l) throw InputError(fmt::format("{0}.{1}_d or {0}.{1}_m is required: {2}", s.name(), name, what));
  return l->metres(d_ref_m);
}

std::string length_key(SceneSection& s, const std::string& name) {
  return s.key_path(name + (s.has(name + "_m") ? "_m" : "_d"));
}

}  // namespace

std::unique_ptr<Container> read_container(SceneSection& s, double d_ref_m, double d_max_m) {
  const std::string type = s.choice("type", "cylinder", {"cylinder", "annulus", "box"});
  std::unique_ptr<Container> c;
  std::string fit_key;
  if (type == "box") {
    const double lx = required_length(s, "size_x", d_ref_m, "the box width along x");
    const double ly = required_length(s, "size_y", d_ref_m, "the box width along y");
    c = std::make_unique<Box>(lx, ly, s.boolean("periodic_x", false), s.boolean("periodic_y", false));
    fit_key = length_key(s, lx <= ly ? "size_x" : "size_y");
  } else {
    const double D = required_length(s, "diameter", d_ref_m, "the (outer) container diameter; D/d is the aspect ratio");
    fit_key = length_key(s, "diameter");
    if (type == "annulus") {
      const double Di = required_length(s, "inner_diameter", d_ref_m, "the diameter of the inner cylinder");
      if (Di >= D)
        throw InputError(fmt::format("{}: the inner diameter ({} m) is not below the outer one ({} m); allowed: "
                                     "inner_diameter < diameter",
                                     length_key(s, "inner_diameter"), Di, D));
      c = std::make_unique<Annulus>(0.5 * D, 0.5 * Di);
    } else {
      c = std::make_unique<Cylinder>(0.5 * D);
    }
  }
  if (2.0 * c->max_radius() < d_max_m * (1.0 - 1e-12))
    throw InputError(fmt::format("{}: the largest particle ({:.4g} m, {:.4g} d) does not fit in the {} (it holds "
                                 "spheres up to {:.4g} m, {:.4g} d); allowed: a {} of at least that width{}",
                                 fit_key, d_max_m, d_max_m / d_ref_m, type, 2.0 * c->max_radius(),
                                 2.0 * c->max_radius() / d_ref_m,
                                 type == "annulus" ? "gap" : type == "box" ? "side" : "diameter",
                                 c->periodicity().lateral() ? " (3 diameters for a periodic side)" : ""));
  if (const auto period = s.optional_length("period_z", Range::positive())) {
    c->set_axial_period(period->metres(d_ref_m));
    if (c->axial_period() < Periodicity::kShortestInDiameters * d_max_m * (1.0 - 1e-12))
      throw InputError(fmt::format("{}: an axial period of {:.4g} m ({:.4g} d) is shorter than 3 largest diameters "
                                   "({:.4g} m); allowed: a period of at least that",
                                   length_key(s, "period_z"), c->axial_period(), c->axial_period() / d_ref_m,
                                   Periodicity::kShortestInDiameters * d_max_m));
  }
  return c;
}

namespace {

// The cross-section of a container record.
std::unique_ptr<Container> section_from_json(const nlohmann::json& j) {
  auto positive = [&](const char* key) {
    return j.contains(key) && j[key].is_number() && j[key].get<double>() > 0 ? j[key].get<double>() : -1.0;
  };
  const std::string type = j.is_object() ? j.value("type", "") : "";
  if (type == "cylinder" && positive("diameter") > 0) return std::make_unique<Cylinder>(0.5 * positive("diameter"));
  if (type == "annulus" && positive("diameter") > positive("inner_diameter") && positive("inner_diameter") > 0)
    return std::make_unique<Annulus>(0.5 * positive("diameter"), 0.5 * positive("inner_diameter"));
  if (type == "box" && positive("size_x") > 0 && positive("size_y") > 0)
    return std::make_unique<Box>(positive("size_x"), positive("size_y"), j.value("periodic_x", false),
                                 j.value("periodic_y", false));
  throw InputError(fmt::format("unrecognised container record {}; allowed: {{\"type\":\"cylinder\",\"diameter\":D}}, "
                               "{{\"type\":\"annulus\",\"diameter\":D,\"inner_diameter\":Di<D}}, "
                               "{{\"type\":\"box\",\"size_x\":Lx,\"size_y\":Ly,\"periodic_x\":bool,"
                               "\"periodic_y\":bool}}, optionally \"period_z\":H; lengths > 0",
                               j.dump()));
}

}  // namespace

std::unique_ptr<Container> container_from_json(const nlohmann::json& j) {
  std::unique_ptr<Container> c = section_from_json(j);
  if (j.contains("period_z")) {
    if (!j["period_z"].is_number() || !(j["period_z"].get<double>() > 0.0))
      throw InputError(fmt::format("container record {}: period_z = {}; allowed: a length > 0", j.dump(),
                                   j["period_z"].dump()));
    c->set_axial_period(j["period_z"].get<double>());
  }
  return c;
}

}  // namespace bedforge
