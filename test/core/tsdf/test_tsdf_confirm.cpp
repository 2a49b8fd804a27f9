// Unconfirmed voxels (TsdfConfig::confirm_depth_voxels, issue 22 defect 4): a voxel only ever
// seen deep behind a surface fuses but stays out of the mesh; the room's table top (a 4 cm slab,
// mu = 8 cm, seen only from above) no longer grows a skirt below its underside.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "downstream_perception/core/tsdf/esdf.h"
#include "downstream_perception/core/tsdf/marching_cubes.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "esdf_test_helpers.h"
#include "tsdf_test_helpers.h"
#include "tsdf_test_scenes.h"

using namespace downstream_perception;        // NOLINT
using namespace downstream_perception::test;  // NOLINT

TEST(TsdfConfirm, AnUpdateThatDoesNotConfirmKeepsTheWeightNegativeUntilOneDoes) {
  TsdfConfig c;
  c.max_weight = 3.0;
  const TsdfMap map(c);
  TsdfVoxel v;
  v = map.fused(v, -1.0f, 1.0f, false);  // first seen deep behind a surface
  EXPECT_FLOAT_EQ(v.distance, -1.0f);
  EXPECT_FLOAT_EQ(v.weight, -1.0f);
  EXPECT_FLOAT_EQ(v.observedWeight(), 1.0f);
  v = map.fused(v, -0.5f, 1.0f, false);  // the magnitude fuses as a weight does
  EXPECT_FLOAT_EQ(v.distance, -0.75f);
  EXPECT_FLOAT_EQ(v.weight, -2.0f);
  v = map.fused(v, -0.5f, 1.0f, false);
  v = map.fused(v, -0.5f, 1.0f, false);
  EXPECT_FLOAT_EQ(v.weight, -3.0f);     // capped at max_weight, still unconfirmed
  v = map.fused(v, 0.25f, 1.0f, true);  // seen in front of a surface: confirmed
  EXPECT_FLOAT_EQ(v.weight, 3.0f);
  EXPECT_GT(v.distance, -0.5f);
  v = map.fused(v, -1.0f, 1.0f, false);  // a later deep view does not take it back
  EXPECT_FLOAT_EQ(v.weight, 3.0f);
  // A zero-weight observation of an unobserved voxel leaves it unobserved.
  const TsdfVoxel untouched = map.fused(TsdfVoxel{}, -1.0f, 0.0f, false);
  EXPECT_EQ(untouched.observedWeight(), 0.0f);
  EXPECT_FALSE(untouched.weight < 0.0f);
}

TEST(TsdfConfirm, TheMeshLeavesUnconfirmedVoxelsOutAndTheEsdfReadsThem) {
  // A plane x = 3.5 (1 m voxels): voxels x <= 3 in front (D > 0), x >= 4 behind (D < 0).
  TsdfConfig c = lessonConfig();
  TsdfMap map(c);
  fill(&map, {0, -2, -2}, {7, 2, 2},
       [](const Eigen::Vector3d& p) { return std::clamp((3.5 - p.x()) / 4.0, -1.0, 1.0); });
  // (fill writes weight 1 everywhere: every voxel confirmed)
  const std::size_t triangles = meshOf(map).triangles.size();
  ASSERT_GT(triangles, 0u);
  // Make the behind side unconfirmed: no crossing is left to mesh.
  for (int x = 4; x <= 7; ++x) {
    for (int y = -2; y <= 2; ++y) {
      for (int z = -2; z <= 2; ++z) {
        const Eigen::Vector3i voxel(x, y, z);
        TsdfVoxel& v = map.allocate(TsdfMap::blockOf(voxel))->voxels[TsdfMap::localIndex(voxel)];
        v.weight = -v.weight;
      }
    }
  }
  EXPECT_EQ(meshOf(map).triangles.size(), 0u);
  // The ESDF, the slice and queries still read it: inside evidence for a planner.
  const TsdfVoxel* behind = map.voxel({5, 0, 0});
  ASSERT_NE(behind, nullptr);
  EXPECT_LT(behind->weight, 0.0f);
  EXPECT_EQ(esdfStateOf(*behind, static_cast<float>(c.min_weight)), EsdfState::kOccupied);
}

namespace {

struct SlabCount {
  std::size_t skirt = 0;    ///< vertices more than a voxel below the table top's underside
  std::size_t surface = 0;  ///< vertices within a voxel of a true surface
};

/// The benchmark's room (sim.scenes.room) seen by its 320 x 240 camera from the 30 poses of its
/// circle, the scene moved off the lattice by `offset_m` on every axis. Rendered once and fused
/// under several settings (the sphere tracing costs more than the fusion, most of all under the
/// sanitizers).
struct RoomFrames {
  RoomScene scene;
  PinholeCamera camera = benchmarkCamera();
  std::vector<Eigen::Isometry3d> poses;
  std::vector<std::vector<float>> depths;
};

RoomFrames roomFrames(double offset_m) {
  RoomFrames frames;
  frames.scene.offset = Eigen::Vector3d::Constant(offset_m);
  for (int i = 0; i < 30; ++i) {
    Eigen::Isometry3d pose = circlePose(i, 30);
    pose.translation() += frames.scene.offset;
    frames.poses.push_back(pose);
    frames.depths.push_back(renderDepth(frames.camera, pose, frames.scene));
  }
  return frames;
}

/// `frames` fused into a map with the settings `c`; counts of the mesh's vertices under the
/// table top's footprint (x -1.2..-0.4, y 0.4..1.0; the top spans z 0.72..0.76) more than a
/// voxel below its underside and above the floor's band.
SlabCount tableTopSkirt(const TsdfConfig& c, const RoomFrames& frames) {
  TsdfMap map(c);
  DepthIntegrator integrator;
  for (std::size_t i = 0; i < frames.poses.size(); ++i) {
    integrator.integrate(&map, frames.depths[i].data(), frames.camera, frames.poses[i]);
  }
  SlabCount count;
  for (const Eigen::Vector3f& vf : meshOf(map).vertices) {
    const Eigen::Vector3d v = vf.cast<double>();
    const Eigen::Vector3d p = v - frames.scene.offset;
    count.surface += std::abs(frames.scene(v)) <= c.voxel_size_m;
    const bool under_top = p.x() > -1.22 && p.x() < -0.38 && p.y() > 0.38 && p.y() < 1.02;
    count.skirt += under_top && p.z() < 0.72 - c.voxel_size_m && p.z() > 0.2;
  }
  return count;
}

/// A fronto-parallel wall `wall_m` along the optical axis of the benchmark camera at the origin,
/// fused `frames` times into `map`.
void seeWallAt(TsdfMap* map, double wall_m, int frames) {
  const PinholeCamera camera = benchmarkCamera();
  const std::vector<float> depth(static_cast<std::size_t>(camera.width) * camera.height,
                                 static_cast<float>(wall_m));
  for (int frame = 0; frame < frames; ++frame) {
    DepthIntegrator().integrate(map, depth.data(), camera, Eigen::Isometry3d::Identity());
  }
}

/// 2 cm voxels, the given confirm depth, the other settings' defaults.
TsdfConfig withConfirmDepth(double confirm_depth_voxels) {
  TsdfConfig c;
  c.voxel_size_m = 0.02;
  c.confirm_depth_voxels = confirm_depth_voxels;
  return c;
}

}  // namespace

TEST(TsdfConfirm, TheTableTopGrowsNoSkirtBelowItsUnderside) {
  for (const double offset : {0.0, 0.75}) {
    const TsdfConfig unconfirmed = withConfirmDepth(0.0);
    const RoomFrames frames = roomFrames(offset * unconfirmed.voxel_size_m);
    const SlabCount off = tableTopSkirt(unconfirmed, frames);
    TsdfConfig confirm_only = withConfirmDepth(TsdfConfig().confirm_depth_voxels);
    confirm_only.far_free_guess_weight = 1.0;
    const SlabCount on = tableTopSkirt(confirm_only, frames);
    const SlabCount defaults =
        tableTopSkirt(withConfirmDepth(TsdfConfig().confirm_depth_voxels), frames);
    std::printf(
        "offset %.2f voxel: skirt vertices %zu (off %zu, with far_free_guess_weight %zu); surface "
        "vertices %zu (off %zu, with far_free_guess_weight %zu)\n",
        offset, on.skirt, off.skirt, defaults.skirt, on.surface, off.surface, defaults.surface);
    EXPECT_GT(off.skirt, 20u) << offset;  // the skirt this guards against is there without it
    EXPECT_LE(on.skirt, off.skirt / 4) << offset;
    EXPECT_LE(defaults.skirt, on.skirt) << offset;
    // The real surfaces stay: within a voxel of them, at least 99.9 % of the vertices with the
    // confirm rule, 99.8 % with far_free_guess_weight too (it removed 0.11 % at offset 3/4 when
    // written, where the accuracy bench's completeness did not move in its fourth decimal).
    EXPECT_GE(static_cast<double>(on.surface), 0.999 * static_cast<double>(off.surface)) << offset;
    EXPECT_GE(static_cast<double>(defaults.surface), 0.998 * static_cast<double>(off.surface))
        << offset;
  }
}

TEST(TsdfConfirm, ConfigChecksTheDepthAndNamesItInertWithoutIncidences) {
  TsdfConfig c;
  EXPECT_EQ(c.confirm_depth_voxels, 2.5);
  for (const double bad : {-0.5, 65.0, std::nan(""), HUGE_VAL}) {
    c.confirm_depth_voxels = bad;
    EXPECT_NE(c.validate().find("confirm_depth_voxels"), std::string::npos) << bad;
  }
  c.confirm_depth_voxels = 0.0;
  EXPECT_EQ(c.validate(), "");
  c.confirm_depth_voxels = 3.0;
  EXPECT_EQ(c.inertSettings(), "");
  c.edge_guard_rad = 0.0;  // no rim rule ...
  EXPECT_EQ(c.inertSettings(), "");
  c.grazing_reach_voxels = 0.0;  // ... and no grazing reach: no incidence is estimated
  EXPECT_NE(c.inertSettings().find("confirm_depth_voxels"), std::string::npos);
}

// At 5 cm the 4 cm slab is thinner than a voxel. The voxels a voxel or two under it are seen
// behind the top by the frames above it and free by the frames looking past it under the table.
// With the confirm depth at 2.5 voxels (12.5 cm) they confirmed and meshed a skirt 6-10 cm below
// the underside (the accuracy bench's ghosts at 5 cm). Capped at 6.25 cm most do not; where
// frames also see them free, equal weights still average to "inside". A lower
// unconfirmed_update_weight lets the free space win everywhere, and far_free_guess_weight (the
// default) where frames saw the voxel far free: no skirt on any lattice phase either way.
TEST(TsdfConfirm, AtFiveCentimetresTheSlabGrowsNoFarSideWhereFramesSeeItFree) {
  std::size_t capped_total = 0, deep_total = 0;
  for (const double offset : {0.0, 0.25, 0.5, 0.75}) {
    TsdfConfig defaults;
    defaults.voxel_size_m = 0.05;
    const RoomFrames frames = roomFrames(offset * defaults.voxel_size_m);
    const SlabCount far_free_wins = tableTopSkirt(defaults, frames);
    TsdfConfig c = defaults;  // guesses at full weight everywhere: the cap alone
    c.far_free_guess_weight = 1.0;
    const SlabCount capped = tableTopSkirt(c, frames);
    TsdfConfig uncapped = c;
    uncapped.confirm_depth_max_m = 0.0;
    const SlabCount deep = tableTopSkirt(uncapped, frames);
    TsdfConfig weighted = c;
    weighted.unconfirmed_update_weight = 0.05;
    const SlabCount free_wins = tableTopSkirt(weighted, frames);
    std::printf(
        "5 cm, offset %.2f voxel: skirt vertices %zu (cap alone %zu, no cap %zu, weight 0.05 "
        "%zu); surface %zu (%zu, %zu, %zu)\n",
        offset, far_free_wins.skirt, capped.skirt, deep.skirt, free_wins.skirt,
        far_free_wins.surface, capped.surface, deep.surface, free_wins.surface);
    EXPECT_GT(deep.skirt, 20u) << offset;  // what the cap guards against
    EXPECT_LE(capped.skirt, deep.skirt) << offset;
    capped_total += capped.skirt;
    deep_total += deep.skirt;
    EXPECT_EQ(free_wins.skirt, 0u) << offset;
    EXPECT_EQ(far_free_wins.skirt, 0u) << offset;
    for (const SlabCount& kept : {capped, free_wins, far_free_wins}) {
      EXPECT_GE(static_cast<double>(kept.surface), 0.99 * static_cast<double>(deep.surface))
          << offset;
    }
  }
  EXPECT_LE(capped_total, deep_total / 2);  // 71 against 191 when written
}

// The confirm depth: confirm_depth_voxels voxels, capped at confirm_depth_max_m, never below
// kConfirmDepthFloorVoxels; 0 = no cap.
TEST(TsdfConfirm, TheConfirmDepthIsCappedInMetresAboveAFloorInVoxels) {
  TsdfConfig c;
  EXPECT_EQ(c.confirm_depth_max_m, 0.05);
  const std::vector<std::pair<double, double>> voxel_depth = {
      {0.01, 0.025}, {0.02, 0.05}, {0.03, 0.05}, {0.05, 0.0625}, {0.1, 0.125}};
  for (const auto& [voxel, depth] : voxel_depth) {
    c.voxel_size_m = voxel;
    EXPECT_NEAR(c.confirmDepth(), depth, 1e-12) << voxel;
  }
  c.voxel_size_m = 0.05;
  c.confirm_depth_max_m = 0.0;  // no cap
  EXPECT_NEAR(c.confirmDepth(), 0.125, 1e-12);
  c.confirm_depth_voxels = 1.0;  // below the floor: the user's depth
  c.confirm_depth_max_m = 0.05;
  EXPECT_NEAR(c.confirmDepth(), 0.05, 1e-12);
  for (const double bad : {-0.01, 101.0, std::nan(""), HUGE_VAL}) {
    c.confirm_depth_max_m = bad;
    EXPECT_NE(c.validate().find("confirm_depth_max_m"), std::string::npos) << bad;
  }
  c.confirm_depth_max_m = 0.1;
  EXPECT_EQ(c.validate(), "");
  EXPECT_EQ(c.inertSettings(), "");
  c.confirm_depth_voxels = 0.0;
  EXPECT_NE(c.inertSettings().find("confirm_depth_max_m"), std::string::npos);
}

// The two weight factors of non-confirming updates: unconfirmed_update_weight (default 1) and
// far_free_guess_weight (default 0.05), in (0, 1]; neither acts without the confirm rule or
// without incidences.
TEST(TsdfConfirm, ConfigChecksTheGuessWeightsAndNamesThemInertWithoutConfirmation) {
  const struct {
    const char* name;
    double TsdfConfig::*member;
    double default_value;
  } factors[] = {{"unconfirmed_update_weight", &TsdfConfig::unconfirmed_update_weight, 1.0},
                 {"far_free_guess_weight", &TsdfConfig::far_free_guess_weight, 0.05}};
  for (const auto& factor : factors) {
    TsdfConfig c;
    EXPECT_EQ(c.*factor.member, factor.default_value) << factor.name;
    for (const double bad : {0.0, -0.1, 1.01, std::nan(""), HUGE_VAL}) {
      c.*factor.member = bad;
      EXPECT_NE(c.validate().find(factor.name), std::string::npos) << factor.name << " " << bad;
    }
    c.*factor.member = 0.2;
    EXPECT_EQ(c.validate(), "") << factor.name;
    EXPECT_EQ(c.inertSettings(), "") << factor.name;
    c.confirm_depth_voxels = 0.0;  // every update confirms: no guess, no unconfirmed voxel
    EXPECT_NE(c.inertSettings().find(factor.name), std::string::npos);
    c.confirm_depth_voxels = TsdfConfig().confirm_depth_voxels;
    c.edge_guard_rad = 0.0;
    c.grazing_reach_voxels = 0.0;  // no incidences: no update is deep along a normal
    EXPECT_NE(c.inertSettings().find(factor.name), std::string::npos);
  }
}

// Along the optical axis of a fronto-parallel wall (incidence 0, no rim near): a voxel a voxel
// behind the wall confirms at full weight; one three voxels behind (deeper than the confirm
// depth, within mu) fuses at unconfirmed_update_weight per frame and stays unconfirmed, with the
// frame's value; 1 fuses it at full weight, still unconfirmed.
TEST(TsdfConfirm, ANonConfirmingUpdateFusesAtTheLowerWeight) {
  for (const double scale : {0.05, 0.3, 1.0}) {
    TsdfConfig c;
    c.voxel_size_m = 0.02;
    c.confirm_depth_voxels = 2.5;
    c.unconfirmed_update_weight = scale;
    TsdfMap map(c);
    seeWallAt(&map, 1.0, 2);
    const TsdfVoxel* near = map.voxel({0, 0, 51});  // 2 cm behind the wall at 1 m
    const TsdfVoxel* deep = map.voxel({0, 0, 53});  // 6 cm behind: deeper than 2.5 voxels
    ASSERT_NE(near, nullptr);
    ASSERT_NE(deep, nullptr);
    EXPECT_FLOAT_EQ(near->weight, 2.0f) << scale;
    EXPECT_NEAR(near->distance * c.truncation(), -0.02, 1e-4) << scale;
    EXPECT_FLOAT_EQ(deep->weight, static_cast<float>(-2.0 * scale)) << scale;
    EXPECT_NEAR(deep->distance * c.truncation(), -0.06, 1e-4) << scale;
  }
}

namespace {

/// 2 cm voxels, mu 8 cm, the confirm depth 5 cm along the axis; the voxel watched is {0, 0, 53}
/// (z 1.06 m): far free with the wall at 1.16 m (10 cm > mu in front), a non-confirming guess with
/// it at 1 m (6 cm behind), a confirming inside update with it at 1.03 m (3 cm behind).
TsdfConfig farFreeConfig(double far_free_guess_weight) {
  TsdfConfig c;
  c.voxel_size_m = 0.02;
  c.far_free_guess_weight = far_free_guess_weight;
  return c;
}

const Eigen::Vector3i kWatched(0, 0, 53);

}  // namespace

// Seen far free twice (D = +1, weight 2), then guessed inside once (D = -6/8): the guess fuses at
// far_free_guess_weight; 1 fuses it at full weight, as before the rule.
TEST(TsdfFarFree, AGuessOnAVoxelSeenFarFreeFusesAtTheLowerWeight) {
  for (const double factor : {0.05, 0.3, 1.0}) {
    TsdfMap map(farFreeConfig(factor));
    seeWallAt(&map, 1.16, 2);
    const TsdfVoxel* v = map.voxel(kWatched);
    ASSERT_NE(v, nullptr);
    EXPECT_FLOAT_EQ(v->distance, 1.0f) << factor;
    EXPECT_FLOAT_EQ(v->weight, 2.0f) << factor;
    seeWallAt(&map, 1.0, 1);
    const double guess = -0.06 / map.config().truncation();
    EXPECT_NEAR(v->weight, 2.0 + factor, 1e-5) << factor;  // confirmed already: stays positive
    EXPECT_NEAR(v->distance, (2.0 + factor * guess) / (2.0 + factor), 1e-4) << factor;
  }
}

// Guessed inside twice first (unconfirmed, weight -2), then seen far free once: the far-free
// update fuses at 1 / far_free_guess_weight times its weight and confirms the voxel, so the order
// of the frames does not decide which evidence wins.
TEST(TsdfFarFree, FarFreeOnAnUnconfirmedVoxelFusesAtTheInverseWeight) {
  for (const double factor : {0.05, 0.3, 1.0}) {
    TsdfMap map(farFreeConfig(factor));
    seeWallAt(&map, 1.0, 2);
    const TsdfVoxel* v = map.voxel(kWatched);
    ASSERT_NE(v, nullptr);
    const double guess = -0.06 / map.config().truncation();
    EXPECT_NEAR(v->distance, guess, 1e-4) << factor;
    EXPECT_FLOAT_EQ(v->weight, -2.0f) << factor;
    seeWallAt(&map, 1.16, 1);
    const double boost = 1.0 / factor;
    EXPECT_NEAR(v->weight, 2.0 + boost, 1e-3) << factor;
    EXPECT_NEAR(v->distance, (2.0 * guess + boost) / (2.0 + boost), 1e-4) << factor;
    EXPECT_EQ(v->distance > 0.0f, factor < 1.0) << factor;  // at equal weights the guesses win
  }
}

// Seen far free once, then inside from nearer (confirming, 3 cm behind) until it reads inside:
// a later guess agrees with it and fuses at full weight (the rule only guards voxels that read
// free).
TEST(TsdfFarFree, AGuessOnAVoxelThatReadsInsideFusesAtFullWeight) {
  TsdfMap map(farFreeConfig(0.05));
  seeWallAt(&map, 1.16, 1);
  seeWallAt(&map, 1.03, 3);
  const TsdfVoxel* v = map.voxel(kWatched);
  ASSERT_NE(v, nullptr);
  const double mu = map.config().truncation();
  const double inside = (1.0 - 3.0 * 0.03 / mu) / 4.0;
  ASSERT_LT(inside, 0.0);
  EXPECT_NEAR(v->distance, inside, 1e-4);
  EXPECT_FLOAT_EQ(v->weight, 4.0f);
  seeWallAt(&map, 1.0, 1);
  EXPECT_FLOAT_EQ(v->weight, 5.0f);
  EXPECT_NEAR(v->distance, (4.0 * inside - 0.06 / mu) / 5.0, 1e-4);
}
