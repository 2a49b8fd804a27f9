// The incidence window (TsdfConfig::incidence_window_radius_px): exact on planes, the window
// never spans a depth step or an invalid pixel, and with depth noise its estimate scatters far
// less than the one from a pixel's own neighbours.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <random>
#include <vector>

#include "downstream_perception/core/tsdf/depth_incidence.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "tsdf_test_scenes.h"

using namespace downstream_perception;        // NOLINT
using namespace downstream_perception::test;  // NOLINT

namespace {

constexpr float kJump = 0.08f;      // mu at 2 cm voxels
constexpr float kUntouched = 7.0f;  // no cosine: marks pixels the window left alone

/// Two planes in one image: a wall (normal `wall_n`, offset 2 m) and, over the pixel rectangle
/// [u0, u1) x [v0, v1), a tilted panel about 1 m nearer; optionally NaN pixels.
struct PanelScene {
  PinholeCamera camera = smallCamera();
  Eigen::Vector3d wall_n = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  Eigen::Vector3d panel_n = Eigen::Vector3d(-0.5, 0.4, 1.0).normalized();
  int u0 = 50, u1 = 110, v0 = 30, v1 = 90;
  std::vector<float> depth, inverse;

  explicit PanelScene(const std::vector<std::size_t>& holes = {}) {
    depth = planeDepth(camera, wall_n, 2.0);
    const std::vector<float> panel = planeDepth(camera, panel_n, 1.0);
    for (int v = v0; v < v1; ++v) {
      for (int u = u0; u < u1; ++u) depth[index(u, v)] = panel[index(u, v)];
    }
    for (const std::size_t i : holes) depth[i] = std::nanf("");
    updateInverse();
  }
  std::size_t index(int u, int v) const { return static_cast<std::size_t>(v) * camera.width + u; }
  bool onPanel(int u, int v) const { return u >= u0 && u < u1 && v >= v0 && v < v1; }
  void updateInverse() {
    inverse.assign(depth.size(), 0.0f);
    for (std::size_t i = 0; i < depth.size(); ++i) {
      if (depth[i] == depth[i]) inverse[i] = 1.0f / depth[i];
    }
  }
  /// |cos| of the incidence at pixel (u, v) on the plane it sees.
  double truth(int u, int v) const {
    const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
    return std::abs(ray.dot(onPanel(u, v) ? panel_n : wall_n)) / ray.norm();
  }
  /// Whether pixel (u, v) breaks a surface: not valid, or its pair with the next pixel along
  /// its row or column (where inside the image) not valid or across the panel's outline.
  bool breaks(int u, int v) const {
    const auto differs = [&](int u2, int v2) {
      if (u2 >= camera.width || v2 >= camera.height) return false;
      return inverse[index(u2, v2)] == 0.0f || onPanel(u2, v2) != onPanel(u, v);
    };
    return inverse[index(u, v)] == 0.0f || differs(u + 1, v) || differs(u, v + 1);
  }
  /// Whether the 3 x 3 pixels around (u, v) lie inside the image and none of them breaks.
  bool cleanThreeByThree(int u, int v) const {
    if (u < 1 || v < 1 || u + 1 >= camera.width || v + 1 >= camera.height) return false;
    for (int dv = -1; dv <= 1; ++dv) {
      for (int du = -1; du <= 1; ++du) {
        if (breaks(u + du, v + dv)) return false;
      }
    }
    return true;
  }
  std::vector<float> windowCosines(int radius) const {
    std::vector<float> cosine(depth.size(), kUntouched);
    IncidenceWindowScratch scratch;
    windowIncidenceCosines(camera, depth.data(), inverse.data(), kJump, radius, &scratch,
                           cosine.data());
    return cosine;
  }
};

}  // namespace

TEST(DepthIncidence, WindowIncidenceIsExactOnPlanesAndNeverSpansAStepOrAHole) {
  const PanelScene scene({PanelScene().index(20, 20), PanelScene().index(75, 60)});
  // The outline is a depth step of more than the jump everywhere (else the window could span it).
  for (int v = scene.v0; v < scene.v1; ++v) {
    ASSERT_GT(scene.depth[scene.index(scene.u0 - 1, v)] - scene.depth[scene.index(scene.u0, v)],
              kJump);
    ASSERT_GT(scene.depth[scene.index(scene.u1, v)] - scene.depth[scene.index(scene.u1 - 1, v)],
              kJump);
  }
  for (int u = scene.u0; u < scene.u1; ++u) {
    ASSERT_GT(scene.depth[scene.index(u, scene.v0 - 1)] - scene.depth[scene.index(u, scene.v0)],
              kJump);
    ASSERT_GT(scene.depth[scene.index(u, scene.v1)] - scene.depth[scene.index(u, scene.v1 - 1)],
              kJump);
  }
  for (const int radius : {1, 2, 5}) {
    const std::vector<float> cosine = scene.windowCosines(radius);
    int exact = 0, left = 0;
    for (int v = 0; v < scene.camera.height; ++v) {
      for (int u = 0; u < scene.camera.width; ++u) {
        const float c = cosine[scene.index(u, v)];
        if (scene.cleanThreeByThree(u, v)) {
          // Some window fits (at the latest the 3 x 3 one) and lies on the pixel's own plane.
          EXPECT_NEAR(c, scene.truth(u, v), 1e-4 * scene.truth(u, v) + 1e-6)
              << radius << ": " << u << "," << v;
          ++exact;
        } else {
          // The image border, the step between the planes, the holes: left alone.
          EXPECT_EQ(c, kUntouched) << radius << ": " << u << "," << v;
          ++left;
        }
      }
    }
    // Both kinds occur: the step's pixels (two columns and two rows of the panel's outline, at
    // least), the border and the holes' neighbourhoods.
    EXPECT_GT(exact, 15000) << radius;
    EXPECT_GT(left, 2 * 60 + 2 * 60 + 2 * 9) << radius;
  }
  // Radius 0 leaves every pixel alone.
  const std::vector<float> none = scene.windowCosines(0);
  EXPECT_EQ(std::count(none.begin(), none.end(), kUntouched),
            static_cast<std::ptrdiff_t>(none.size()));
}

TEST(DepthIncidence, WithDepthNoiseTheWindowScattersFarLessThanTheNeighbours) {
  PanelScene scene;
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.0f, 0.005f);  // 5 mm, the benchmark's depth noise
  for (float& d : scene.depth) d += noise(rng);
  scene.updateInverse();
  std::vector<float> neighbours(scene.depth.size()), xs;
  incidenceCosines(scene.camera, scene.depth.data(), scene.inverse.data(), kJump, &xs,
                   neighbours.data());
  std::vector<float> windowed = neighbours;
  IncidenceWindowScratch scratch;
  windowIncidenceCosines(scene.camera, scene.depth.data(), scene.inverse.data(), kJump, 5, &scratch,
                         windowed.data());
  // Errors on the panel and the wall away from the step and the border (every window clean).
  std::vector<double> err_neighbours, err_window;
  for (int v = 6; v + 6 < scene.camera.height; ++v) {
    for (int u = 6; u + 6 < scene.camera.width; ++u) {
      const bool near_step = (std::abs(u - scene.u0) <= 6 || std::abs(u - scene.u1) <= 6 ||
                              std::abs(v - scene.v0) <= 6 || std::abs(v - scene.v1) <= 6);
      if (near_step) continue;
      const double truth = scene.truth(u, v);
      err_neighbours.push_back(std::abs(neighbours[scene.index(u, v)] - truth));
      err_window.push_back(std::abs(windowed[scene.index(u, v)] - truth));
    }
  }
  const auto p99 = [](std::vector<double> e) {
    std::sort(e.begin(), e.end());
    return e[e.size() * 99 / 100];
  };
  const double neighbours_p99 = p99(err_neighbours), window_p99 = p99(err_window);
  std::printf("|cos error| p99 over %zu pixels: neighbours %.4f, 11 x 11 window %.4f\n",
              err_window.size(), neighbours_p99, window_p99);
  EXPECT_GT(err_window.size(), 8000u);
  EXPECT_LT(window_p99, 0.05);
  EXPECT_LT(window_p99, neighbours_p99 / 4.0);
}

TEST(DepthIncidence, TsdfConfigChecksTheWindowAndNamesItInertWithoutIncidences) {
  TsdfConfig c;
  EXPECT_EQ(c.incidence_window_radius_px, 5);
  EXPECT_EQ(c.validate(), "");
  for (const int bad : {-1, 65}) {
    c.incidence_window_radius_px = bad;
    EXPECT_NE(c.validate().find("incidence_window_radius_px"), std::string::npos) << bad;
  }
  c.incidence_window_radius_px = 3;
  EXPECT_EQ(c.inertSettings(), "");
  c.grazing_reach_voxels = 0.0;
  c.edge_guard_rad = 0.0;
  EXPECT_NE(c.inertSettings().find("incidence_window_radius_px 3 has no effect"), std::string::npos)
      << c.inertSettings();
}
