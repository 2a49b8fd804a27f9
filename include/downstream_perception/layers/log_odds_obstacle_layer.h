// downstream_perception/LogOddsObstacleLayer: LaserScan, PointCloud and PointCloud2 sources
// (costmap_2d's source keys, meanings and defaults) integrated into a
// log-odds grid (hit/miss increments, clamp, exact ray clearing, REP-117 semantics), each
// message placed with the transform at its own stamp. The master gets LETHAL
// (l > occupied_log_odds), FREE (l < free_log_odds) or, for cells in between, nothing (they keep
// what the master holds). Also: footprint clearing, costmap_2d's combination_method, optional
// time decay of evidence toward unknown, rolling-window shifts, dynamic_reconfigure, and
// clear_tracked_objects: the evidence under confirmed tracks is forgotten at each update, so a
// moving object is drawn once, by the TrackedObstacleLayer's prediction, without a trail of its
// past returns.
#pragma once

#include <limits>
#include <memory>
#include <mutex>
#include <vector>

#include "downstream_perception/LogOddsObstacleLayerConfig.h"
#include "downstream_perception/core/costmap/log_odds_costs.h"
#include "downstream_perception/core/costmap/log_odds_grid.h"
#include "downstream_perception/layers/observation/observation_source.h"
#include "downstream_perception/layers/track_inbox.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/param_reader.h"
#include "downstream_perception/ros/common/reconfigure_host.h"
#include "downstream_perception/ros/costmap/layer.h"

namespace downstream_perception {

/// The layer's own settings besides the sensor model (YAML / dynamic_reconfigure keys).
struct ObstacleLayerConfig {
  CombinationMethod combination_method = CombinationMethod::kMaximum;  ///< costmap_2d's default
  bool footprint_clearing_enabled = true;
  double decay_time_s = 0.0;  ///< s, time constant of the fade toward unknown; 0 = off
  bool clear_tracked_objects = false;
  double tracked_clearing_margin_m = 0.1;  ///< m: growth of each track's box before clearing
  double max_obstacle_height = 2.0;        ///< m, costmap_2d's layer key: no marks above it
};

class LogOddsObstacleLayer : public Layer {
 public:
  LogOddsObstacleLayer() = default;
  ~LogOddsObstacleLayer() override;

  void updateBounds(double robot_x, double robot_y, double robot_yaw, double* min_x, double* min_y,
                    double* max_x, double* max_y) override;
  void updateCosts(Costmap& master, int min_i, int min_j, int max_i, int max_j) override;
  void matchSize() override;
  void shiftOrigin(int dx, int dy) override;
  void reset() override;
  void onClockJump() override;
  void activate() override;
  void deactivate() override;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) override;
  /// Names the silent source(s) and their topics when the layer is not current.
  std::string notCurrentReason() const override;

 protected:
  void onInitialize() override;
  /// Subclasses read their own keys of the layer namespace here (before unknown keys are named).
  virtual void readLayerParams(ParamReader& reader) { (void)reader; }
  /// m, global frame: a subclass's own upper marking limit (FlatVoxelLayer: its voxel column's
  /// top); combined with max_obstacle_height. Set in readLayerParams().
  double extra_mark_limit_z_ = std::numeric_limits<double>::infinity();
  /// A WARN about a key of this layer (kept for diagnostics).
  void warnParam(const std::string& msg);

 private:
  void reconfigure(LogOddsObstacleLayerConfig& config, std::uint32_t level);
  void readSources(const std::string& names);
  /// Gives every source the grid's current geometry (CloudBeamsConfig::merge_grid).
  void setMergeGrids();
  /// The marking limit min(max_obstacle_height, extra_mark_limit_z_) into every source; WARNs
  /// once per source whose own band reaches above it.
  void applyMarkLimit(double max_obstacle_height);
  /// WARNs (throttled, per source) for silent sources and topics without a publisher.
  void warnSourceProblems();
  /// costmap_2d's obstacle_range / raytrace_range into *ic (unless ours are set at the source);
  /// returns "; obstacle_range from <key>..." for the start-up line, or "".
  std::string readCostmap2dRanges(const ros::NodeHandle& source_nh, const std::string& source,
                                  ScanIntegratorConfig* ic);
  void integrate(ObservationSource& source, const Observation& observation);
  void markAllDirty();
  void clearFootprint(double robot_x, double robot_y, double robot_yaw);
  void decay();
  void clearTrackedObjects();

  std::mutex grid_mutex_;  ///< guards grid_, dirty_, evidence_box_
  LogOddsGrid grid_;
  LogOddsConfig grid_config_;
  ObstacleLayerConfig config_;
  CellBounds dirty_;         ///< cells whose state changed since the last updateBounds
  CellBounds evidence_box_;  ///< every cell that ever received evidence (decay works here)
  ros::Time last_decay_;
  std::size_t cells_decayed_to_unknown_ = 0;
  std::size_t footprint_cells_cleared_ = 0;
  std::vector<std::size_t> footprint_scratch_;
  TrackInbox track_inbox_;  ///< confirmed tracks, for clear_tracked_objects
  ros::Time last_track_clearing_;
  std::size_t tracked_cells_cleared_ = 0;
  std::size_t tracks_cleared_last_ = 0;
  bool track_unknown_space_ = true;
  std::vector<std::unique_ptr<ObservationSource>> sources_;
  std::vector<ros::WallTime> source_warned_;  ///< per source: last throttled WARN
  std::vector<bool> band_cut_warned_;         ///< per source: the mark-limit WARN was given
  mutable std::mutex param_warnings_mutex_;
  std::vector<std::string> param_warnings_;  ///< wrong types, unsupported and unknown keys
  ConfigErrorLog config_errors_;
  ReconfigureHost<LogOddsObstacleLayerConfig> reconfigure_;
};

}  // namespace downstream_perception
