// Naming the particles near defects, on a bed where the nearest surface is known.
#include "meshing/surface/defect_locations.hpp"

#include <gtest/gtest.h>

using namespace bedforge;
using namespace bedforge::meshing;

TEST(DefectLocations, NearestSurfaceNotNearestCentre) {
  // A small sphere (d = 0.2) at x = 0 and a large one (d = 2) at x = 2. The point x = 0.7 is
  // nearer the small one's centre (0.7 against 1.3) but nearer the large one's surface (0.3
  // against 0.6): the large one. x = 0.5 is nearer the small one's surface (0.4 against 0.5).
  Bed b;
  b.centres = {{0, 0, 0}, {2, 0, 0}};
  b.diameters = {0.2, 2.0};
  const DefectLocations d = locate_defects(b, {{0.5, 0, 0}, {0.7, 0, 0}, {1.2, 0, 0}, {0.05, 0, 0}}, "cells");
  EXPECT_EQ(d.nearest, (std::vector<int>{0, 1, 1, 0}));
  // Ties in count keep the lower index first.
  EXPECT_EQ(d.summary, "particle 0 (2 cells), particle 1 (2 cells)");
  const DefectLocations more = locate_defects(b, {{1.2, 0, 0}, {0.7, 0, 0}, {0.05, 0, 0}}, "triangles");
  EXPECT_EQ(more.summary, "particle 1 (2 triangles), particle 0 (1 triangles)");
}

TEST(DefectLocations, AnEmptyBedNamesNoParticle) {
  const DefectLocations d = locate_defects(Bed{}, {{0, 0, 0}}, "cells");
  EXPECT_EQ(d.nearest, (std::vector<int>{-1}));
  EXPECT_TRUE(d.summary.empty());
}
