#include "downstream_perception/layers/log_odds_obstacle_layer.h"

#include <pluginlib/class_list_macros.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "downstream_perception/core/costmap/footprint.h"
#include "downstream_perception/layers/observation/laser_scan_source.h"
#include "downstream_perception/layers/observation/point_cloud_source.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/timing_diagnostics.h"
#include "downstream_perception/ros/costmap/layered_costmap.h"

namespace downstream_perception {

namespace {

// The scans over seen space each clearing walk ran (kAuto's timed choice, walk_chooser.h), the
// shared (two-thread) walks summed: "per ray / blocks / reverse query / first visit / shared".
// Read under grid_mutex_, which integrate() holds.
std::string walkRunsText(const ScanIntegrator& integrator) {
  const auto& runs = integrator.walkChooser().runs();
  const auto shared = runs[WalkChooser::kPerRayShared] + runs[WalkChooser::kBlocksShared] +
                      runs[WalkChooser::kFirstVisitShared];
  return std::to_string(runs[WalkChooser::kPerRay]) + " / " +
         std::to_string(runs[WalkChooser::kBlocks]) + " / " +
         std::to_string(runs[WalkChooser::kReverseQuery]) + " / " +
         std::to_string(runs[WalkChooser::kFirstVisit]) + " / " + std::to_string(shared);
}
// Decay runs at most this often: each pass scans the evidence box once.
constexpr double kMinDecayPeriodS = 0.1;
// Tracked-object clearing reaches this far behind the older of (the track's stamp, the previous
// clearing): a scan integrated since the previous update may be stamped up to its latency earlier.
constexpr double kClearingSensorLatencyS = 0.1;
// ... and never further back than this (the first clearing, a long pause).
constexpr double kMaxClearingLookbackS = 1.0;
// A subscribed topic with no publisher after this long is named (a publisher may start late).
constexpr double kNoPublisherGraceS = 5.0;
// A silent source or a topic without a publisher is logged at most this often, per source.
constexpr double kSourceWarnPeriodS = 10.0;
}  // namespace

LogOddsObstacleLayer::~LogOddsObstacleLayer() {
  // Stop the callbacks before the grid they write into goes away.
  reconfigure_.stop();
  track_inbox_.unsubscribe();
  sources_.clear();
}

void LogOddsObstacleLayer::onInitialize() {
  config_errors_.setPrefix("layer '" + name_ + "'");
  ParamReader reader(nh_, "layer '" + name_ + "'");
  // costmap_2d's ObstacleLayer keys, in its lookup order, with its defaults.
  track_unknown_space_ = layered_costmap_->isTrackingUnknown();
  reader.get("track_unknown_space", &track_unknown_space_);
  double transform_tolerance = 0.2;
  reader.get("transform_tolerance", &transform_tolerance);
  if (!std::isfinite(transform_tolerance) || transform_tolerance < 0.0) {
    config_errors_.add("transform_tolerance must be finite and >= 0 s, got " +
                       std::to_string(transform_tolerance));
  }
  std::string names;
  reader.get("observation_sources", &names);
  // The dynamic_reconfigure keys: type-checked here (the server drops a wrong-typed value without
  // a word), read by the server below.
  for (const char* key : {"enabled", "footprint_clearing_enabled", "clear_tracked_objects"}) {
    bool unused = false;
    reader.get(key, &unused);
  }
  for (const char* key :
       {"p_hit", "p_miss", "log_odds_min", "log_odds_max", "occupied_log_odds", "free_log_odds",
        "tracked_clearing_margin_m", "max_obstacle_height", "decay_time_s"}) {
    double unused = 0.0;
    reader.get(key, &unused);
  }
  int combination = 0;
  reader.get("combination_method", &combination);
  // Found from each source by searchParam (costmap_2d's lookup), so they may sit here.
  reader.known({"obstacle_range", "raytrace_range"});
  grid_ = LogOddsGrid(layered_costmap_->costmap().geometry(), grid_config_);
  readSources(names);
  setMergeGrids();
  {
    std::istringstream stream(names);
    std::string name;
    while (stream >> name) reader.known({name});  // each source's own namespace
  }
  TrackInboxConfig tracks;
  tracks.include_tentative = false;  // only confirmed tracks: a tentative one may be clutter and
  tracks.include_coasting = false;   // a coasting one is not where the sensor sees its returns
  reader.get("tracks_topic", &tracks.topic);
  reader.get("track_timeout_s", &tracks.track_timeout_s);
  reader.get("tracks_tf_queue_size", &tracks.tf_queue_size);
  const std::string why = tracks.validate();
  if (!why.empty()) {
    config_errors_.add("tracks for clear_tracked_objects: " + why + "; using the defaults");
    tracks = TrackInboxConfig();
    tracks.include_coasting = false;
  }
  track_inbox_.setConfig(tracks);
  readLayerParams(reader);
  reader.warnUnknown();
  {
    std::lock_guard<std::mutex> lock(param_warnings_mutex_);
    for (const auto& w : reader.warnings()) param_warnings_.push_back(w);
  }
  // The server reads the YAML values (or the .cfg defaults, equal to the C++ ones) and calls
  // reconfigure() once at once: one code path for start-up and live changes.
  reconfigure_.start(nh_, this, &LogOddsObstacleLayer::reconfigure);
}

void LogOddsObstacleLayer::warnParam(const std::string& msg) {
  ROS_WARN("layer '%s': %s", name_.c_str(), msg.c_str());
  std::lock_guard<std::mutex> lock(param_warnings_mutex_);
  param_warnings_.push_back(msg);
}

void LogOddsObstacleLayer::reconfigure(LogOddsObstacleLayerConfig& cfg, std::uint32_t) {
  // Each key (or the sensor model as a group) is validated when the request changes it. A
  // rejected value is written back into `cfg`: the server stores and publishes what the callback
  // leaves there, so it shows the value in use and a later change of another key does not send
  // the rejected one again. Its error stays in diagnostics until a request sets a valid value.
  LogOddsConfig model;
  model.p_hit = cfg.p_hit;
  model.p_miss = cfg.p_miss;
  model.clamp_min = cfg.log_odds_min;
  model.clamp_max = cfg.log_odds_max;
  model.occupied_threshold = cfg.occupied_log_odds;
  model.free_threshold = cfg.free_log_odds;
  if (model != grid_config_) {
    const std::string why = model.validate();
    if (why.empty()) {
      config_errors_.clear("sensor model");
    } else {
      config_errors_.set("sensor model", "sensor model invalid (" + why + "); keeping p_hit " +
                                             std::to_string(grid_config_.p_hit) + ", p_miss " +
                                             std::to_string(grid_config_.p_miss) +
                                             " and the previous limits");
      model = grid_config_;
      cfg.p_hit = model.p_hit;
      cfg.p_miss = model.p_miss;
      cfg.log_odds_min = model.clamp_min;
      cfg.log_odds_max = model.clamp_max;
      cfg.occupied_log_odds = model.occupied_threshold;
      cfg.free_log_odds = model.free_threshold;
    }
  }
  ObstacleLayerConfig layer = config_;
  if (cfg.combination_method != static_cast<int>(config_.combination_method)) {
    const std::string why = validateCombinationMethod(cfg.combination_method);
    if (why.empty()) {
      layer.combination_method = static_cast<CombinationMethod>(cfg.combination_method);
      config_errors_.clear("combination_method");
    } else {
      config_errors_.set(
          "combination_method",
          why + "; keeping " + std::to_string(static_cast<int>(config_.combination_method)));
      cfg.combination_method = static_cast<int>(config_.combination_method);
    }
  }
  const auto check = [this](const char* key, double* requested, double in_use, bool valid,
                            const std::string& rule, double* target) {
    if (*requested == in_use) return;  // unchanged: a kept error stays
    if (valid) {
      *target = *requested;
      config_errors_.clear(key);
      return;
    }
    config_errors_.set(key, std::string(key) + " " + rule + ", got " + std::to_string(*requested) +
                                "; keeping " + std::to_string(in_use));
    *requested = in_use;
  };
  check("decay_time_s", &cfg.decay_time_s, config_.decay_time_s,
        std::isfinite(cfg.decay_time_s) && cfg.decay_time_s >= 0.0,
        "must be finite and >= 0 s (0 = off)", &layer.decay_time_s);
  check("tracked_clearing_margin_m", &cfg.tracked_clearing_margin_m,
        config_.tracked_clearing_margin_m,
        std::isfinite(cfg.tracked_clearing_margin_m) && cfg.tracked_clearing_margin_m >= 0.0 &&
            cfg.tracked_clearing_margin_m <= 2.0,
        "must be in [0, 2] m", &layer.tracked_clearing_margin_m);
  check("max_obstacle_height", &cfg.max_obstacle_height, config_.max_obstacle_height,
        std::isfinite(cfg.max_obstacle_height), "must be finite (m)", &layer.max_obstacle_height);
  layer.footprint_clearing_enabled = cfg.footprint_clearing_enabled;
  layer.clear_tracked_objects = cfg.clear_tracked_objects;
  applyMarkLimit(layer.max_obstacle_height);
  {
    std::lock_guard<std::mutex> lock(grid_mutex_);
    grid_config_ = model;
    if (grid_.config() != model) {
      grid_.setConfig(model);  // thresholds may have moved: every state is re-read
    }
    config_ = layer;
    last_decay_ = ros::Time();
  }
  markAllDirty();
  const bool was_enabled = enabled_;
  enabled_ = cfg.enabled;
  // Subscribed exactly while enabled (activate/deactivate are idempotent); the tracks while
  // clear_tracked_objects is on, too.
  if (enabled_) {
    activate();
  } else {
    deactivate();
  }
  // The layer's cells appear or disappear from the master: redraw all of it.
  if (was_enabled != enabled_) layered_costmap_->requestFullRedraw();
  ROS_INFO(
      "layer '%s': p_hit %.3f p_miss %.3f, log-odds in [%.2f, %.2f], occupied > %.2f, "
      "free < %.2f, combination %d, footprint clearing %s, max_obstacle_height %.2f m, decay "
      "time %.2f s, tracked-object clearing %s, %s",
      name_.c_str(), model.p_hit, model.p_miss, model.clamp_min, model.clamp_max,
      model.occupied_threshold, model.free_threshold, static_cast<int>(layer.combination_method),
      layer.footprint_clearing_enabled ? "on" : "off", layer.max_obstacle_height,
      layer.decay_time_s,
      layer.clear_tracked_objects ? ("on (" + track_inbox_.config().topic + ", margin " +
                                     std::to_string(layer.tracked_clearing_margin_m) + " m)")
                                        .c_str()
                                  : "off",
      enabled_ ? "enabled" : "disabled");
}

std::string LogOddsObstacleLayer::readCostmap2dRanges(const ros::NodeHandle& source_nh,
                                                      const std::string& source,
                                                      ScanIntegratorConfig* ic) {
  // costmap_2d's obstacle_range / raytrace_range: the maximum marking / clearing range, looked
  // up like costmap_2d does (searchParam from the source's namespace up: source, layer,
  // costmap, ...). Our *_max_range keys at the source, when given, win (and a conflict is named).
  std::string from;
  const auto take = [&](const char* theirs, const char* ours, double* value) {
    std::string key;
    XmlRpc::XmlRpcValue raw;
    if (!source_nh.searchParam(theirs, key) || !source_nh.getParam(key, raw)) return;
    double v = 0.0;
    const std::string wrong = convertParam(raw, &v);
    if (!wrong.empty()) {
      warnParam("source '" + source + "': parameter " + key + " " + wrong + "; ignored");
      return;
    }
    if (source_nh.hasParam(ours)) {
      if (v != *value) {
        ROS_WARN("layer '%s', source '%s': both %s (%s = %.3f) and %s (%.3f) are set; using %s",
                 name_.c_str(), source.c_str(), theirs, key.c_str(), v, ours, *value, ours);
      }
      return;
    }
    *value = v;
    from += std::string(from.empty() ? "; " : ", ") + theirs + " from " + key;
  };
  take("obstacle_range", "obstacle_max_range", &ic->obstacle_max_range);
  take("raytrace_range", "raytrace_max_range", &ic->raytrace_max_range);
  return from;
}

void LogOddsObstacleLayer::readSources(const std::string& names) {
  std::istringstream stream(names);
  std::string name;
  while (stream >> name) {
    ros::NodeHandle snh(nh_, name);
    ParamReader reader(snh, "layer '" + name_ + "', source '" + name + "'");
    ObservationSourceConfig config;
    ScanIntegratorConfig& ic = config.integrator;
    // costmap_2d's keys, in its lookup order, with its defaults.
    config.topic = name;
    reader.get("topic", &config.topic);
    reader.get("sensor_frame", &config.sensor_frame);
    reader.get("observation_persistence", &config.observation_persistence);
    reader.get("expected_update_rate", &config.expected_update_rate);
    std::string data_type = "PointCloud";
    reader.get("data_type", &data_type);
    config.cloud.min_obstacle_height = 0.0;
    config.cloud.max_obstacle_height = 2.0;
    reader.get("min_obstacle_height", &config.cloud.min_obstacle_height);
    reader.get("max_obstacle_height", &config.cloud.max_obstacle_height);
    bool inf_is_valid = false;
    reader.get("inf_is_valid", &inf_is_valid);
    ic.clearing = false;
    ic.marking = true;
    reader.get("clearing", &ic.clearing);
    reader.get("marking", &ic.marking);
    // Ours (docs/costmap.md): finer ranges, REP-117 no-return clearing, tf queue, de-skew.
    ic.inf_is_valid = false;
    reader.get("inf_is_no_return", &ic.inf_is_valid);
    reader.get("range_max_is_no_return", &ic.range_max_is_no_return);
    reader.get("tf_queue_size", &config.tf_queue_size);
    reader.get("per_beam_time_correction", &config.per_beam_time_correction);
    reader.get("obstacle_min_range", &ic.obstacle_min_range);
    reader.get("obstacle_max_range", &ic.obstacle_max_range);
    reader.get("raytrace_min_range", &ic.raytrace_min_range);
    reader.get("raytrace_max_range", &ic.raytrace_max_range);
    reader.known({"obstacle_range", "raytrace_range"});
    const std::string ranges_from = readCostmap2dRanges(snh, name, &ic);
    reader.warnUnknown();
    {
      std::lock_guard<std::mutex> lock(param_warnings_mutex_);
      for (const auto& w : reader.warnings())
        param_warnings_.push_back("source '" + name + "': " + w);
    }
    if (data_type != "LaserScan" && data_type != "PointCloud" && data_type != "PointCloud2") {
      config_errors_.add("source '" + name + "': data_type '" + data_type +
                         "' is not supported (LaserScan, PointCloud or PointCloud2); source "
                         "ignored");
      continue;
    }
    const bool is_scan = data_type == "LaserScan";
    if (inf_is_valid && !is_scan) {
      warnParam("source '" + name + "': inf_is_valid does not apply to " + data_type +
                " observations (as in costmap_2d); ignored");
    } else if (inf_is_valid && ic.inf_is_valid) {
      warnParam("source '" + name +
                "': inf_is_valid and inf_is_no_return are both true; using "
                "inf_is_no_return (+Inf clears up to raytrace range and marks nothing)");
    } else if (inf_is_valid) {
      config.costmap2d_inf_is_valid = true;  // costmap_2d's meaning: a return at range_max
    }
    if (config.observation_persistence > 0.0) {
      warnParam("source '" + name + "': observation_persistence " +
                std::to_string(config.observation_persistence) +
                " s differs from costmap_2d: there each observation of the last " +
                "observation_persistence seconds is marked again at every update (a mark "
                "outlives later clearing that long); here each observation is integrated once "
                "(integrating the same measurement again would count it many times over) and its "
                "evidence lasts until later misses outweigh it (see decay_time_s)");
    }
    std::string why;
    if (!std::isfinite(config.expected_update_rate) || config.expected_update_rate < 0.0) {
      why = "expected_update_rate must be finite and >= 0 s (0 = off), got " +
            std::to_string(config.expected_update_rate);
    }
    if (why.empty()) why = ic.validate();
    if (why.empty()) why = config.cloud.validate();
    if (config.tf_queue_size < 1 || config.tf_queue_size > 10000) {
      why = "tf_queue_size must be in [1, 10000], got " + std::to_string(config.tf_queue_size);
    }
    if (!why.empty()) {
      config_errors_.add("source '" + name + "': " + why + "; source ignored");
      continue;
    }
    auto on_observation = [this](ObservationSource& source, const Observation& observation) {
      integrate(source, observation);
    };
    if (is_scan) {
      sources_.push_back(std::make_unique<LaserScanSource>(
          name, config, topic_nh_, *tf_, layered_costmap_->globalFrame(), on_observation));
    } else {
      sources_.push_back(std::make_unique<PointCloudSource>(
          name, config, topic_nh_, *tf_, layered_costmap_->globalFrame(), on_observation,
          data_type == "PointCloud"));
    }
    source_warned_.emplace_back();
    band_cut_warned_.push_back(false);
    ROS_INFO(
        "layer '%s': %s source '%s' on %s (%s%s, mark <= %.2f m, clear <= %.2f m%s, heights "
        "[%.2f, %.2f] m, +Inf %s, expected_update_rate %.2f s)",
        name_.c_str(), data_type.c_str(), name.c_str(),
        ros::names::resolve(topic_nh_.getNamespace(), config.topic).c_str(),
        ic.marking ? "marking" : "not marking", ic.clearing ? ", clearing" : ", not clearing",
        ic.obstacle_max_range, ic.raytrace_max_range, ranges_from.c_str(),
        config.cloud.min_obstacle_height, config.cloud.max_obstacle_height,
        !is_scan                        ? "n/a"
        : ic.inf_is_valid               ? "clears (inf_is_no_return)"
        : config.costmap2d_inf_is_valid ? "is a return at range_max (inf_is_valid)"
                                        : "ignored",
        config.expected_update_rate);
  }
  if (sources_.empty()) {
    ROS_WARN("layer '%s': no usable observation_sources; the layer will stay empty", name_.c_str());
  }
}

void LogOddsObstacleLayer::applyMarkLimit(double max_obstacle_height) {
  const double limit = std::min(max_obstacle_height, extra_mark_limit_z_);
  for (std::size_t k = 0; k < sources_.size(); ++k) {
    ObservationSource& source = *sources_[k];
    source.setMarkHeightLimit(limit);
    const double top = source.config().cloud.max_obstacle_height;
    if (top > limit && !band_cut_warned_[k]) {
      band_cut_warned_[k] = true;
      std::ostringstream msg;
      msg << "source '" << source.name() << "': points between the layer's marking limit " << limit
          << " m and the source's max_obstacle_height " << top
          << " m neither mark nor clear here; costmap_2d lets them clear (not mark)";
      warnParam(msg.str());
    }
  }
}

void LogOddsObstacleLayer::integrate(ObservationSource& source, const Observation& observation) {
  const auto t0 = std::chrono::steady_clock::now();
  IntegrationStats stats;
  {
    std::lock_guard<std::mutex> lock(grid_mutex_);
    stats = source.integrator().integrate(grid_, observation.beams, observation.decisions);
    // Only cells whose state changed alter this layer's output: that is the window the master
    // must refresh (a sensor sweeping an unchanged room costs no re-inflation downstream).
    dirty_.expand(stats.changed);
    evidence_box_.expand(stats.touched);
  }
  const auto t1 = std::chrono::steady_clock::now();
  const double age = (ros::Time::now() - observation.stamp).toSec();
  source.recordIntegration(stats, std::chrono::duration<double, std::milli>(t1 - t0).count(), age);
  if (!stats.changed.empty()) layered_costmap_->notifyDataArrived(observation.stamp);
}

void LogOddsObstacleLayer::clearFootprint(double robot_x, double robot_y, double robot_yaw) {
  // The robot stands there: whatever a sensor saw in its footprint (its own body, a stale
  // obstacle) is free. Caller holds grid_mutex_.
  footprint_scratch_.clear();
  const Footprint world =
      transformFootprint(layered_costmap_->footprint(), Pose2D{robot_x, robot_y, robot_yaw});
  polygonCells(world, grid_.geometry(), &footprint_scratch_);
  for (const std::size_t i : footprint_scratch_) {
    if (grid_.state(i) == CellState::kFree) continue;
    grid_.setLogOdds(i, grid_config_.clamp_min);
    const CellIndex c = grid_.geometry().cellOf(i);
    dirty_.expand(c.x, c.y);
    evidence_box_.expand(c.x, c.y);
    ++footprint_cells_cleared_;
  }
}

void LogOddsObstacleLayer::decay() {
  // Caller holds grid_mutex_.
  const ros::Time now = ros::Time::now();
  if (last_decay_.isZero() || now < last_decay_) {
    last_decay_ = now;
    return;
  }
  const double dt = (now - last_decay_).toSec();
  if (dt < kMinDecayPeriodS) return;
  last_decay_ = now;
  std::size_t changed = 0;
  dirty_.expand(grid_.decay(std::exp(-dt / config_.decay_time_s), evidence_box_, &changed));
  cells_decayed_to_unknown_ += changed;
}

void LogOddsObstacleLayer::clearTrackedObjects() {
  // A confirmed track is drawn by the TrackedObstacleLayer as its prediction; its own returns
  // here would draw it a second time, and leave a trail behind it until enough misses clear
  // them. Positive evidence under the box's recent path goes back to unknown (not free: nothing
  // says the floor under a forklift is free). Caller holds grid_mutex_.
  const ros::Time now = ros::Time::now();
  const FreshTracks fresh = track_inbox_.fresh(now);
  const double since_last =
      last_track_clearing_.isZero() ? 0.0 : std::max(0.0, (now - last_track_clearing_).toSec());
  last_track_clearing_ = now;
  tracks_cleared_last_ = 0;
  const double lookback = std::min(
      kMaxClearingLookbackS, std::max(0.0, since_last - fresh.age_s) + kClearingSensorLatencyS);
  for (const PlanarTrack& t : fresh.tracks) {
    footprint_scratch_.clear();
    const CellBounds b =
        recentCells(t, lookback, fresh.age_s, config_.tracked_clearing_margin_m,
                    PredictionConfig().max_object_size_m, grid_.geometry(), &footprint_scratch_);
    tracks_cleared_last_ += !b.empty();
    for (const std::size_t i : footprint_scratch_) {
      if (grid_.units(i) <= 0) continue;
      grid_.setLogOdds(i, 0.0);
      const CellIndex c = grid_.geometry().cellOf(i);
      dirty_.expand(c.x, c.y);
      ++tracked_cells_cleared_;
    }
  }
}

void LogOddsObstacleLayer::updateBounds(double robot_x, double robot_y, double robot_yaw,
                                        double* min_x, double* min_y, double* max_x,
                                        double* max_y) {
  bool current = true;
  for (const auto& source : sources_) current = current && source->isCurrent();
  current_ = current;
  warnSourceProblems();
  std::lock_guard<std::mutex> lock(grid_mutex_);
  if (config_.decay_time_s > 0.0) decay();
  if (config_.footprint_clearing_enabled && layered_costmap_->hasRobotPose()) {
    clearFootprint(robot_x, robot_y, robot_yaw);
  }
  if (config_.clear_tracked_objects) clearTrackedObjects();
  grid_.geometry().expandWorldBox(dirty_, min_x, min_y, max_x, max_y);
  dirty_ = CellBounds{};
}

void LogOddsObstacleLayer::warnSourceProblems() {
  const ros::WallTime now = ros::WallTime::now();
  for (std::size_t k = 0; k < sources_.size(); ++k) {
    std::string why = sources_[k]->notCurrentReason();
    if (why.empty()) why = sources_[k]->noPublisherReason(kNoPublisherGraceS);
    if (why.empty()) continue;
    // One line per source per period (a ROS_WARN_THROTTLE site is shared by all sources).
    if (!source_warned_[k].isZero() && (now - source_warned_[k]).toSec() < kSourceWarnPeriodS) {
      continue;
    }
    source_warned_[k] = now;
    ROS_WARN("layer '%s': %s", name_.c_str(), why.c_str());
  }
}

std::string LogOddsObstacleLayer::notCurrentReason() const {
  std::string reasons;
  for (const auto& source : sources_) {
    const std::string why = source->notCurrentReason();
    if (why.empty()) continue;
    reasons += (reasons.empty() ? "layer '" + name_ + "': " : "; ") + why;
  }
  return reasons;
}

void LogOddsObstacleLayer::updateCosts(Costmap& master, int min_i, int min_j, int max_i,
                                       int max_j) {
  std::lock_guard<std::mutex> lock(grid_mutex_);
  if (grid_.geometry() != master.geometry()) return;  // matchSize() pending
  CellBounds window;
  window.expand(min_i, min_j);
  window.expand(max_i - 1, max_j - 1);
  // Unknown cells write nothing when tracking unknown space: costmap_2d's updateWithOverwrite
  // never writes NO_INFORMATION over what the master holds.
  writeStateCosts(grid_, window, !track_unknown_space_, cost::kFreeSpace, &master,
                  config_.combination_method);
}

void LogOddsObstacleLayer::markAllDirty() {
  std::lock_guard<std::mutex> lock(grid_mutex_);
  const GridGeometry& g = grid_.geometry();
  dirty_ = CellBounds{};
  dirty_.expand(0, 0);
  dirty_.expand(g.sizeX() - 1, g.sizeY() - 1);
}

void LogOddsObstacleLayer::matchSize() {
  {
    std::lock_guard<std::mutex> lock(grid_mutex_);
    const GridGeometry& g = layered_costmap_->costmap().geometry();
    if (grid_.geometry() != g) grid_.resize(g);
    evidence_box_ = CellBounds{};
  }
  setMergeGrids();
  markAllDirty();
}

void LogOddsObstacleLayer::setMergeGrids() {
  // One beam per grid cell of a cloud: the same cells, a fraction of the ray walks. The cells
  // must be this grid's (not squares from the world origin: see CloudBeamsConfig::merge_grid).
  // A cloud converted just before a resize merges on the old cells once.
  GridGeometry geometry;
  {
    std::lock_guard<std::mutex> lock(grid_mutex_);
    geometry = grid_.geometry();
  }
  for (auto& source : sources_) source->setMergeGrid(geometry);
}

void LogOddsObstacleLayer::shiftOrigin(int dx, int dy) {
  std::lock_guard<std::mutex> lock(grid_mutex_);
  grid_.shift(dx, dy);
  // Windows move with the content; the host redraws the whole master after a shift.
  for (CellBounds* b : {&dirty_, &evidence_box_}) {
    if (b->empty()) continue;
    b->min_x -= dx;
    b->max_x -= dx;
    b->min_y -= dy;
    b->max_y -= dy;
  }
}

void LogOddsObstacleLayer::onClockJump() {
  {
    std::lock_guard<std::mutex> lock(grid_mutex_);
    last_decay_ = ros::Time();  // decay restarts from the new timeline's next update
    last_track_clearing_ = ros::Time();
  }
  track_inbox_.onClockJump();
}

void LogOddsObstacleLayer::reset() {
  {
    std::lock_guard<std::mutex> lock(grid_mutex_);
    grid_.reset();
    evidence_box_ = CellBounds{};
  }
  markAllDirty();
}

void LogOddsObstacleLayer::activate() {
  for (auto& source : sources_) source->subscribe();
  bool clear_tracked = false;
  {
    std::lock_guard<std::mutex> lock(grid_mutex_);
    clear_tracked = config_.clear_tracked_objects;
  }
  if (clear_tracked) {
    track_inbox_.subscribe(nh_, *tf_, layered_costmap_->globalFrame(), name_);
  } else {
    track_inbox_.unsubscribe();
  }
}

void LogOddsObstacleLayer::deactivate() {
  for (auto& source : sources_) source->unsubscribe();
  track_inbox_.unsubscribe();
}

void LogOddsObstacleLayer::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::size_t n_free = 0;
  std::size_t n_occ = 0;
  std::size_t n_unknown = 0;
  double max_abs = 0.0;
  std::size_t decayed = 0;
  std::size_t footprint_cleared = 0;
  std::size_t tracked_cleared = 0;
  std::size_t tracks_cleared = 0;
  ObstacleLayerConfig config;
  {
    std::lock_guard<std::mutex> lock(grid_mutex_);
    grid_.countStates(&n_free, &n_occ, &n_unknown);
    max_abs = grid_.maxAbsLogOdds();
    decayed = cells_decayed_to_unknown_;
    footprint_cleared = footprint_cells_cleared_;
    tracked_cleared = tracked_cells_cleared_;
    tracks_cleared = tracks_cleared_last_;
    config = config_;
  }
  std::size_t rejected_total = 0;
  std::size_t waiting_total = 0;
  std::string not_current;
  std::string no_publisher;
  bool any_integrated = sources_.empty();
  for (auto& source : sources_) {
    const std::string not_current_why = source->notCurrentReason();
    const std::string no_publisher_why = source->noPublisherReason(kNoPublisherGraceS);
    const bool current = not_current_why.empty();
    if (not_current.empty()) not_current = not_current_why;
    if (no_publisher.empty()) no_publisher = no_publisher_why;
    const std::string p = source->name() + ": ";
    const std::string topic = source->resolvedTopic();
    status.add(p + "topic", topic.empty() ? source->config().topic + " (not subscribed)" : topic);
    status.add(p + "publishers", source->numPublishers());
    status.add(p + "problem", !not_current_why.empty()    ? not_current_why
                              : !no_publisher_why.empty() ? no_publisher_why
                                                          : std::string("none"));
    const CloudBeamsConfig band = source->heightBand();
    status.add(p + "height band (m)", "[" + std::to_string(band.min_obstacle_height) + ", " +
                                          std::to_string(band.max_obstacle_height) + "]");
    status.add(p + "marking", source->config().integrator.marking);
    status.add(p + "clearing", source->config().integrator.clearing);
    std::lock_guard<std::mutex> lock(source->mutex());
    const auto& h = source->health();
    any_integrated = any_integrated || h.integrated > 0;
    status.add(p + "data type", source->dataType());
    status.add(p + "messages received", h.received);
    status.add(p + "messages integrated", h.integrated);
    const std::size_t rejected = source->rejections().report(status, p);
    for (const auto& [what, count] : h.notes) status.add(p + what, count);
    rejected_total += rejected;
    status.add(p + "messages rejected", rejected);
    status.add(p + "transform age at integration mean (s)", h.transform_age_s.mean());
    status.add(p + "transform age at integration max (s)", h.transform_age_s.max);
    status.add(p + "integration time mean (ms)", h.integrate_ms.mean());
    status.add(p + "integration time max (ms)", h.integrate_ms.max);
    addTimingHistogram(status, p + "integration time", "ms", h.integrate_ms.histogram);
    status.add(p + "last message cells cleared", h.last.cells_cleared);
    status.add(p + "last message cells marked", h.last.cells_marked);
    status.add(p + "clear:mark ratio (last message)", h.last.clearMarkRatio());
    status.add(p + "clear:mark ratio (all messages)", h.total.clearMarkRatio());
    status.add(p + "beams invalid (total)", h.total.beams_invalid);
    status.add(p + "beams no return (total)", h.total.beams_no_return);
    status.add(p + "points outside height band (total)", h.total.points_outside_height);
    status.add(p + "points merged into a cell's beam (total)", h.total.points_merged);
    std::string walks;
    {
      std::lock_guard<std::mutex> lock(grid_mutex_);
      walks = walkRunsText(source->integrator());
    }
    status.add(p + "clearing walks run (per ray / blocks / reverse query / first visit / shared)",
               walks);
    status.add(p + "current", current);
    waiting_total += addTfWaits(status, p, source->waitingForTf());
  }
  status.add("cells occupied", n_occ);
  status.add("cells free", n_free);
  status.add("cells unknown", n_unknown);
  status.add("max |log-odds|", max_abs);
  status.add("log-odds clamp", grid_config_.clamp_max);
  status.add("combination method", static_cast<int>(config.combination_method));
  status.add("footprint clearing", config.footprint_clearing_enabled);
  status.add("footprint cells cleared (total)", footprint_cleared);
  status.add("clear tracked objects", config.clear_tracked_objects);
  if (config.clear_tracked_objects) {
    track_inbox_.diagnose(status, "tracks: ");
    status.add("tracks cleared (last update)", tracks_cleared);
    status.add("cells cleared under tracks (total)", tracked_cleared);
  }
  status.add("decay time (s)", config.decay_time_s);
  status.add("cells decayed to another state (total)", decayed);
  status.add("memory (bytes)", grid_.memoryBytes());
  std::vector<std::string> param_warnings;
  {
    std::lock_guard<std::mutex> lock(param_warnings_mutex_);
    param_warnings = param_warnings_;
  }
  addParamWarnings(status, param_warnings);
  if (config_errors_.report(status)) return;  // ERROR, with the first problem
  if (!not_current.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "not current: " + not_current);
  } else if (!no_publisher.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, no_publisher);
  } else if (waiting_total > 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   std::to_string(waiting_total) +
                       " message(s) waiting for tf (see 'waiting for tf from ...')");
  } else if (!any_integrated) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no message integrated yet");
  } else if (rejected_total > 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   std::to_string(rejected_total) + " message(s) rejected (see counts)");
  } else if (!param_warnings.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   std::to_string(param_warnings.size()) +
                       " parameter warning(s), the first: " + param_warnings.front());
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "integrating");
  }
}

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::LogOddsObstacleLayer, downstream_perception::Layer)
