// The rim distance rule (issue 22, defect 4): the seeds' distance transform against brute force,
// incidence angles and allowances against analytic planes, and the surfaces it is for (a shelf
// top seen at grazing incidence on a plane of voxel centres) against the rule before it; rims at
// grazing incidence: a board's far edge in front of a wall is one, a concave corner is not.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "downstream_perception/core/tsdf/depth_rims.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "esdf_test_helpers.h"
#include "fused_frames.h"
#include "tsdf_test_helpers.h"
#include "tsdf_test_scenes.h"

using namespace downstream_perception;        // NOLINT
using namespace downstream_perception::test;  // NOLINT

TEST(DepthRims, SeedDistancesEqualBruteForce) {
  std::mt19937 rng(7);
  SeedDistances out;  // reused across sizes, as the integrator does
  for (const auto& [w, h, density] : std::vector<std::tuple<int, int, double>>{{1, 1, 1.0},
                                                                               {17, 1, 0.2},
                                                                               {1, 23, 0.2},
                                                                               {37, 23, 0.02},
                                                                               {37, 23, 0.3},
                                                                               {64, 48, 0.0},
                                                                               {64, 48, 0.005},
                                                                               {5, 9, 1.0}}) {
    std::bernoulli_distribution seed(density);
    std::vector<std::uint8_t> seeds(static_cast<std::size_t>(w) * h);
    for (auto& s : seeds) s = seed(rng);
    std::vector<float> values(seeds.size());
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = 0.5f + static_cast<float>(i);
    seedDistances(w, h, seeds.data(), &out, std::numeric_limits<float>::infinity(),
                  {values.data()});
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        long best = -1;
        for (int q = 0; q < h; ++q) {
          for (int p = 0; p < w; ++p) {
            if (!seeds[static_cast<std::size_t>(q) * w + p]) continue;
            const long d2 = static_cast<long>(p - u) * (p - u) + static_cast<long>(q - v) * (q - v);
            if (best < 0 || d2 < best) best = d2;
          }
        }
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        if (best < 0) {
          EXPECT_EQ(out.seed[i], -1);
          EXPECT_EQ(out.squared[i], SeedDistances::kNoSeed);
          EXPECT_EQ(out.seed_values[0][i], SeedDistances::kNoSeed);
          continue;
        }
        ASSERT_EQ(out.squared[i], static_cast<float>(best))
            << w << "x" << h << " at " << u << "," << v;
        const int s = out.seed[i];
        ASSERT_GE(s, 0);
        ASSERT_TRUE(seeds[static_cast<std::size_t>(s)]);
        EXPECT_EQ(out.seed_values[0][i], values[static_cast<std::size_t>(s)]);  // the seed's value
        const int su = s % w, sv = s / w;
        EXPECT_EQ((su - u) * (su - u) + (sv - v) * (sv - v), best);
      }
    }
    // Bounded beyond the image's diagonal: the same distances and seeds, the run fill then in
    // 32-bit integers (the unbounded call above takes the 64-bit path).
    SeedDistances wide;
    seedDistances(w, h, seeds.data(), &wide, 1000.0f);
    EXPECT_EQ(wide.squared, out.squared) << w << "x" << h;
    EXPECT_EQ(wide.seed, out.seed) << w << "x" << h;
    // Bounded to 5 px: exact nearer than that, at least that (or no seed) beyond.
    SeedDistances bounded;
    seedDistances(w, h, seeds.data(), &bounded, 5.0f);
    for (std::size_t i = 0; i < seeds.size(); ++i) {
      if (out.squared[i] < 25.0f) {
        EXPECT_EQ(bounded.squared[i], out.squared[i]);
      } else {
        EXPECT_GE(bounded.squared[i], 25.0f);
      }
    }
  }
}

TEST(DepthRims, SeedDistancesStayExactAcrossTheLargestImages) {
  // 16384 px across (the largest PinholeCamera allows), 3 rows: squared distances up to
  // 2.7e8 px^2, beyond float's integers; the envelope compares them in 64-bit integers.
  const int w = 16384, h = 3;
  std::vector<std::uint8_t> seeds(static_cast<std::size_t>(w) * h, 0);
  seeds[0] = 1;                                        // (0, 0)
  seeds[static_cast<std::size_t>(2) * w + w - 1] = 1;  // (16383, 2)
  seeds[static_cast<std::size_t>(1) * w + 8191] = 1;   // (8191, 1)
  SeedDistances out;
  seedDistances(w, h, seeds.data(), &out);
  for (const int v : {0, 1, 2}) {
    for (const int u : {1, 4095, 4096, 6000, 8190, 12287, 12288, 16382}) {
      long best = -1;
      int best_seed = -1;
      for (const auto& [su, sv] : std::vector<std::array<int, 2>>{{0, 0}, {8191, 1}, {16383, 2}}) {
        const long d2 = static_cast<long>(su - u) * (su - u) + static_cast<long>(sv - v) * (sv - v);
        if (best < 0 || d2 < best) {
          best = d2;
          best_seed = sv * w + su;
        }
      }
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      EXPECT_EQ(out.squared[i], static_cast<float>(best)) << u << "," << v;
      EXPECT_EQ(out.seed[i], best_seed) << u << "," << v;
    }
  }
}

namespace {

/// The floor y = 0.5 m (camera frame, y down) seen by smallCamera, cut at depth 2 m: farther
/// pixels are invalid (NaN), so row 97 (the first with depth <= 2 m) is the floor's far rim.
/// Neighbouring rows from there on lie within mu (8 cm) in depth, so the incidence is known.
struct CutFloor {
  PinholeCamera camera = smallCamera();
  std::vector<float> depth, inverse;
  std::vector<std::uint8_t> seeds;
  static constexpr int kRimRow = 97;
  CutFloor() {
    depth = planeDepth(camera, Eigen::Vector3d(0.0, 1.0, 0.0), 0.5);
    const std::size_t n = depth.size();
    inverse.assign(n, 0.0f);
    seeds.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      if (!(depth[i] <= 2.0f)) depth[i] = std::nanf("");
      if (depth[i] == depth[i]) inverse[i] = 1.0f / depth[i];
    }
    for (int u = 0; u < camera.width; ++u)
      seeds[static_cast<std::size_t>(kRimRow) * camera.width + u] = 1;
  }
  /// |cos| and sin of the incidence at pixel (u, v), and its depth, from the plane itself.
  void truth(int u, int v, double* cosine, double* sine, double* z) const {
    const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
    *cosine = std::abs(ray.y()) / ray.norm();
    *sine = std::sqrt(1.0 - *cosine * *cosine);
    *z = 0.5 / ray.y();
  }
};

RimAllowanceSettings twoCentimetreSettings() {
  RimAllowanceSettings s;
  s.voxel = 0.02f;
  s.truncation = 0.08f;
  s.jump = 0.08f;
  s.reach = 0.02f;
  s.reach_max = 0.32f;
  s.rim_scale = 1.5f;
  s.fallback_radius_px = 2.0f;
  s.radians_per_px = 1.0f / 150.0f;  // smallCamera's
  return s;
}

}  // namespace

TEST(DepthRims, IncidenceOfAPlaneMatchesItsNormal) {
  const CutFloor floor;
  for (const int v : {99, 100, 110, 119}) {
    for (const int u : {1, 40, 79, 158}) {
      double c = 0, s = 0, z = 0;
      floor.truth(u, v, &c, &s, &z);
      EXPECT_NEAR(
          incidenceCosine(floor.camera, floor.depth.data(), floor.inverse.data(), u, v, 0.08f), c,
          1e-3 * c + 1e-5)
          << u << "," << v;
    }
  }
  // An invalid pixel (beyond the cut): no estimate.
  EXPECT_EQ(incidenceCosine(floor.camera, floor.depth.data(), floor.inverse.data(), 79, 96, 0.08f),
            -1.0f);
  // The uncut floor near the horizon steps by metres from row to row (row 62: 30 m, its
  // neighbours 50 m and 21 m): no neighbour within mu, no estimate.
  std::vector<float> far = planeDepth(floor.camera, Eigen::Vector3d(0.0, 1.0, 0.0), 0.5);
  std::vector<float> far_inverse(far.size(), 0.0f);
  for (std::size_t i = 0; i < far.size(); ++i)
    far_inverse[i] = far[i] == far[i] ? 1.0f / far[i] : 0.0f;
  EXPECT_EQ(incidenceCosine(floor.camera, far.data(), far_inverse.data(), 79, 62, 0.08f), -1.0f);
  EXPECT_GT(incidenceCosine(floor.camera, far.data(), far_inverse.data(), 79, 110, 0.08f), 0.0f);
  // Given a plane tolerance, a pixel whose neighbours continue its plane gets the plane's
  // incidence however far they step (the integrator's second look).
  for (const int v : {61, 62, 70}) {
    double c = 0, s = 0, z = 0;
    floor.truth(79, v, &c, &s, &z);
    EXPECT_NEAR(incidenceCosine(floor.camera, far.data(), far_inverse.data(), 79, v, 0.08f, 0.04f),
                c, 1e-2 * c)
        << v;
  }
}

TEST(DepthRims, BatchIncidenceEqualsThePixelByPixelOne) {
  // A box on a tilted floor with invalid pixels: every branch of the neighbour choice.
  const PinholeCamera camera = smallCamera();
  const Eigen::Isometry3d pose = lookAt({-1.5, -0.4, 1.2}, {0.0, 0.0, 0.2});
  const auto scene = [](const Eigen::Vector3d& p) {
    return std::min(p.z() + 0.1 * p.x(), boxSdf(p, {0.0, 0.0, 0.2}, {0.2, 0.3, 0.2}));
  };
  std::vector<float> depth = renderDepth(camera, pose, scene);
  std::vector<float> inverse(depth.size(), 0.0f);
  for (std::size_t i = 0; i < depth.size(); ++i) {
    if (i % 53 == 0) depth[i] = std::nanf("");
    if (depth[i] == depth[i]) inverse[i] = 1.0f / depth[i];
  }
  std::vector<float> cosine(depth.size()), xs;
  incidenceCosines(camera, depth.data(), inverse.data(), 0.08f, &xs, cosine.data());
  int known = 0, unknown = 0;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const float one = incidenceCosine(camera, depth.data(), inverse.data(), u, v, 0.08f);
      const float batch = cosine[static_cast<std::size_t>(v) * camera.width + u];
      if (one < 0.0f) {
        EXPECT_EQ(batch, -1.0f) << u << "," << v;
        ++unknown;
      } else {
        EXPECT_NEAR(batch, one, 1e-4f) << u << "," << v;
        ++known;
      }
    }
  }
  EXPECT_GT(known, 10000);
  EXPECT_GT(unknown, 300);
}

TEST(DepthRims, GrazingReachByHand) {
  const RimAllowanceSettings s = twoCentimetreSettings();
  EXPECT_FLOAT_EQ(grazingReach(1.0f, s), 0.08f);   // head-on: mu
  EXPECT_FLOAT_EQ(grazingReach(0.25f, s), 0.08f);  // 0.02 / 0.25 = mu
  EXPECT_FLOAT_EQ(grazingReach(0.1f, s), 0.2f);    // 0.02 / 0.1
  EXPECT_FLOAT_EQ(grazingReach(0.05f, s), 0.32f);  // 0.4, capped
  EXPECT_FLOAT_EQ(grazingReach(-1.0f, s), 0.08f);  // unknown incidence
  RimAllowanceSettings off = s;
  off.reach = 0.0f;
  EXPECT_FLOAT_EQ(grazingReach(0.05f, off), 0.08f);
}

TEST(DepthRims, AllowanceFollowsTheRimDistanceAndTheIncidence) {
  const CutFloor floor;
  const int w = floor.camera.width, h = floor.camera.height;
  SeedDistances distances;
  seedDistances(w, h, floor.seeds.data(), &distances);
  // Scale 0.1: the rim binds 22 rows away too, where the floor's incidence cosine is 0.13 above
  // the rim's (perspective, not a turning surface): still the plane's travel.
  for (const float scale : {1.5f, 0.2f, 0.1f}) {
    RimAllowanceSettings s = twoCentimetreSettings();
    s.rim_scale = scale;
    std::vector<float> allowed(static_cast<std::size_t>(w) * h), cosine(allowed.size()), xs;
    incidenceCosines(floor.camera, floor.depth.data(), floor.inverse.data(), s.jump, &xs,
                     cosine.data());
    rimAllowances(floor.depth.data(), floor.inverse.data(), floor.seeds.data(), &distances,
                  cosine.data(), allowed.size(), 1.0f / 150.0f, s, allowed.data());
    int rim_bound = 0;
    for (const int k : {2, 3, 4, 8, 15, 22}) {
      const int v = CutFloor::kRimRow + k;
      for (const int u : {40, 79, 120}) {
        double c = 0, sn = 0, z = 0;
        floor.truth(u, v, &c, &sn, &z);
        const double reach = std::min(0.32, std::max(0.08, 0.02 / c));
        const double travel = scale * k * z / (150.0 * c * sn);  // D = k px straight up
        const double expected = std::min(reach, std::max(0.02, travel));
        rim_bound += travel < reach;
        EXPECT_NEAR(allowed[static_cast<std::size_t>(v) * w + u], expected, 2e-3 * expected)
            << "scale " << scale << " at " << u << "," << v;
      }
    }
    // The rim row itself: a voxel; beyond the cut (invalid): mu.
    EXPECT_FLOAT_EQ(allowed[static_cast<std::size_t>(CutFloor::kRimRow) * w + 79], 0.02f);
    EXPECT_FLOAT_EQ(allowed[static_cast<std::size_t>(CutFloor::kRimRow - 1) * w + 79], 0.08f);
    if (scale < 1.0f) {
      EXPECT_GT(rim_bound, 6);  // the small scale makes the rim bind near it
    } else {
      EXPECT_EQ(rim_bound, 0);
    }
  }
}

TEST(DepthRims, ASphereLetsItsRaysReachItsSilhouettesDepthButNotItsBack) {
  // A ball (radius 0.4 m, 1.5 m ahead) against nothing: its silhouette is the rim. Along each
  // pixel's ray the ball is a chord; the plane rule would stop the rays near the silhouette at
  // about half of what reaches the silhouette's depth (half the chord). The silhouette factor
  // lets them reach it, and no ray passes the ball's back.
  const PinholeCamera camera = smallCamera();
  const int w = camera.width, h = camera.height;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  const Eigen::Vector3d centre(0.0, 0.0, 1.5);
  const double radius = 0.4;
  std::vector<float> depth(n, std::nanf("")), inverse(n, 0.0f), chord(n, 0.0f);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
      // |t ray - centre| = radius: t^2 |ray|^2 - 2 t ray.centre + |centre|^2 - radius^2 = 0.
      const double a = ray.squaredNorm(), b = ray.dot(centre);
      const double disc = b * b - a * (centre.squaredNorm() - radius * radius);
      if (disc <= 0.0) continue;
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      depth[i] = static_cast<float>((b - std::sqrt(disc)) / a);
      inverse[i] = 1.0f / depth[i];
      chord[i] = static_cast<float>(2.0 * std::sqrt(disc) / a * std::sqrt(a));  // m along the ray
    }
  }
  std::vector<std::uint8_t> seeds(n, 0);  // ball pixels beside a miss
  for (int v = 1; v + 1 < h; ++v) {
    for (int u = 1; u + 1 < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      seeds[i] = inverse[i] != 0.0f && (inverse[i - 1] == 0.0f || inverse[i + 1] == 0.0f ||
                                        inverse[i - w] == 0.0f || inverse[i + w] == 0.0f);
    }
  }
  RimAllowanceSettings s = twoCentimetreSettings();
  s.rim_scale = 1.0f;
  s.truncation = s.reach_max = 2.0f;  // so the rim alone bounds every ray
  std::vector<float> cosine(n), xs, allowed(n);
  incidenceCosines(camera, depth.data(), inverse.data(), s.jump, &xs, cosine.data());
  SeedDistances distances;
  seedDistances(w, h, seeds.data(), &distances, std::numeric_limits<float>::infinity(),
                {depth.data(), cosine.data()});
  rimAllowances(depth.data(), inverse.data(), seeds.data(), &distances, cosine.data(), n,
                1.0f / 150.0f, s, allowed.data());
  int checked = 0, near_silhouette = 0, reaching = 0, plane_reaching = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (inverse[i] == 0.0f || seeds[i] || cosine[i] < 0.0f) continue;
    const float d = std::sqrt(distances.squared[i]);
    if (d > 10.0f) continue;  // farther in, the rim stops binding (mu does, not tested here)
    ++checked;
    // Never past the ball's back (the voxel floor aside).
    EXPECT_LE(allowed[i], std::max(chord[i] * 1.02f, s.voxel)) << i;
    if (d < 3.0f || d > 8.0f) continue;  // 3-8 px inside the silhouette
    ++near_silhouette;
    const float c = cosine[i], sine = std::sqrt(1.0f - c * c);
    const float plane = d * depth[i] / (150.0f * c * sine);
    // Two thirds of the way: D counts from the rim pixel's centre, the silhouette lies up to a
    // pixel beyond it (about 0.7-0.8 of the half chord is what the estimate gives here).
    reaching += allowed[i] >= 0.65f * 0.5f * chord[i];
    plane_reaching += plane >= 0.65f * 0.5f * chord[i];
  }
  EXPECT_GT(checked, 1000);
  ASSERT_GT(near_silhouette, 500);
  EXPECT_GT(reaching, near_silhouette * 9 / 10);    // nearly everywhere
  EXPECT_LT(plane_reaching, near_silhouette / 10);  // where the plane rule fell short
}

TEST(DepthRims, TheBackgroundBesideAnObjectIsNotBoundByItsRim) {
  // A fronto-parallel board at 1 m over the left half, the wall at 3 m behind: the board's rim
  // (column 79) bounds the board's pixels, not the wall's (2 m farther than the rim).
  const PinholeCamera camera = smallCamera();
  const int w = camera.width, h = camera.height;
  std::vector<float> depth(static_cast<std::size_t>(w) * h), inverse(depth.size());
  std::vector<std::uint8_t> seeds(depth.size(), 0);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      depth[i] = u < 80 ? 1.0f : 3.0f;
      inverse[i] = 1.0f / depth[i];
      seeds[i] = u == 79;
    }
  }
  RimAllowanceSettings s = twoCentimetreSettings();
  s.rim_scale = 0.01f;  // so the rim binds wherever it counts
  std::vector<float> cosine(depth.size()), xs;
  incidenceCosines(camera, depth.data(), inverse.data(), s.jump, &xs, cosine.data());
  // The rims' depths and incidences from the transform (what the integrator passes) or
  // gathered by rimAllowances itself: the same allowances.
  for (const bool with_planes : {true, false}) {
    SeedDistances distances;
    if (with_planes) {
      seedDistances(w, h, seeds.data(), &distances, std::numeric_limits<float>::infinity(),
                    {depth.data(), cosine.data()});
    } else {
      seedDistances(w, h, seeds.data(), &distances);
    }
    EXPECT_EQ(distances.seed_values.empty(), !with_planes);
    std::vector<float> allowed(depth.size());
    rimAllowances(depth.data(), inverse.data(), seeds.data(), &distances, cosine.data(),
                  allowed.size(), 1.0f / 150.0f, s, allowed.data());
    const std::size_t row = 60 * static_cast<std::size_t>(w);
    EXPECT_FLOAT_EQ(allowed[row + 79], 0.02f);  // the rim
    EXPECT_FLOAT_EQ(allowed[row + 77], 0.02f);  // the board next to it: bound to a voxel
    EXPECT_FLOAT_EQ(allowed[row + 81], 0.08f);  // the wall beside: mu, not bound
    EXPECT_FLOAT_EQ(allowed[row + 100], 0.08f);
  }
}

namespace {

/// Pose k of the corridor's camera walk (bench_tsdf_accuracy): 0.5 m apart along x, 1.5 m high,
/// looking ahead and down, the yaw turning from `first_yaw` by 0.05 rad a step.
Eigen::Isometry3d corridorPose(int k, double first_yaw) {
  const Eigen::Vector3d eye(0.5 * k, 0.0, 1.5);
  const double yaw = first_yaw + 0.05 * k;
  return lookAt(eye, eye + Eigen::Vector3d(2.0 * std::cos(yaw), 2.0 * std::sin(yaw), -0.8));
}

/// bench_tsdf_accuracy's corridor reduced to what issue 22's defect 4 measured there: the floor,
/// the -y wall and its shelf (a 4 cm board, top at z = 0.92 m: on a plane of 2 cm voxel centres),
/// seen as the corridor's camera sees it (from 1.5 m high, 3-7 m away: 80-85 degrees incidence
/// on the shelf top). Returns the share of the shelf top some frame saw with a vertex within
/// 2 cm, and (*ghosts) the vertices more than a voxel off every surface.
double shelfTopCovered(const TsdfConfig& c, std::size_t* ghosts) {
  const auto scene = [](const Eigen::Vector3d& p) {
    return std::min({p.z(), p.y() + 1.2, boxSdf(p, {7.0, -0.9, 0.9}, {0.25, 0.3, 0.02})});
  };
  const PinholeCamera camera = benchmarkCamera();
  TsdfMap map(c);
  std::vector<Eigen::Isometry3d> walk;
  for (int k = 0; k < 8; ++k) walk.push_back(corridorPose(k, -0.3));
  const auto [poses, depths] = fuseFrames(&map, camera, walk, [&](const Eigen::Isometry3d& pose) {
    return renderDepth(camera, pose, scene);
  });
  const TriangleMesh mesh = meshOf(map);
  *ghosts = 0;
  for (const Eigen::Vector3f& v : mesh.vertices)
    *ghosts += std::abs(scene(v.cast<double>())) > 0.02;
  std::size_t seen = 0;
  const double covered =
      coveredShare(camera, poses, depths, mesh,
                   gridOn({6.77, -1.18, 0.92}, {0.46, 0.0, 0.0}, {0.0, 0.54, 0.0}), &seen);
  EXPECT_GT(seen, 100u);
  return covered;
}

}  // namespace

TEST(DepthRims, AShelfTopAtGrazingIncidenceOnVoxelCentresIsMeshed) {
  TsdfConfig c;
  c.voxel_size_m = 0.02;
  TsdfConfig before = c;  // the rule before issue 22's defect 4
  before.edge_guard_rule = TsdfConfig::EdgeGuardRule::kFixedRadius;
  before.grazing_reach_voxels = 0.0;
  std::size_t ghosts = 0, ghosts_before = 0;
  const double covered = shelfTopCovered(c, &ghosts);
  const double covered_before = shelfTopCovered(before, &ghosts_before);
  std::printf("shelf top covered %.3f (before %.3f); ghosts %zu (before %zu)\n", covered,
              covered_before, ghosts, ghosts_before);
  // 0.79 while the band next to the shelf's rims was cut behind the surface only (its voxels,
  // on the top's plane, then fused positive); 0.87 with the band cut alike in front.
  EXPECT_GT(covered, 0.84);
  EXPECT_GT(covered, covered_before + 0.3);
  EXPECT_LE(ghosts, ghosts_before);
}

namespace {

/// bench_tsdf_accuracy's furnished room reduced to its shelf board (1 x 0.4 x 0.04 m, top at
/// z = 1.125 m) standing 10 cm in front of the +y wall, and the floor, all shifted by 5 mm (a
/// quarter of a 2 cm voxel). Ray cast exactly (slabs).
struct ShelfAgainstAWall {
  Eigen::Vector3d lo{0.505, 1.505, 1.085}, hi{1.505, 1.905, 1.125};  // the board
  double wall_y = 2.005;

  double sdf(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d c = 0.5 * (lo + hi), h = 0.5 * (hi - lo);
    return std::min({p.z() - 0.005, wall_y - p.y(), boxSdf(p, c, h)});
  }
  /// z-depth of the nearest hit along the ray o + t d (d's z component in the camera is 1).
  double hit(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
    double t = std::numeric_limits<double>::infinity();
    if (d.z() < 0.0) t = std::min(t, (0.005 - o.z()) / d.z());
    if (d.y() > 0.0) t = std::min(t, (wall_y - o.y()) / d.y());
    double enter = 0.0, leave = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
      enter = std::max(enter, std::min(a, b));
      leave = std::min(leave, std::max(a, b));
    }
    if (enter <= leave) t = std::min(t, enter);
    return t;
  }
};

/// What the cameras of the room's circle (1.7 m radius, 1.4 m high) that see the board leave
/// of it in a 2 cm map: vertices more than a voxel off every surface (ghosts), those in the gap
/// behind the board, and the share of the board's top samples the frames see that is meshed.
struct ShelfResult {
  std::size_t frames = 0, ghosts = 0, in_gap = 0, seen = 0;
  double covered = 0.0;
};

ShelfResult fuseShelf(const ShelfAgainstAWall& scene, const PinholeCamera& camera) {
  TsdfConfig c;
  c.voxel_size_m = 0.02;
  TsdfMap map(c);
  std::vector<Eigen::Isometry3d> circle;
  for (int k = 0; k < 30; ++k) {
    const double a = 2.0 * M_PI * k / 30;
    const Eigen::Isometry3d pose =
        lookAt({1.7 * std::cos(a), 1.7 * std::sin(a), 1.4}, {0.0, 0.0, 0.5});
    const Eigen::Vector3d board = pose.inverse() * Eigen::Vector3d(1.0, 1.7, 1.1);
    if (board.z() > 0.0 && std::abs(board.x() / board.z()) <= 0.6) circle.push_back(pose);
  }
  const auto [poses, depths] = fuseFrames(&map, camera, circle, [&](const Eigen::Isometry3d& pose) {
    return castDepth(camera, pose, [&](const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
      return scene.hit(o, d);
    });
  });
  ShelfResult r;
  r.frames = poses.size();
  const TriangleMesh mesh = meshOf(map);
  for (const Eigen::Vector3f& vf : mesh.vertices) {
    const Eigen::Vector3d v = vf.cast<double>();
    if (std::abs(scene.sdf(v)) <= 0.02) continue;
    ++r.ghosts;
    r.in_gap += v.y() > scene.hi.y() && v.y() < scene.wall_y && v.z() > 1.0 && v.z() < 1.2;
  }
  r.covered = coveredShare(camera, poses, depths, mesh,
                           gridOn({scene.lo.x() + 0.03, scene.lo.y() + 0.03, scene.hi.z()},
                                  {scene.hi.x() - scene.lo.x() - 0.06, 0.0, 0.0},
                                  {0.0, scene.hi.y() - scene.lo.y() - 0.06, 0.0}),
                           &r.seen);
  std::printf("%zu frames; ghost vertices %zu, in the gap %zu; board top covered %.3f of %zu\n",
              r.frames, r.ghosts, r.in_gap, r.covered, r.seen);
  return r;
}

}  // namespace

TEST(DepthRims, ABoardSeenAtGrazingInFrontOfAWallLeavesTheGapBehindItEmpty) {
  // The wall's pixels just above the board's far edge continue the board's plane within the
  // plane test's tolerance (the board steps by more than the 10 cm gap per pixel); they lie
  // beyond that plane's continuation, though, and form a plane of their own: the board ends
  // there, a rim, and its band does not run on into the gap (a mesh sheet there, 3-5 cm off
  // every surface: 102 vertices before). The board's top stays meshed. Cameras on the room's
  // circle (1.7 m radius) 1.4 m high, at 640 x 480: the board's top 4-8 degrees from the line
  // of sight, and every ray over its far edge meets the wall below the board's plane (from
  // lower down, at 1.3 m, some pass so close over the edge that they meet the wall above it: a
  // board touching the wall would give the same image, and some of the sheet remains).
  const ShelfResult r = fuseShelf(ShelfAgainstAWall(), vgaCamera());
  ASSERT_GE(r.frames, 5u);  // the cameras with the board in view
  ASSERT_GT(r.seen, 300u);
  EXPECT_EQ(r.in_gap, 0u);
  EXPECT_GT(r.covered, 0.99);
}

TEST(DepthRims, AFarBoardTopSteppingMoreThanMuPerPixelIsMeshedAndItsGapStaysEmpty) {
  // The board of the test above seen at 320 x 240: its top, 4-8 degrees from the line of sight,
  // steps by more than mu per pixel, so no neighbour lies within mu and the first look knows no
  // incidence (mu along the ray, 5-6 mm under the top). The top 1.5 cm above a plane of voxel
  // centres (the furnished room's shelf at offset 3/4): those voxels were never reached and the
  // top stayed unmeshed (0.36 of it covered). The second look takes the incidence from the
  // plane its pixels form and bounds the reach by the rims and by the steps one side continues
  // (the board's far edge, whose wall pixels continue its plane): 0.72 covered, the gap empty.
  ShelfAgainstAWall scene;
  scene.hi.z() = 1.135;
  const ShelfResult r = fuseShelf(scene, benchmarkCamera());
  ASSERT_GE(r.frames, 5u);
  ASSERT_GT(r.seen, 100u);
  EXPECT_EQ(r.in_gap, 0u);
  EXPECT_EQ(r.ghosts, 0u);
  EXPECT_GT(r.covered, 0.65);  // 0.72; 0.36 without the second look
}

TEST(DepthRims, AWallSeenAtGrazingKeepsItsReachIntoTheCornerItMakesWithTheWallAcross) {
  // The corridor's far end (bench_tsdf_accuracy): its side wall, 5-9 m away at grazing
  // incidence, steps by more than mu per pixel and meets the end wall across; the end wall's
  // pixels form a plane of their own, and the side wall's continuation would still match them.
  // A concave corner, not an occluding edge: there the end wall's pixels lie before the side
  // wall's continuation, and the side wall's last pixel is predicted exactly only by its own
  // plane, so the side wall keeps its reach up to the corner: 0.93 of its samples beside the
  // corner meshed, as before the occluding-edge test (0.78 with rims wherever the end wall
  // forms a plane of its own; 0.88 when the last pixel's fit was not compared); 0.98 with the
  // second look (the side wall's plane gives its far pixels an incidence and a reach).
  const AxisPlanes hit{{{2, 0.0, -1}, {1, -1.2, -1}, {0, 9.0, +1}}};  // floor, side, end wall
  const PinholeCamera camera = benchmarkCamera();
  TsdfConfig c;
  c.voxel_size_m = 0.02;
  TsdfMap map(c);
  std::vector<Eigen::Isometry3d> walk;
  for (int k = 0; k < 8; ++k) walk.push_back(corridorPose(k, -0.2));
  const auto [poses, depths] = fuseFrames(&map, camera, walk, [&](const Eigen::Isometry3d& pose) {
    return castDepth(camera, pose, hit);
  });
  std::size_t seen = 0;
  const double covered =
      coveredShare(camera, poses, depths, meshOf(map),
                   gridOn({8.4, -1.2, 0.1}, {0.56, 0.0, 0.0}, {0.0, 0.0, 1.78}), &seen);
  std::printf("side wall by the corner covered %.3f of %zu\n", covered, seen);
  ASSERT_GT(seen, 200u);
  EXPECT_GT(covered, 0.95);
}

TEST(DepthRims, ConfigChecksTheNewSettingsAndNamesInertOnes) {
  TsdfConfig c;
  EXPECT_EQ(c.validate(), "");
  EXPECT_EQ(c.inertSettings(), "");
  TsdfConfig bad = c;
  bad.edge_guard_rim_scale = 0.0;
  EXPECT_NE(bad.validate().find("edge_guard_rim_scale"), std::string::npos);
  bad = c;
  bad.grazing_reach_voxels = std::nan("");
  EXPECT_NE(bad.validate().find("grazing_reach_voxels"), std::string::npos);
  bad = c;
  bad.grazing_reach_max_voxels = 1e9;
  EXPECT_NE(bad.validate().find("grazing_reach_max_voxels"), std::string::npos);
  bad = c;
  bad.edge_guard_rule = static_cast<TsdfConfig::EdgeGuardRule>(7);
  EXPECT_NE(bad.validate().find("edge_guard_rule"), std::string::npos);
  TsdfConfig inert = c;
  inert.edge_guard_grazing_voxels = 3.0;  // a fixed_radius setting under rim_distance
  EXPECT_NE(inert.inertSettings().find("edge_guard_grazing_voxels"), std::string::npos);
  inert.edge_guard_rule = TsdfConfig::EdgeGuardRule::kFixedRadius;
  EXPECT_EQ(inert.inertSettings(), "");
  inert.edge_guard_rim_scale = 2.0;
  EXPECT_NE(inert.inertSettings().find("edge_guard_rim_scale"), std::string::npos);
}
