// Configuration of the 3-D voxel obstacle map (VoxelMap), with costmap_2d VoxelLayer's keys and
// meaning where it has them. Every field has a documented default and unit; validate() names the
// first invalid field (NaN, Inf, out of range) instead of letting it reach the arithmetic.
#pragma once

#include <cstddef>
#include <string>

#include "downstream_perception/core/costmap/log_odds_grid.h"

namespace downstream_perception {

struct VoxelMapConfig {
  /// Edge of a voxel in x and y, m (the layer uses the costmap's resolution). Default 0.05.
  double resolution_m = 0.05;
  /// Height of a voxel, m (costmap_2d VoxelLayer `z_resolution`). Default 0.2.
  double z_resolution_m = 0.2;
  /// Height of the bottom of voxel layer 0, m (costmap_2d `origin_z`). Default 0.
  double origin_z_m = 0.0;
  /// Voxels per column (costmap_2d `z_voxels`, there at most 16; here at most kMaxZVoxels).
  /// Default 10.
  int z_voxels = 10;
  /// A column with MORE than this many occupied voxels in the height band is lethal (costmap_2d
  /// `mark_threshold`). Default 0: one occupied voxel marks.
  int mark_threshold = 0;
  /// A column with AT MOST this many unknown voxels is known; a known column that is not lethal
  /// is free, any other is unknown (costmap_2d `unknown_threshold`). Counted as costmap_2d
  /// counts: the band's unknown voxels plus 16 - band when the band has fewer than 16 voxels
  /// (costmap_2d's 16-bit column). Default 15: with 10 voxels, a column is free once one of its
  /// voxels is known, and unknown until then.
  int unknown_threshold = 15;
  /// The robot's height band, m: only voxels whose centre lies in [min, max] are projected into
  /// the 2-D costmap (an overhang above the robot is kept in 3-D but ignored). Defaults 0 and 2.
  double min_obstacle_height_m = 0.0;
  double max_obstacle_height_m = 2.0;  ///< top of the band projected into the costmap, m
  /// Inverse sensor model per voxel. Defaults: p_hit 0.7 (+0.847), p_miss 0.4 (-0.405), clamp
  /// [-2, 3.5] (octomap's 0.12 / 0.97), occupied above 0.5 (one hit marks, as in costmap_2d),
  /// free below -0.3 (one miss frees).
  LogOddsConfig log_odds{0.7, 0.4, -2.0, 3.5, 0.5, -0.3};
  /// Time constant of the decay toward unknown, s: evidence is multiplied by exp(-dt / tau) for
  /// the time dt since the voxel's last update. 0 = no decay (costmap_2d has none). Default 0.
  double decay_time_s = 0.0;
  /// Memory bound for the voxel blocks, MiB. Updates that would need a block beyond it are
  /// dropped and counted. Default 64.
  double max_memory_mib = 64.0;

  static constexpr int kMaxZVoxels = 1024;

  /// Empty if valid, else a message naming the first offending field and value.
  std::string validate() const;
  /// Height of the top of the column, m.
  double topZ() const { return origin_z_m + z_voxels * z_resolution_m; }
};

/// Per observation source: how far rays mark and clear (costmap_2d `obstacle_range`,
/// `raytrace_range`), and how far a no-return ray clears.
struct VoxelRayConfig {
  double obstacle_max_range_m = 2.5;  ///< returns farther than this do not mark (3-D distance)
  double raytrace_max_range_m = 3.0;  ///< rays clear at most this far, m
  double no_return_range_m = 3.0;     ///< a no-return ray clears this far, m
  bool marking = true;                ///< returns mark their voxel
  bool clearing = true;               ///< rays clear the voxels they cross
  /// Of the rays of a frame that end in the same voxel, cast only the first (every return still
  /// marks). Each cast ray is still walked exactly; a voxel crossed only by a skipped ray (beside
  /// the cast one, near the end, where rays to one voxel diverge by less than a voxel) is not
  /// cleared in that frame. Trades that for far fewer rays: a 640x480 depth image has ~40 pixels
  /// per 5 cm voxel at 4 m. Default false (every ray exact, costmap_2d's behaviour).
  bool one_ray_per_end_voxel = false;

  std::string validate() const;
};

}  // namespace downstream_perception
