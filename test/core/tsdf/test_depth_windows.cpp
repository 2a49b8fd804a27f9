// How a voxel reads its depth from the 2 x 2 pixels around its projection (issue 22, defect 4):
// planes interpolate, depth edges and invalid pixels take the nearest pixel, creases (bent
// beyond the frame's noise) the farthest of the four; and the room corner the crease rule is
// for: on planes of voxel centres it is meshed to its corner line, not cut off a voxel wide.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "downstream_perception/core/tsdf/depth_windows.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "esdf_test_helpers.h"
#include "fused_frames.h"
#include "tsdf_test_helpers.h"
#include "tsdf_test_scenes.h"

using namespace downstream_perception;        // NOLINT
using namespace downstream_perception::test;  // NOLINT

namespace {

/// The inverse depths the integrator gives classifyDepthWindows: 0 where invalid.
std::vector<float> inverseOf(const std::vector<float>& depth) {
  std::vector<float> inverse(depth.size());
  for (std::size_t i = 0; i < depth.size(); ++i) {
    inverse[i] = std::isfinite(depth[i]) && depth[i] > 0.0f ? 1.0f / depth[i] : 0.0f;
  }
  return inverse;
}

/// Two planes 2 m from the camera, mirror images about the camera's y-z plane, meeting in a
/// concave crease (the nearer of the two is seen) along the image's middle column; `slant`:
/// their normals' x (1: each at 45 degrees to the view, a room's corner seen along its diagonal).
std::vector<float> creaseDepth(const PinholeCamera& camera, double slant = 0.5) {
  const std::vector<float> left =
      planeDepth(camera, Eigen::Vector3d(slant, 0.2, 1.0).normalized(), 2.0);
  const std::vector<float> right =
      planeDepth(camera, Eigen::Vector3d(-slant, 0.2, 1.0).normalized(), 2.0);
  std::vector<float> depth(left.size());
  for (std::size_t i = 0; i < depth.size(); ++i) depth[i] = std::min(left[i], right[i]);
  return depth;
}

struct Classified {
  std::vector<DepthWindow> windows;
  float threshold = 0.0f;
};

Classified classify(const PinholeCamera& camera, const std::vector<float>& depth,
                    int crease_sum_radius = 0) {
  DepthWindowSettings s;
  s.max_step = 0.05f;
  s.crease_min = 0.001f;
  s.crease_noise_factor = 4.0f;
  s.crease_sum_radius = crease_sum_radius;
  Classified c;
  c.windows.resize(depth.size());
  DepthWindowScratch scratch;
  const std::vector<float> inverse = inverseOf(depth);
  c.threshold = classifyDepthWindows(depth.data(), inverse.data(), camera.width, camera.height, s,
                                     &scratch, c.windows.data());
  return c;
}

}  // namespace

TEST(DepthWindows, PlanesInterpolateCreasesTakeTheFarthestEdgesTheNearest) {
  const PinholeCamera camera = smallCamera();  // 160 x 120: the crease between columns 79, 80
  std::vector<float> depth = creaseDepth(camera);
  const int w = camera.width, h = camera.height;
  depth[static_cast<std::size_t>(10) * w + 20] = std::nanf("");  // an invalid pixel
  for (int v = 0; v < h; ++v) depth[static_cast<std::size_t>(v) * w + 120] += 0.3f;  // a step
  const Classified c = classify(camera, depth);
  EXPECT_FLOAT_EQ(c.threshold, 0.001f);  // no noise: the floor
  std::size_t creases = 0;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const DepthWindow got = c.windows[static_cast<std::size_t>(v) * w + u];
      const bool edge = v == h - 1 || u == w - 1 || u == 119 || u == 120 ||
                        (v >= 9 && v <= 10 && u >= 19 && u <= 20);
      if (edge) {
        EXPECT_EQ(got, DepthWindow::kNearestPixel) << u << ", " << v;
      } else if (u == 79) {
        EXPECT_EQ(got, DepthWindow::kCreaseBetweenColumns) << u << ", " << v;
        creases += got == DepthWindow::kCreaseBetweenColumns;
      } else {
        EXPECT_EQ(got, DepthWindow::kInterpolate) << u << ", " << v;
      }
    }
  }
  EXPECT_EQ(creases, static_cast<std::size_t>(h - 1));
}

TEST(DepthWindows, TheTwoPlanesOfACreaseAreReadExactlyEitherWay) {
  // Two planes meeting along a line through the image (a column, a row, or slanting): in each
  // crease window the value at any point is the visible plane's (the nearer at a concave
  // crease, the farther at a convex one), where the bilinear interpolation errs by up to a
  // quarter of the kink.
  const PinholeCamera camera = smallCamera();
  const int w = camera.width, h = camera.height;
  struct Case {
    Eigen::Vector3d n1, n2;
    bool concave;
  };
  const std::vector<Case> cases = {
      {Eigen::Vector3d(0.5, 0.2, 1.0), Eigen::Vector3d(-0.5, 0.2, 1.0), true},   // column
      {Eigen::Vector3d(0.5, 0.2, 1.0), Eigen::Vector3d(-0.5, 0.2, 1.0), false},  // convex
      {Eigen::Vector3d(0.1, 0.6, 1.0), Eigen::Vector3d(0.1, -0.6, 1.0), true},   // row
      {Eigen::Vector3d(0.5, 0.3, 1.0), Eigen::Vector3d(-0.4, -0.2, 1.0), true},  // slanting
  };
  for (const Case& k : cases) {
    const Eigen::Vector3d n1 = k.n1.normalized(), n2 = k.n2.normalized();
    const auto inverseAt = [&](double u, double v) {
      const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
      const double i1 = n1.dot(ray) / 2.0, i2 = n2.dot(ray) / 2.0;  // both planes 2 m off
      return k.concave ? std::max(i1, i2) : std::min(i1, i2);
    };
    std::vector<float> depth(static_cast<std::size_t>(w) * h);
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        depth[static_cast<std::size_t>(v) * w + u] = static_cast<float>(1.0 / inverseAt(u, v));
      }
    }
    const Classified c = classify(camera, depth);
    const std::vector<float> inverse = inverseOf(depth);
    std::size_t creases = 0;
    double worst = 0.0, worst_bilinear = 0.0;
    for (int v = 2; v + 3 < h; ++v) {
      for (int u = 2; u + 3 < w; ++u) {
        const DepthWindow kind = c.windows[static_cast<std::size_t>(v) * w + u];
        if (kind < DepthWindow::kCreaseBetweenRows) continue;
        // Only windows the crease crosses between the pixels the model reads across it.
        const bool rows = kind == DepthWindow::kCreaseBetweenRows;
        ++creases;
        for (const double a : {0.1, 0.5, 0.9}) {
          for (const double b : {0.2, 0.5, 0.8}) {
            const CreaseDepth got =
                creaseInverseDepth(inverse.data(), w, h, u, v, static_cast<float>(a),
                                   static_cast<float>(b), kind, 0.05f);
            ASSERT_GT(got.inverse, 0.0f);
            EXPECT_EQ(got.concave, k.concave);
            const double truth = inverseAt(u + a, v + b);
            const std::size_t i = static_cast<std::size_t>(v) * w + u;
            const double bilinear = (1 - b) * ((1 - a) * inverse[i] + a * inverse[i + 1]) +
                                    b * ((1 - a) * inverse[i + w] + a * inverse[i + w + 1]);
            // A crease slanting across the window may put a side's pixels on both planes (it
            // crosses a line outside the window's rows, or the window's rows in both lines):
            // there the model errs as a chord would. Left out here.
            const bool straddled = [&] {
              // Which plane each of the 4 x 2 pixels the model reads shows (n1 or not).
              bool shows_n1[2][4];
              for (int line = 0; line < 2; ++line) {
                for (int step = 0; step < 4; ++step) {
                  const double uu = rows ? u + line : u - 1 + step;
                  const double vv = rows ? v - 1 + step : v + line;
                  const Eigen::Vector3d ray((uu - camera.cx) / camera.fx,
                                            (vv - camera.cy) / camera.fy, 1.0);
                  shows_n1[line][step] = (n1.dot(ray) > n2.dot(ray)) == k.concave;
                }
              }
              // Each side's four pixels on one plane.
              return shows_n1[0][0] != shows_n1[0][1] || shows_n1[1][0] != shows_n1[1][1] ||
                     shows_n1[0][1] != shows_n1[1][1] || shows_n1[0][2] != shows_n1[0][3] ||
                     shows_n1[1][2] != shows_n1[1][3] || shows_n1[0][2] != shows_n1[1][2];
            }();
            if (straddled) continue;
            worst = std::max(worst, std::abs(got.inverse - truth) / truth);
            worst_bilinear = std::max(worst_bilinear, std::abs(bilinear - truth) / truth);
          }
        }
      }
    }
    std::printf("creases %zu; worst relative error %.2e (bilinear %.2e)\n", creases, worst,
                worst_bilinear);
    EXPECT_GT(creases, 100u);
    EXPECT_LT(worst, 2e-6);
    EXPECT_GT(worst_bilinear, 1e-3);
  }
}

TEST(DepthWindows, DepthNoiseRaisesTheThresholdSoPlanesStayPlanes) {
  // 5 mm of independent depth noise: a plane's windows bend by a median of 2.34 sigma (the
  // largest of the twist and four pairs' smaller kinks, each a multiple of the noise); the
  // threshold is 4 x that, 9.35 sigma, which about 5e-5 of a plane's windows exceed.
  const PinholeCamera camera = benchmarkCamera();
  const double sigma = 0.005;
  for (const unsigned seed : {1u, 2u, 3u}) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> noise(0.0f, static_cast<float>(sigma));
    std::vector<float> depth =
        planeDepth(camera, Eigen::Vector3d(0.1, -0.2, 1.0).normalized(), 2.0);
    for (float& d : depth) d += noise(rng);
    const Classified c = classify(camera, depth);
    const std::size_t creases = static_cast<std::size_t>(
        std::count_if(c.windows.begin(), c.windows.end(),
                      [](DepthWindow k) { return k >= DepthWindow::kCreaseBetweenRows; }));
    std::printf("seed %u: threshold %.4f m, creases %zu of %zu windows\n", seed, c.threshold,
                creases, c.windows.size());
    EXPECT_NEAR(c.threshold, 9.35 * sigma, 0.1 * 9.35 * sigma);
    EXPECT_LT(creases, c.windows.size() / 2000);
    // The slope changes summed along six lines (Gaussian: their threshold is 4 sigma) add few.
    const Classified summed = classify(camera, depth, 2);
    const std::size_t summed_creases = static_cast<std::size_t>(
        std::count_if(summed.windows.begin(), summed.windows.end(),
                      [](DepthWindow k) { return k >= DepthWindow::kCreaseBetweenRows; }));
    std::printf("  summed along six lines: creases %zu\n", summed_creases);
    EXPECT_LT(summed_creases, c.windows.size() / 2000);
  }
}

TEST(DepthWindows, SummedAlongItsLineANoisyCreaseStandsOut) {
  // A room's corner seen along its diagonal (each wall at 45 degrees to the view, 2 m away,
  // 13 mm per pixel: a 27 mm kink) under 5 mm of depth noise. A window's own kinks (at most
  // half the kink each side) stay under the noise threshold (9.35 sigma); the slope change
  // summed over the six lines along the crease is the whole kink six times over, against 24.5
  // mm of noise, and the window holding the crease is the largest across it.
  const PinholeCamera camera = smallCamera();
  const int w = camera.width, h = camera.height;
  for (const unsigned seed : {1u, 2u, 3u}) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> noise(0.0f, 0.005f);
    std::vector<float> depth = creaseDepth(camera, 1.0);
    for (float& d : depth) d += noise(rng);
    std::size_t found[2] = {0, 0}, elsewhere[2] = {0, 0};
    for (const int radius : {0, 2}) {
      const Classified c = classify(camera, depth, radius);
      const int k = radius > 0 ? 1 : 0;
      for (int v = 3; v + 4 < h; ++v) {
        bool row_found = false;
        for (int u = 0; u < w; ++u) {
          const DepthWindow got = c.windows[static_cast<std::size_t>(v) * w + u];
          if (got < DepthWindow::kCreaseBetweenRows) continue;
          if (std::abs(u - 79) <= 1) {
            row_found = row_found || got == DepthWindow::kCreaseBetweenColumns;
          } else {
            ++elsewhere[k];
          }
        }
        found[k] += row_found;
      }
    }
    const std::size_t rows = static_cast<std::size_t>(h - 7);
    std::printf("seed %u: crease found in %zu / %zu of %zu rows, %zu / %zu windows elsewhere\n",
                seed, found[0], found[1], rows, elsewhere[0], elsewhere[1]);
    EXPECT_LT(found[0], rows / 10);
    EXPECT_GT(found[1], rows * 9 / 10);
    EXPECT_LT(elsewhere[1], static_cast<std::size_t>(w * h) / 500);
  }
}

namespace {

/// Closest point to p on triangle (a, b, c) (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3d closestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  }
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

double distanceToMesh(const TriangleMesh& mesh, const Eigen::Vector3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t + 2 < mesh.triangles.size(); t += 3) {
    const Eigen::Vector3d a = mesh.vertices[mesh.triangles[t]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[mesh.triangles[t + 1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[mesh.triangles[t + 2]].cast<double>();
    best = std::min(best, (closestOnTriangle(p, a, b, c) - p).norm());
  }
  return best;
}

/// A room's corner on planes of voxel centres: the wall x = 1 m and the floor z = 0 (5 cm
/// voxels), seen from inside the room by a camera moving along the wall 1.2-1.6 m high, 320 x
/// 240 (the corner runs nearly along the image rows, where a window's twist does not see it).
/// Returns the share of the corner line's points (every 2 cm) within 1 cm of the mesh's
/// surface (a corner cut off a voxel wide lies 3.5 cm from them) and of the corner line's voxels
/// that fused >= 0.
struct CornerResult {
  double near_line = 0.0, non_negative = 0.0;
};

/// sigma > 0: independent depth noise (m), 30 frames instead of 12, seeded.
CornerResult fuseCorner(double sigma = 0.0, unsigned seed = 1) {
  const AxisPlanes hit{{{2, 0.0, -1}, {0, 1.0, +1}}};  // the floor, the wall
  const PinholeCamera camera = benchmarkCamera();
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  TsdfMap map(c);
  std::vector<Eigen::Isometry3d> walk;
  const int frames = sigma > 0.0 ? 30 : 12;
  for (int k = 0; k < frames; ++k) {
    const double y = -0.6 + 1.2 * k / frames;
    walk.push_back(
        lookAt({-0.8 - 0.05 * (k % 3), y, 1.2 + 0.48 * k / frames}, {1.0, y + 0.3, 0.1}));
  }
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, static_cast<float>(sigma));
  fuseFrames(&map, camera, walk, [&](const Eigen::Isometry3d& pose) {
    std::vector<float> depth = castDepth(camera, pose, hit);
    if (sigma > 0.0) {
      for (float& d : depth) d += noise(rng);
    }
    return depth;
  });
  const TriangleMesh mesh = meshOf(map);
  CornerResult r;
  std::size_t points = 0, near = 0, voxels = 0, non_negative = 0;
  for (int j = -20; j <= 20; ++j) {
    ++points;
    near += distanceToMesh(mesh, Eigen::Vector3d(1.0, 0.02 * j, 0.0)) <= 0.01;
  }
  for (int j = -8; j <= 8; ++j) {
    const TsdfVoxel* voxel = map.voxel(Eigen::Vector3i(20, j, 0));
    if (voxel == nullptr || !(voxel->observedWeight() > 0.0f)) continue;
    ++voxels;
    non_negative += voxel->distance >= 0.0f;
  }
  r.near_line = static_cast<double>(near) / points;
  r.non_negative = voxels > 0 ? static_cast<double>(non_negative) / voxels : 0.0;
  std::printf("corner line within 1 cm of the mesh %.3f; its voxels >= 0 %.3f of %zu\n",
              r.near_line, r.non_negative, voxels);
  return r;
}

}  // namespace

TEST(DepthWindows, ARoomCornerOnVoxelCentresIsMeshedToItsCornerLine) {
  // 0 and 0 with the bilinear interpolation across the crease (its chord, nearer than both
  // planes, fused the corner line's voxels negative: the corner was cut off on its whole
  // length); 0.80 and 0.65 with the crease's planes (where the corner passes within a few
  // hundredths of a pixel of a pixel row its windows bend less than the 0.01 voxel a crease
  // needs, and their chord errs by as little: those voxels fuse a hair negative).
  const CornerResult r = fuseCorner();
  EXPECT_GT(r.near_line, 0.75);
  EXPECT_GT(r.non_negative, 0.55);
}

TEST(DepthWindows, ANoisyRoomCornerIsFoundSummedAlongItsLine) {
  // The same corner under 5 mm of depth noise (30 frames, three seeds): a window's own kinks
  // drown in the noise (the threshold rises to 9.35 sigma), so the crease is found by its slope
  // change summed over six neighbouring lines along it (classifyDepthWindows), and read by its
  // two planes rather than by the chord.
  // Without the sums the corner is cut off on its whole length in every seed (0 and 0).
  double near_line = 0.0;
  for (const unsigned seed : {1u, 2u, 3u}) {
    const CornerResult r = fuseCorner(0.005, seed);
    EXPECT_GT(r.near_line, 0.25);
    EXPECT_GT(r.non_negative, 0.15);
    near_line += r.near_line / 3.0;
  }
  EXPECT_GT(near_line, 0.45);
}
