// Where a plane between pieces or slabs goes among the heights it keeps clear of.
#include "meshing/surface/clip_planes.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace bedforge::meshing;

namespace {

// Spheres' ends at 0, 0.0034 and 0.03 d, treated contacts' rims between them: the widest interval
// (0.0034-0.012, middle 0.0077) lies 0.0043 d from an end; the intervals between the rims from
// 0.012 to 0.0243 are narrower (0.0015 to 0.0025) but keep more than 0.005 d from every end, as
// the plane that replaced issue 58's 0.0017 d from a sphere's end did (docs/findings.md, 2026-12-06).
ClearHeights heights() {
  ClearHeights h;
  h.sphere_ends = {0.0, 0.0034, 0.03};
  h.all = {0.0, 0.0034, 0.012, 0.0135, 0.016, 0.018, 0.0195, 0.021, 0.0225, 0.0243, 0.03};
  return h;
}

}  // namespace

TEST(WidestIntervalMiddle, ThePlaneKeepsTheClearanceFromTheSpheresEndsWhereAnIntervalDoes) {
  // Of the intervals 0.005 d clear of the ends, the first widest.
  EXPECT_DOUBLE_EQ(widest_interval_middle(heights(), 0.015, 1.0, std::nan(""), 0.005), 0.01475);
  // Leaving out the interval that holds 0.014 (a plane moved away from it), the next.
  EXPECT_DOUBLE_EQ(widest_interval_middle(heights(), 0.015, 1.0, 0.014, 0.005), 0.017);
}

TEST(WidestIntervalMiddle, WhereNoIntervalIsThatClearTheWidestIsTaken) {
  EXPECT_DOUBLE_EQ(widest_interval_middle(heights(), 0.015, 1.0, std::nan(""), 0.02), 0.0077);
  // And only within `shift` of where it was asked: about 0.0285 by 0.002, the interval 0.0243-0.03.
  EXPECT_DOUBLE_EQ(widest_interval_middle(heights(), 0.0285, 0.002, std::nan(""), 0.005), 0.02715);
  // No interval within `shift`: where it was asked.
  EXPECT_DOUBLE_EQ(widest_interval_middle(heights(), 0.5, 0.01, std::nan(""), 0.005), 0.5);
}
