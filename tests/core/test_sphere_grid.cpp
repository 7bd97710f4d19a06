#include "core/sphere_grid.hpp"

#include <gtest/gtest.h>

#include <map>

#include "core/random.hpp"

using namespace bedforge;

namespace {

// Every centre within h of each of `points` is visited, and no sphere twice.
void expect_finds_all_within(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& points,
                             const Container& c, double h) {
  SphereGrid grid;
  grid.build(x, std::vector<double>(x.size(), 0.5), c, h);
  const Periodicity per = c.periodicity();
  for (const Eigen::Vector3d& p : points) {
    std::map<int, int> visits;
    grid.for_each_run_around(per.wrapped(p), [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) {
        ++visits[grid.sphere(k)];
        EXPECT_EQ(grid.centre_and_radius(k).head<3>(), per.wrapped(x[grid.sphere(k)]));
      }
    });
    for (const auto& [s, n] : visits) EXPECT_EQ(n, 1) << "sphere " << s << " visited " << n << " times";
    for (std::size_t s = 0; s < x.size(); ++s) {
      if (per.separation(p, x[s]).norm() >= h) continue;
      EXPECT_TRUE(visits.count(static_cast<int>(s))) << "sphere " << s << " missed";
    }
  }
}

}  // namespace

TEST(SphereGrid, FindsEveryCentreWithinItsCellWidthOfAnyPoint) {
  // Points anywhere in the container, up to a cell width beyond the centres' heights (a point on
  // the top sphere's surface lies above every centre): a tube with a floor, one periodic along z
  // (1 to about 10 cells per period), and a box periodic on every side.
  const double h = 1.3;
  for (double period : {0.0, 1.5, 3.7, 12.0}) {
    Cylinder tube(5.0);
    tube.set_axial_period(period);
    Box box(2.0, 6.0, true, true);
    box.set_axial_period(period);
    for (const Container* c : {static_cast<const Container*>(&tube), static_cast<const Container*>(&box)}) {
      Rng rng(11);
      std::vector<Eigen::Vector3d> x, points;
      const double height = period > 0.0 ? period : 10.0;
      for (int i = 0; i < 400; ++i) {
        const auto p = c->sample_centre(rng, 0.5);
        x.emplace_back(p.x(), p.y(), height * rng.uniform());
      }
      for (int i = 0; i < 400; ++i) {
        const auto p = c->sample_centre(rng, 0.0);
        points.emplace_back(p.x(), p.y(), (height + 2.0 * h) * rng.uniform() - h);
      }
      SCOPED_TRACE(std::string(c->kind()) + ", period " + std::to_string(period));
      expect_finds_all_within(x, points, *c, h);
    }
  }
}
