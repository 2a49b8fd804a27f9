// Multi-object tracker: detections in, tracks with stable ids, velocities and covariances out.
//
// SORT's structure (a constant-velocity Kalman filter per track, global assignment, birth and
// death rules) with three changes that matter on a robot:
//  - metric mode: tracks live in a fixed frame and associate under a chi-square gate on the
//    squared Mahalanobis distance (the detection's own covariance when it has one), so a
//    coasting track's growing uncertainty widens its gate and re-acquires the object after an
//    occlusion. The assignment cost is the negative log-likelihood d^2 + ln det S, so a wide
//    coasting track does not win a detection from a well-localised neighbour just because its
//    d^2 is small. A track confirmed right after an occlusion the gate could not bridge takes
//    the coasting track's id (re-identification); image mode keeps SORT's IoU association;
//  - time-based prediction (dt from the stamps) with acceleration noise in physical units;
//  - ByteTrack's second pass: detections below `high_score` may still continue existing tracks
//    (never start new ones).
// Ids are never reused. Track states: tentative until min_hits updates (a tentative track that
// misses an update is dropped; with confirm_at_start, first-frame births with a high enough
// score skip this), then confirmed; a confirmed track without a detection coasts
// (prediction only) up to max_age_s and is then deleted.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "downstream_perception/core/tracking/box.h"
#include "downstream_perception/core/tracking/kalman.h"

namespace downstream_perception {

enum class TrackState : std::uint8_t { kTentative = 0, kConfirmed = 1, kCoasting = 2 };

struct Detection {
  int class_id = -1;   ///< -1: unknown class (associates with any class)
  double score = 1.0;  ///< detector confidence in [0, 1]
  // Metric mode: position (m) in the tracking frame and its covariance (m^2); a zero covariance
  // means "use TrackerConfig::measurement_std".
  double x = 0.0;
  double y = 0.0;
  double cov_xx = 0.0;
  double cov_xy = 0.0;
  double cov_yy = 0.0;
  double size_x = 0.0;  ///< m, carried to the track (footprints)
  double size_y = 0.0;
  Box box;            ///< image mode: pixels
  int truth_id = -1;  ///< ground-truth object id when known (simulation): ID-switch counting
};

struct TrackerConfig {
  /// Image mode: largest accepted |box coordinate| (px). Far above any sensor's resolution;
  /// a box at 1e308 px made the track covariance infinite.
  static constexpr double kMaxBoxCoordinatePx = 1e6;
  /// Metric mode: largest accepted |position| and size (m), and (its square) covariance entry
  /// (m^2). Above every earth-fixed frame (UTM northings < 1e7 m, ECEF < 6.4e6 m), far below
  /// where the filter's arithmetic would overflow.
  static constexpr double kMaxPositionM = 1e8;
  /// Largest max_age_s (s): a coasting track holds memory until it dies.
  static constexpr double kMaxAgeS = 3600.0;
  /// Largest |stamp| (s) step() takes: ROS time ends at 2^32 s; beyond, dt^3 overflows.
  static constexpr double kMaxStampS = 1e10;

  enum class Mode { kMetric, kImage };
  /// The member initialisers below are the metric defaults (a default-constructed config is
  /// metric, as it always was). Image mode has its own defaults: start from defaultsFor(kImage).
  Mode mode = Mode::kMetric;
  double gate_confidence = 0.999;  ///< chi-square gate (metric): 2 dof, 0.99 -> 9.21, 0.999 -> 13.8
  /// Metric mode: a coasting track this close (chi-square gate, 2 dof, sum of both position
  /// covariances) to a track born while it coasted and updated this frame is its duplicate and
  /// is removed. 0.9 -> 4.61, about 0.3 m at 0.1 m uncertainty.
  double duplicate_confidence = 0.9;
  /// Metric mode: a track confirmed this frame takes the id of a track that was already coasting
  /// at its birth when their positions agree within this chi-square gate (2 dof, sum of
  /// covariances): re-identification after an occlusion the gate could not bridge.
  /// 0.99999 -> 23.0.
  double reid_confidence = 0.99999;
  double min_iou = 0.3;  ///< image mode: minimum IoU to associate
  /// Image mode: how each association pass chooses among the pairs its gate allows. true (the
  /// member default, and SORT's gated Hungarian): as many pairs as possible first, then the
  /// largest summed IoU. false (image default, see defaultsFor): the largest summed (IoU -
  /// min_iou), ByteTrack's lapjv with a cost limit, so a pair is made only where it beats
  /// leaving both unmatched: a coasting track next to a person no longer takes that person's
  /// detection so that the person's own track can take a poor one (a false positive, a
  /// neighbour's box), which handed identities over. Metric mode always maximises the pairs (its
  /// cost has no fixed limit; the chi-square gate decides which pairs may be).
  bool maximize_matches = true;
  /// Spectral density of the white acceleration noise. Metric: m^2/s^3 per axis. Image: box
  /// heights^2/s^3 (px^2/s^3 per px^2 of box height), so it scales with the apparent size.
  double accel_psd = 0.5;
  /// Metric: m, position noise of detections without a covariance. Image: box heights (std of
  /// each of centre x, centre y, width and height in px per px of box height).
  double measurement_std = 0.1;
  double initial_velocity_std = 1.0;  ///< m/s (metric) or box heights/s (image)
  /// Updates before a track is confirmed; a tentative track that misses one is dropped. Image
  /// default 2 (see defaultsFor).
  int min_hits = 3;
  /// Start-up confirmation (ByteTrack's frame-1 rule): in the tracker's first frame (the first
  /// step() after construction or reset()), a track born from a detection whose score is at
  /// least start_confirm_score is confirmed at once instead of waiting min_hits updates, so the
  /// objects present at start-up are reported from the first frame, as ByteTrack and SORT do.
  /// Tracks born later, and first-frame ones below the score, follow min_hits. Only the first
  /// step() counts, even when it holds no detections (ByteTrack's frame_id == 1). Image default
  /// true, metric false (see defaultsFor): on the metric scenes it gained MOTA and IDF1 but
  /// added ID switches (docs/tracker.md).
  bool confirm_at_start = false;
  /// Score in [0, 1] a first-frame detection needs for start-up confirmation. ByteTrack's
  /// det_thresh = track_thresh + 0.1: 0.6 with high_score 0.5. Births need high_score anyway.
  double start_confirm_score = 0.6;
  double max_age_s = 1.5;   ///< s a confirmed track coasts without detections (both modes)
  double high_score = 0.5;  ///< detections at or above: first pass, may start tracks
  double low_score = 0.1;   ///< below: ignored; in between: second pass only
  bool second_pass = true;  ///< ByteTrack's low-score association
  bool class_aware = true;  ///< tracks only take detections of their class

  /// Empty if valid, else the reason.
  std::string validate() const;

  /// The documented defaults of a mode. Metric: the member initialisers. Image (chosen on the
  /// pinhole scenes of sim.image_scene, several seeds, 25 and 30 fps; docs/tracker.md, "Tracking
  /// core"): the same noise levels read in box heights, and min_hits 2, because with 3 a person who
  /// is missed once in the first frames is dropped and found again frames later (recall).
  /// Image mode also confirms first-frame tracks at once (confirm_at_start), as ByteTrack does.
  static TrackerConfig defaultsFor(Mode mode);
  /// The parameters whose default in `mode` differs from the metric one, by their YAML / field
  /// name, with the mode's value (a bool as 0 / 1): what a node applies to the keys its user left
  /// unset.
  static std::vector<std::pair<std::string, double>> modeSpecificDefaults(Mode mode);
};

struct Track {
  std::uint64_t id = 0;
  int class_id = -1;
  TrackState state = TrackState::kTentative;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< m (metric) or box centre (px)
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< m/s or px/s
  Eigen::Matrix2d position_cov = Eigen::Matrix2d::Zero();
  Eigen::Matrix2d velocity_cov = Eigen::Matrix2d::Zero();
  double size_x = 0.0;  ///< m (metric, last detection's) or box width (px)
  double size_y = 0.0;  ///< m or box height (px)
  double score = 0.0;   ///< last associated detection's score
  int hits = 0;         ///< detections associated so far
  double age_s = 0.0;   ///< since birth
  double time_since_update_s = 0.0;
  int truth_id = -1;  ///< last associated detection's truth id
  Box box() const { return Box::fromCenter(position.x(), position.y(), size_x, size_y); }
};

struct TrackerStats {
  std::size_t detections = 0;                    ///< detections given to step()
  std::size_t detections_ignored_low_score = 0;  ///< scores below low_score
  /// NaN/Inf, boxes with min > max or no area, negative sizes, covariances that are not
  /// positive semi-definite
  std::size_t detections_rejected_invalid = 0;
  /// Finite but beyond TrackerConfig::kMaxBoxCoordinatePx (image) or kMaxPositionM (metric)
  std::size_t detections_rejected_out_of_range = 0;
  std::size_t matched_first_pass = 0;      ///< high-score detections assigned to a track
  std::size_t matched_second_pass = 0;     ///< low-score detections assigned (ByteTrack's pass)
  std::size_t unmatched_outside_gate = 0;  ///< high-score detections no track could take
  std::size_t births = 0;                  ///< new tentative tracks
  std::size_t deaths = 0;                  ///< includes duplicates removed
  std::size_t duplicates_removed = 0;      ///< coasting tracks removed as duplicates of new ones
  std::size_t reidentified = 0;            ///< new tracks that took a coasting track's id
  std::size_t id_switches = 0;  ///< truth objects whose track id changed (needs truth ids)
  std::size_t tracks = 0;       ///< live tracks after the step (every state)
  std::size_t confirmed = 0;    ///< of them confirmed or coasting
  void accumulate(const TrackerStats& o);
};

class Tracker {
 public:
  /// Throws std::invalid_argument if the config is invalid.
  explicit Tracker(const TrackerConfig& config = {});
  ~Tracker();
  Tracker(Tracker&&) noexcept;
  Tracker& operator=(Tracker&&) noexcept;

  /// One frame at time `stamp_s` (s, strictly increasing: one stamp is one frame, so a stamp
  /// equal to or older than the last is rejected with std::invalid_argument and changes
  /// nothing; merge the detections of one instant into one call). Predicts every track to the
  /// stamp, associates, updates, manages births and deaths. Returns this frame's statistics.
  TrackerStats step(double stamp_s, const std::vector<Detection>& detections);
  /// Every live track (tentative, confirmed, coasting), oldest first.
  const std::vector<Track>& tracks() const;
  /// For each detection of the last step: the id of the track that took it, or 0.
  const std::vector<std::uint64_t>& lastAssignment() const;
  const TrackerConfig& config() const;
  /// New thresholds for a running tracker (tracks are kept). Throws std::invalid_argument if
  /// the config is invalid or changes the mode.
  void setConfig(const TrackerConfig& config);
  void reset();

  struct Impl;  ///< implementation detail (one per mode), defined in tracker.cpp

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace downstream_perception
