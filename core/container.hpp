#pragma once
#include <Eigen/Core>
#include <nlohmann/json.hpp>

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

// The vessel a bed is packed in. Its axis is z, the rigid floor is z = 0, the top is open, and
// the lateral walls are deformable (they push overlapping spheres back with a linear force).
// The packers and the analysis see containers only through this interface.
class Container {
 public:
  static constexpr int kMaxWallContacts = 4;

  virtual ~Container() = default;
  virtual std::string kind() const = 0;
  // Cross-section area (length^2).
  virtual double cross_section_area() const = 0;
  // Walls overlapped by the sphere (centre c, radius r): writes up to kMaxWallContacts, returns count.
  virtual int wall_contacts(const Eigen::Vector3d& c, double r, WallContact* out) const = 0;
  // Uniformly random (x, y) of a centre whose sphere of radius r lies inside the walls.
  virtual Eigen::Vector2d sample_centre(Rng& rng, double r) const = 0;
  // Largest radius of a sphere that fits between the walls.
  virtual double max_radius() const = 0;
  // Bounding box of the cross-section as (xmin, ymin, xmax, ymax).
  virtual Eigen::Vector4d lateral_bounds() const = 0;
  // The same container with every length multiplied by `factor` (change of unit).
  virtual std::unique_ptr<Container> scaled(double factor) const = 0;
  // Dimensions in the container's length unit, for reports and bed headers.
  virtual nlohmann::json to_json() const = 0;
};

// Circular cylinder of radius R around the z axis.
class Cylinder final : public Container {
 public:
  explicit Cylinder(double radius) : radius_(radius) {}
  double radius() const { return radius_; }

  std::string kind() const override { return "cylinder"; }
  double cross_section_area() const override;
  int wall_contacts(const Eigen::Vector3d& c, double r, WallContact* out) const override;
  Eigen::Vector2d sample_centre(Rng& rng, double r) const override;
  double max_radius() const override { return radius_; }
  Eigen::Vector4d lateral_bounds() const override { return {-radius_, -radius_, radius_, radius_}; }
  std::unique_ptr<Container> scaled(double factor) const override;
  nlohmann::json to_json() const override;

 private:
  double radius_;
};

// Reads [container] (`type`, `diameter_m` | `diameter_d`) into a container in metres;
// `d_ref_m` converts lengths given in diameters. InputError when a sphere of `d_max_m` cannot fit.
std::unique_ptr<Container> read_container(SceneSection& section, double d_ref_m, double d_max_m);

// The container recorded by `to_json()` (metres), e.g. from a bed file's header.
std::unique_ptr<Container> container_from_json(const nlohmann::json& j);

}  // namespace bedforge
