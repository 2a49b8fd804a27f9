// The static map against costmap_2d's StaticLayer semantics. Golden numbers are worked out by
// hand from costmap_2d's rules (unsigned-char compares, value / lethal * 254 truncated).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "downstream_perception/core/costmap/static_map.h"
#include "downstream_perception/core/grid/cost_values.h"

using namespace downstream_perception;  // NOLINT

namespace {

std::uint8_t map(int occupancy, const StaticMapConfig& c) {
  return interpretStaticValue(static_cast<std::uint8_t>(static_cast<std::int8_t>(occupancy)), c);
}

StaticMapInfo info(int w, int h, double res = 0.5, double ox = -1.0, double oy = 2.0) {
  StaticMapInfo i;
  i.width = w, i.height = h, i.resolution = res, i.origin_x = ox, i.origin_y = oy;
  i.data_size = static_cast<std::size_t>(w) * h;
  return i;
}

}  // namespace

TEST(StaticMapValues, DefaultsAreCostmap2ds) {
  const StaticMapConfig c;
  EXPECT_TRUE(c.track_unknown_space);
  EXPECT_FALSE(c.use_maximum);
  EXPECT_EQ(c.lethal_cost_threshold, 100);
  EXPECT_EQ(c.unknown_cost_value, -1);
  EXPECT_TRUE(c.trinary_costmap);
}

TEST(StaticMapValues, TrinaryDefault) {
  const StaticMapConfig c;
  EXPECT_EQ(map(-1, c), 255);  // unknown, tracked
  EXPECT_EQ(map(0, c), 0);
  EXPECT_EQ(map(50, c), 0);
  EXPECT_EQ(map(99, c), 0);
  EXPECT_EQ(map(100, c), 254);
  // Out-of-range occupancy values are bytes >= 100: lethal, as in costmap_2d.
  EXPECT_EQ(map(101, c), 254);
  EXPECT_EQ(map(127, c), 254);
  EXPECT_EQ(map(-128, c), 254);  // byte 128
  EXPECT_EQ(map(-2, c), 254);    // byte 254
}

TEST(StaticMapValues, UnknownNotTrackedIsFree) {
  StaticMapConfig c;
  c.track_unknown_space = false;
  EXPECT_EQ(map(-1, c), 0);
  EXPECT_EQ(map(100, c), 254);
}

TEST(StaticMapValues, NonTrinaryScales) {
  StaticMapConfig c;
  c.trinary_costmap = false;
  EXPECT_EQ(map(0, c), 0);
  EXPECT_EQ(map(1, c), 2);     // 2.54
  EXPECT_EQ(map(50, c), 127);  // 127.0
  EXPECT_EQ(map(99, c), 251);  // 251.46
  EXPECT_EQ(map(100, c), 254);
  EXPECT_EQ(map(-1, c), 255);
  c.lethal_cost_threshold = 65;
  EXPECT_EQ(map(50, c), 195);  // 195.38
  EXPECT_EQ(map(64, c), 250);  // 250.09
  EXPECT_EQ(map(65, c), 254);
}

TEST(StaticMapValues, LethalThresholdClamped) {
  StaticMapConfig c;
  c.lethal_cost_threshold = 150;  // clamped to 100
  EXPECT_EQ(clampedLethalThreshold(150), 100);
  EXPECT_EQ(map(99, c), 0);
  EXPECT_EQ(map(100, c), 254);
  c.lethal_cost_threshold = -5;  // clamped to 0: every known value is lethal
  EXPECT_EQ(clampedLethalThreshold(-5), 0);
  EXPECT_EQ(map(0, c), 254);
  EXPECT_EQ(map(-1, c), 255);  // the unknown test comes first
  c.trinary_costmap = false;   // no division by zero either
  EXPECT_EQ(map(0, c), 254);
}

TEST(StaticMapValues, UnknownCostValueComparedAsByte) {
  StaticMapConfig c;
  c.unknown_cost_value = 255;  // the same byte as -1
  EXPECT_EQ(map(-1, c), 255);
  c.unknown_cost_value = 50;
  EXPECT_EQ(map(50, c), 255);
  EXPECT_EQ(map(-1, c), 254);  // map_server's unknown is then just a byte >= 100
  c.unknown_cost_value = 300;  // 300 mod 256 = 44
  EXPECT_EQ(map(44, c), 255);
  c.unknown_cost_value = 0;
  c.track_unknown_space = false;
  EXPECT_EQ(map(0, c), 0);
  c.track_unknown_space = true;
  EXPECT_EQ(map(0, c), 255);
}

TEST(StaticMapValues, TableMatchesFunction) {
  StaticMapConfig c;
  c.trinary_costmap = false;
  c.lethal_cost_threshold = 70;
  const auto table = staticValueTable(c);
  for (int v = 0; v < 256; ++v) {
    EXPECT_EQ(table[v], interpretStaticValue(static_cast<std::uint8_t>(v), c)) << v;
  }
}

TEST(StaticMapValidation, RefusesMalformedMaps) {
  const std::size_t big = std::numeric_limits<std::size_t>::max();
  EXPECT_EQ(validateStaticMap(info(4, 3), big), "");
  StaticMapInfo i = info(4, 3);
  i.data_size = 11;
  EXPECT_NE(validateStaticMap(i, big).find("11 values"), std::string::npos);
  // 65536 x 65537 wraps to 65536 in 32 bits: the check is 64-bit.
  i = info(1, 1);
  i.width = 65536, i.height = 65537, i.data_size = 65536;
  EXPECT_NE(validateStaticMap(i, big), "");
  i = info(4, 3, 0.0);
  EXPECT_NE(validateStaticMap(i, big).find("resolution"), std::string::npos);
  i = info(4, 3, -0.05);
  EXPECT_NE(validateStaticMap(i, big), "");
  i = info(4, 3, std::nan(""));
  EXPECT_NE(validateStaticMap(i, big), "");
  i = info(4, 3, 0.05, std::nan(""));
  EXPECT_NE(validateStaticMap(i, big).find("origin"), std::string::npos);
  i = info(0, 3);
  EXPECT_NE(validateStaticMap(i, big), "");
  i = info(4, 3);
  EXPECT_NE(validateStaticMap(i, 11).find("max_cells"), std::string::npos);
  EXPECT_EQ(validateStaticMap(i, 12), "");
  i.qz = std::sin(0.05), i.qw = std::cos(0.05);  // yaw 0.1 rad
  EXPECT_NE(validateStaticMap(i, big).find("rotated"), std::string::npos);
  i.qz = 0.0, i.qw = 0.0;  // never set: taken as the identity
  EXPECT_EQ(validateStaticMap(i, big), "");
  i.qw = -1.0;  // the identity too
  EXPECT_EQ(validateStaticMap(i, big), "");
}

TEST(StaticMap, SetMapMapsEveryCellAndCounts) {
  StaticMap m;
  EXPECT_FALSE(m.hasMap());
  const std::vector<std::int8_t> data = {0, 100, -1, 50, 100, 0, 0, -1, 101, 99, 0, 0};
  ASSERT_EQ(m.setMap(info(4, 3), data.data()), "");
  ASSERT_TRUE(m.hasMap());
  const Costmap& c = m.costs();
  EXPECT_EQ(c.geometry(), GridGeometry(4, 3, 0.5, -1.0, 2.0));
  const std::vector<std::uint8_t> want = {0, 254, 255, 0, 254, 0, 0, 255, 254, 0, 0, 0};
  EXPECT_EQ(c.cells(), want);
  EXPECT_EQ(m.counts().lethal, 3u);
  EXPECT_EQ(m.counts().unknown, 2u);
  EXPECT_EQ(m.counts().free, 7u);
  EXPECT_EQ(m.lastChange().min_x, 0);
  EXPECT_EQ(m.lastChange().max_x, 3);
  EXPECT_EQ(m.lastChange().min_y, 0);
  EXPECT_EQ(m.lastChange().max_y, 2);
}

TEST(StaticMap, RefusedMapKeepsThePreviousOne) {
  StaticMap m;
  const std::vector<std::int8_t> data(12, 100);
  ASSERT_EQ(m.setMap(info(4, 3), data.data()), "");
  StaticMapInfo bad = info(5, 5);
  bad.data_size = 12;
  EXPECT_NE(m.setMap(bad, data.data()), "");
  EXPECT_EQ(m.costs().geometry().sizeX(), 4);
  EXPECT_EQ(m.costs().cost(3, 2), 254);
  EXPECT_EQ(m.counts().lethal, 12u);
}

TEST(StaticMap, UpdateRewritesItsWindowOnly) {
  StaticMap m;
  const std::vector<std::int8_t> data(12, 0);
  ASSERT_EQ(m.setMap(info(4, 3), data.data()), "");
  const std::vector<std::int8_t> up = {100, -1, 50, 100};
  ASSERT_EQ(m.applyUpdate(1, 1, 2, 2, up.data(), up.size()), "");
  const std::vector<std::uint8_t> want = {0, 0, 0, 0, 0, 254, 255, 0, 0, 0, 254, 0};
  EXPECT_EQ(m.costs().cells(), want);
  EXPECT_EQ(m.lastChange().min_x, 1);
  EXPECT_EQ(m.lastChange().max_x, 2);
  EXPECT_EQ(m.lastChange().min_y, 1);
  EXPECT_EQ(m.lastChange().max_y, 2);
  EXPECT_EQ(m.counts().lethal, 2u);
  EXPECT_EQ(m.counts().unknown, 1u);
  EXPECT_EQ(m.counts().free, 9u);
  // The window at the far corner is inside.
  const std::vector<std::int8_t> one = {-1};
  EXPECT_EQ(m.applyUpdate(3, 2, 1, 1, one.data(), 1), "");
  EXPECT_EQ(m.costs().cost(3, 2), 255);
}

TEST(StaticMap, UpdateRefusals) {
  StaticMap m;
  const std::vector<std::int8_t> up(4, 100);
  EXPECT_EQ(m.applyUpdate(0, 0, 2, 2, up.data(), 4), "no map yet");
  const std::vector<std::int8_t> data(12, 0);
  ASSERT_EQ(m.setMap(info(4, 3), data.data()), "");
  EXPECT_NE(m.applyUpdate(-1, 0, 2, 2, up.data(), 4), "");  // left of the map
  EXPECT_NE(m.applyUpdate(3, 0, 2, 2, up.data(), 4), "");   // sticks out right
  EXPECT_NE(m.applyUpdate(0, 2, 2, 2, up.data(), 4), "");   // sticks out top
  EXPECT_NE(m.applyUpdate(0, 0, 2, 2, up.data(), 3).find("3 values"), std::string::npos);
  EXPECT_NE(m.applyUpdate(std::int64_t{1} << 40, 0, 2, 2, up.data(), 4), "");  // no wrap
  EXPECT_NE(m.applyUpdate(0, 0, -2, -2, up.data(), 4), "");
  // 2^32 + 2 columns times 1 row would be 2 cells in 32-bit arithmetic.
  EXPECT_NE(m.applyUpdate(0, 0, (std::int64_t{1} << 32) + 2, 1, up.data(), 2), "");
  for (std::uint8_t c : m.costs().cells()) EXPECT_EQ(c, 0);  // nothing was written
  EXPECT_EQ(m.counts().free, 12u);
  // An empty update is valid and changes nothing.
  EXPECT_EQ(m.applyUpdate(2, 1, 0, 0, nullptr, 0), "");
  EXPECT_TRUE(m.lastChange().empty());
}

TEST(StaticCopy, OverwriteAndMax) {
  const GridGeometry g(3, 1, 1.0, 0.0, 0.0);
  Costmap layer(g, 0), master(g, 0);
  const std::uint8_t l[] = {255, 0, 50};
  const std::uint8_t before[] = {100, 255, 100};
  for (int i = 0; i < 3; ++i) layer.setCost(i, 0, l[i]), master.setCost(i, 0, before[i]);
  Costmap over = master;
  copyStaticOverwrite(layer, &over, 0, 0, 3, 1);
  EXPECT_EQ(over.cells(), (std::vector<std::uint8_t>{255, 0, 50}));
  Costmap mx = master;
  copyStaticMax(layer, &mx, 0, 0, 3, 1);
  // layer unknown: master kept; master unknown: layer's 0 wins; 100 > 50 kept.
  EXPECT_EQ(mx.cells(), (std::vector<std::uint8_t>{100, 0, 100}));
  layer.setCost(2, 0, 254);
  copyStaticMax(layer, &mx, 0, 0, 3, 1);
  EXPECT_EQ(mx.cost(2, 0), 254);
  // Only the window is written.
  Costmap part = master;
  copyStaticOverwrite(layer, &part, 1, 0, 2, 1);
  EXPECT_EQ(part.cells(), (std::vector<std::uint8_t>{100, 0, 100}));
}

TEST(StaticCopy, SampledThroughATransform) {
  Costmap layer(GridGeometry(4, 4, 1.0, 0.0, 0.0), 0);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) layer.setCost(x, y, static_cast<std::uint8_t>(10 * y + x));
  }
  Costmap master(GridGeometry(2, 2, 1.0, 1.0, 1.0), 7);
  EXPECT_EQ(copyStaticSampled(layer, Affine2D(), false, &master, 0, 0, 2, 2), 4u);
  EXPECT_EQ(master.cells(), (std::vector<std::uint8_t>{11, 12, 21, 22}));
  // Shift by +2 m in x: the right column falls off the layer and stays as it was.
  Affine2D shift;
  shift.tx = 2.0;
  Costmap m2(GridGeometry(2, 2, 1.0, 1.0, 1.0), 7);
  EXPECT_EQ(copyStaticSampled(layer, shift, false, &m2, 0, 0, 2, 2), 2u);
  EXPECT_EQ(m2.cells(), (std::vector<std::uint8_t>{13, 7, 23, 7}));
  // +90 degrees: (x, y) -> (-y, x), then +4 m in x. Centre (1.5, 1.5) -> (2.5, 1.5).
  Affine2D rot;
  rot.xx = 0.0, rot.xy = -1.0, rot.yx = 1.0, rot.yy = 0.0, rot.tx = 4.0;
  Costmap m3(GridGeometry(2, 2, 1.0, 1.0, 1.0), 7);
  EXPECT_EQ(copyStaticSampled(layer, rot, false, &m3, 0, 0, 2, 2), 4u);
  // Master cells, row-major: (0,0) c=(1.5,1.5) -> (2.5,1.5) = 12; (1,0) c=(2.5,1.5) -> (2.5,2.5) =
  // 22; (0,1) c=(1.5,2.5) -> (1.5,1.5) = 11; (1,1) c=(2.5,2.5) -> (1.5,2.5) = 21.
  EXPECT_EQ(m3.cells(), (std::vector<std::uint8_t>{12, 22, 11, 21}));
  // use_maximum: an unknown layer cell leaves the master alone.
  layer.setCost(1, 1, 255);
  Costmap m4(GridGeometry(2, 2, 1.0, 1.0, 1.0), 15);
  copyStaticSampled(layer, Affine2D(), true, &m4, 0, 0, 2, 2);
  EXPECT_EQ(m4.cells(), (std::vector<std::uint8_t>{15, 15, 21, 22}));
  // A NaN transform writes nothing.
  Affine2D bad;
  bad.tx = std::nan("");
  EXPECT_EQ(copyStaticSampled(layer, bad, false, &m4, 0, 0, 2, 2), 0u);
}

TEST(StaticCopy, AffineInverse) {
  Affine2D a;
  a.xx = 0.0, a.xy = -1.0, a.yx = 1.0, a.yy = 0.0, a.tx = 4.0, a.ty = -2.0;
  const Affine2D b = invert(a);
  double x = 0.0, y = 0.0, bx = 0.0, by = 0.0;
  applyAffine(a, 1.5, 0.25, &x, &y);  // (3.75, -0.5)
  EXPECT_DOUBLE_EQ(x, 3.75);
  EXPECT_DOUBLE_EQ(y, -0.5);
  applyAffine(b, x, y, &bx, &by);
  EXPECT_DOUBLE_EQ(bx, 1.5);
  EXPECT_DOUBLE_EQ(by, 0.25);
  Affine2D singular;
  singular.xx = 0.0;
  EXPECT_TRUE(std::isnan(invert(singular).xx));
}
