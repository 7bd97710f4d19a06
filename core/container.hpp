#pragma once
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <cmath>
#include <memory>
#include <string>

#include "core/random.hpp"
#include "core/scene_section.hpp"

namespace bedforge {

// Contact of a sphere with a deformable lateral wall.
struct WallContact {
  double overlap;          // penetration depth (> 0), same length unit as the container
  Eigen::Vector3d normal;  // unit vector from the wall into the container: the direction of the wall force
};

// Periodic directions of a container: period along x, y (sides of a box) and z (the axis), 0
// where there is a wall (or, along z, the floor and the open top). Periodic images are taken by
// the minimum-image rule, so a period must exceed twice the interaction reach.
struct Periodicity {
  // The shortest period allowed, in largest diameters: every pair within one minimum image, with
  // room for a neighbour-list skin (the scene refuses a shorter one).
  static constexpr double kShortestInDiameters = 3.0;
  double lx = 0.0, ly = 0.0, lz = 0.0;
  bool any() const { return lx > 0.0 || ly > 0.0 || lz > 0.0; }
  bool lateral() const { return lx > 0.0 || ly > 0.0; }
  // a - b, shortest over periodic images.
  Eigen::Vector3d separation(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    Eigen::Vector3d d = a - b;
    if (lx > 0.0) d.x() -= lx * std::nearbyint(d.x() / lx);
    if (ly > 0.0) d.y() -= ly * std::nearbyint(d.y() / ly);
    if (lz > 0.0) d.z() -= lz * std::nearbyint(d.z() / lz);
    return d;
  }
  // The image of p in the central cell: [-L/2, L/2) across x and y, [0, L) along the axis
  // (where z counts from the bottom of the bed).
  Eigen::Vector3d wrapped(Eigen::Vector3d p) const {
    if (lx > 0.0) p.x() -= lx * std::floor(p.x() / lx + 0.5);
    if (ly > 0.0) p.y() -= ly * std::floor(p.y() / ly + 0.5);
    if (lz > 0.0) p.z() -= lz * std::floor(p.z() / lz);
    return p;
  }
};

// The vessel a bed is packed in. Its axis is z, the rigid floor is z = 0, the top is open;
// or, with an axial period H, the bed repeats along z every H, with neither floor nor top
// (a periodic section of a long bed). The soft-sphere packer treats lateral walls as deformable
// (a linear force pushes overlapping spheres back); the Monte Carlo packer as hard
// (wall_contacts must return none). The packers and the analysis see containers only through
// this interface.
class Container {
 public:
  static constexpr int kMaxWallContacts = 4;

  virtual ~Container() = default;
  virtual std::string kind() const = 0;
  // Cross-section area (length^2).
  virtual double cross_section_area() const = 0;
  // Length of wall around the cross-section (periodic sides have none): with the area, the
  // hydraulic diameter 4 A / P.
  virtual double wall_perimeter() const = 0;
  // Walls overlapped by the sphere (centre c, radius r): writes up to kMaxWallContacts, returns
  // count. Periodic sides have no walls.
  virtual int wall_contacts(const Eigen::Vector3d& c, double r, WallContact* out) const = 0;
  // Uniformly random (x, y) of a centre whose sphere of radius r lies inside the walls.
  virtual Eigen::Vector2d sample_centre(Rng& rng, double r) const = 0;
  // Periodic directions: the axial period, and a box's periodic sides.
  virtual Periodicity periodicity() const { return {0.0, 0.0, axial_period_}; }
  // Axial period (length; 0: a floor at z = 0 and an open top).
  double axial_period() const { return axial_period_; }
  void set_axial_period(double period) { axial_period_ = period; }
  // Largest radius of a sphere that fits between the walls (and, for periodic sides, the
  // largest the minimum-image rule allows).
  virtual double max_radius() const = 0;
  // Bounding box of the cross-section as (xmin, ymin, xmax, ymax).
  virtual Eigen::Vector4d lateral_bounds() const = 0;
  // The same container with every length multiplied by `factor` (change of unit).
  std::unique_ptr<Container> scaled(double factor) const;
  // Dimensions in the container's length unit, for reports and bed headers.
  nlohmann::json to_json() const;

 protected:
  // The cross-section's part of scaled() and to_json(); the base adds the axial period.
  virtual std::unique_ptr<Container> scaled_section(double factor) const = 0;
  virtual nlohmann::json section_json() const = 0;
  double axial_period_ = 0.0;
};

// Circular cylinder of radius R around the z axis.
class Cylinder final : public Container {
 public:
  explicit Cylinder(double radius) : radius_(radius) {}
  double radius() const { return radius_; }

  std::string kind() const override { return "cylinder"; }
  double cross_section_area() const override;
  double wall_perimeter() const override;
  int wall_contacts(const Eigen::Vector3d& c, double r, WallContact* out) const override;
  Eigen::Vector2d sample_centre(Rng& rng, double r) const override;
  double max_radius() const override { return radius_; }
  Eigen::Vector4d lateral_bounds() const override { return {-radius_, -radius_, radius_, radius_}; }

 protected:
  std::unique_ptr<Container> scaled_section(double factor) const override;
  nlohmann::json section_json() const override;

 private:
  double radius_;
};

// Annular gap between two coaxial cylinders (radii R_inner < R_outer); Abreu et al. (1999)
// use it to compare a concave outer wall with a convex inner one.
class Annulus final : public Container {
 public:
  Annulus(double outer_radius, double inner_radius) : outer_(outer_radius), inner_(inner_radius) {}
  double outer_radius() const { return outer_; }
  double inner_radius() const { return inner_; }

  std::string kind() const override { return "annulus"; }
  double cross_section_area() const override;
  double wall_perimeter() const override;
  int wall_contacts(const Eigen::Vector3d& c, double r, WallContact* out) const override;
  Eigen::Vector2d sample_centre(Rng& rng, double r) const override;
  double max_radius() const override { return 0.5 * (outer_ - inner_); }
  Eigen::Vector4d lateral_bounds() const override { return {-outer_, -outer_, outer_, outer_}; }

 protected:
  std::unique_ptr<Container> scaled_section(double factor) const override;
  nlohmann::json section_json() const override;

 private:
  double outer_, inner_;
};

// Rectangular box [-Lx/2, Lx/2] x [-Ly/2, Ly/2]; each pair of opposite sides is either a pair
// of walls or periodic (a box periodic on both sides stands for an unbounded bed).
class Box final : public Container {
 public:
  Box(double size_x, double size_y, bool periodic_x, bool periodic_y)
      : lx_(size_x), ly_(size_y), px_(periodic_x), py_(periodic_y) {}
  double size_x() const { return lx_; }
  double size_y() const { return ly_; }

  std::string kind() const override { return "box"; }
  double cross_section_area() const override { return lx_ * ly_; }
  double wall_perimeter() const override { return (px_ ? 0.0 : 2.0 * ly_) + (py_ ? 0.0 : 2.0 * lx_); }
  int wall_contacts(const Eigen::Vector3d& c, double r, WallContact* out) const override;
  Eigen::Vector2d sample_centre(Rng& rng, double r) const override;
  Periodicity periodicity() const override { return {px_ ? lx_ : 0.0, py_ ? ly_ : 0.0, axial_period_}; }
  double max_radius() const override;
  Eigen::Vector4d lateral_bounds() const override { return {-0.5 * lx_, -0.5 * ly_, 0.5 * lx_, 0.5 * ly_}; }

 protected:
  std::unique_ptr<Container> scaled_section(double factor) const override;
  nlohmann::json section_json() const override;

 private:
  double lx_, ly_;
  bool px_, py_;
};

// Reads [container] into a container in metres: `type` = cylinder (`diameter`), annulus
// (`diameter`, `inner_diameter`) or box (`size_x`, `size_y`, `periodic_x`, `periodic_y`), and
// for any type the optional axial period `period_z`; each length as `_m` or `_d`; `d_ref_m`
// converts lengths given in diameters. InputError when a sphere of `d_max_m` cannot fit, or the
// period is shorter than 3 of them.
std::unique_ptr<Container> read_container(SceneSection& section, double d_ref_m, double d_max_m);

// The container recorded by `to_json()` (metres), e.g. from a bed file's header.
std::unique_ptr<Container> container_from_json(const nlohmann::json& j);

}  // namespace bedforge
