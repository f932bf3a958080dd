// Which sketch a run takes when it is given none, and the drawn path in the route frame: the
// run and the run page (`sketchnav ui`) share them, so the page shows the sketch the run uses.
#include <gtest/gtest.h>

#include <string>

#include "sketchnav/core/error.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/mapsketch/route.h"
#include "sketchnav/run/run.h"

namespace sketchnav::run {
namespace {

TEST(DefaultSketchPath, WorldFileOrShippedWorldName) {
  EXPECT_FALSE(isWorldFile("lab"));
  EXPECT_TRUE(isWorldFile("worlds/lab"));
  EXPECT_TRUE(isWorldFile("hall.json"));
  EXPECT_EQ(defaultSketchPath("/tmp/x/hall.world.json"), "/tmp/x/hall.sketch.json");
  EXPECT_EQ(defaultSketchPath("hall.json"), "");  // no convention for other names
  EXPECT_EQ(defaultSketchPath("corridor"), resourcePath("sketches/corridor.sketch.json"));
  EXPECT_THROW(defaultSketchPath("no-such-world"), RuntimeError);
}

TEST(DrawnPathInRoute, StartsAtTheRouteStartScaledAndYUp) {
  const mapsketch::Sketch sk = mapsketch::loadSketch(resourcePath("sketches/lab.sketch.json"));
  const mapsketch::Route route = mapsketch::toRoute(sk);
  const auto path = drawnPathInRoute(sk, route);
  ASSERT_EQ(path.size(), sk.path.size());
  ASSERT_GE(path.size(), 2u);
  // Canvas pixels (v down) -> metres from the sketch's start (y up), at the route's scale.
  for (size_t i : {size_t{0}, path.size() - 1}) {
    const Eigen::Vector2d d = sk.path[i] - sk.start;
    EXPECT_NEAR(path[i].x(), route.start_m.x() + d.x() * route.scale_m_per_px, 1e-12);
    EXPECT_NEAR(path[i].y(), route.start_m.y() - d.y() * route.scale_m_per_px, 1e-12);
  }
  // The lab sketch's path begins at its start mark.
  EXPECT_NEAR((path.front() - route.start_m).norm(), 0.0, 1e-9);
}

}  // namespace
}  // namespace sketchnav::run
