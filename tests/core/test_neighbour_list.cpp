#include "core/neighbour_list.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

using namespace bedforge;

namespace {

std::set<std::pair<int, int>> brute_force(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& r,
                                          double skin, Periodicity per = {}) {
  std::set<std::pair<int, int>> pairs;
  for (size_t i = 0; i < x.size(); ++i)
    for (size_t j = 0; j < x.size(); ++j)
      if (i != j && per.separation(x[i], x[j]).norm() < r[i] + r[j] + skin) pairs.insert({int(i), int(j)});
  return pairs;
}

std::set<std::pair<int, int>> listed(const NeighbourList& nl, size_t n) {
  std::set<std::pair<int, int>> pairs;
  for (size_t i = 0; i < n; ++i)
    for (int j : nl.of(i)) pairs.insert({int(i), j});
  return pairs;
}

}  // namespace

TEST(NeighbourList, MatchesBruteForceForAMixtureInACylinder) {
  Cylinder c(4.0);
  Rng rng(9);
  std::vector<Eigen::Vector3d> x;
  std::vector<double> r;
  for (int i = 0; i < 600; ++i) {
    const double ri = i % 5 == 0 ? 1.0 : 0.25;  // size ratio 4
    const auto p = c.sample_centre(rng, ri);
    x.emplace_back(p.x(), p.y(), 12.0 * rng.uniform());
    r.push_back(ri);
  }
  NeighbourList nl(0.1);
  nl.build(x, r, c);
  EXPECT_EQ(listed(nl, x.size()), brute_force(x, r, 0.1));
}

TEST(NeighbourList, RebuildsOnlyWhenTwoDisplacementsExceedTheSkin) {
  // Two spheres 0.1 apart, skin 0.2: one may close the whole skin alone, but the two together
  // only as much.
  Cylinder c(2.0);
  std::vector<Eigen::Vector3d> x = {{0, 0, 0.5}, {0, 0, 1.6}, {1, 0, 0.5}};
  std::vector<double> r = {0.5, 0.5, 0.4};
  NeighbourList nl(0.2);
  EXPECT_TRUE(nl.update(x, r, c));
  x[1].z() -= 0.19;
  EXPECT_FALSE(nl.update(x, r, c));
  const auto held = listed(nl, x.size()), touching = brute_force(x, r, 0.0);
  EXPECT_EQ(touching.size(), 2u);
  EXPECT_TRUE(std::includes(held.begin(), held.end(), touching.begin(), touching.end())) << "a touching pair is not listed";
  x[0].z() += 0.02;
  EXPECT_TRUE(nl.update(x, r, c));
  EXPECT_EQ(nl.builds(), 2);
}

TEST(NeighbourList, SurvivesSpheresThrownFarApart) {
  // A diverging run may spread spheres over a huge height before it is caught; the grid must
  // stay bounded and the list correct.
  Cylinder c(1.0);
  std::vector<Eigen::Vector3d> x = {{0, 0, 0.5}, {0, 0, 1.4}, {0, 0, 1e9}, {0, 0, 1e9 + 0.5}};
  std::vector<double> r(4, 0.5);
  NeighbourList nl(0.1);
  nl.build(x, r, c);
  EXPECT_EQ(listed(nl, x.size()), brute_force(x, r, 0.1));
}

TEST(NeighbourList, FindsPairsAcrossPeriodicSides) {
  // Periodic along x, or along both x and y, with 1 to about 10 cells across (a wrapped row
  // must not visit a cell twice); positions given outside the central cell must be wrapped too.
  for (bool periodic_y : {false, true})
    for (double lx : {1.1, 3.0, 3.7, 5.0}) {
      Box box(lx, 4.0, true, periodic_y);
      Rng rng(3);
      std::vector<Eigen::Vector3d> x;
      std::vector<double> r;
      for (int i = 0; i < 300; ++i) {
        const auto p = box.sample_centre(rng, 0.5);
        x.emplace_back(p.x() + lx * (i % 3 - 1), p.y() + (periodic_y ? 4.0 * (i % 2) : 0.0), 20.0 * rng.uniform());
        r.push_back(i % 4 == 0 ? 0.5 : 0.35);
      }
      NeighbourList nl(0.2);
      nl.build(x, r, box);
      EXPECT_EQ(listed(nl, x.size()), brute_force(x, r, 0.2, box.periodicity()))
          << "Lx = " << lx << (periodic_y ? ", periodic y" : "");
    }
}

TEST(NeighbourList, FindsPairsAcrossAnAxialPeriod) {
  // A tube periodic along z, periods of 1 to about 10 cells, centres given up to a period below
  // or above [0, H); and a box periodic on every side.
  for (double period : {1.1, 3.0, 3.7, 9.0}) {
    Cylinder tube(3.0);
    tube.set_axial_period(period);
    Box box(3.3, 4.0, true, true);
    box.set_axial_period(period);
    for (const Container* c : {static_cast<const Container*>(&tube), static_cast<const Container*>(&box)}) {
      Rng rng(5);
      std::vector<Eigen::Vector3d> x;
      std::vector<double> r;
      for (int i = 0; i < 300; ++i) {
        const auto p = c->sample_centre(rng, 0.5);
        x.emplace_back(p.x(), p.y(), period * (rng.uniform() + (i % 3 - 1)));
        r.push_back(i % 4 == 0 ? 0.5 : 0.35);
      }
      NeighbourList nl(0.2);
      nl.build(x, r, *c);
      EXPECT_EQ(listed(nl, x.size()), brute_force(x, r, 0.2, c->periodicity())) << c->kind() << ", H = " << period;
    }
  }
}

TEST(NeighbourList, FindsSpheresPushedThroughTheWall) {
  // Soft walls let a sphere's centre leave the cross-section; it is kept in the grid's edge
  // cells, which must still be searched as far as it reaches.
  Cylinder c(3.0);
  std::vector<Eigen::Vector3d> x = {{2.9, 0, 1}, {3.6, 0.3, 1}, {4.4, 0.1, 1.2}, {-3.5, -0.2, 0.8}, {-2.6, 0, 1}, {0, 3.3, 1}};
  std::vector<double> r(x.size(), 0.5);
  NeighbourList nl(0.1);
  nl.build(x, r, c);
  EXPECT_EQ(listed(nl, x.size()), brute_force(x, r, 0.1));
}
