#include "downstream_perception/core/tracking/tracker.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "downstream_perception/core/tracking/assignment.h"

namespace downstream_perception {

std::string TrackerConfig::validate() const {
  std::ostringstream why;
  // Noise levels enter covariances squared (and cubed with dt): beyond 1e6 (m, m/s, px or
  // m^2/s^3) no sensor is meant and the products leave the double range.
  constexpr double kMaxNoise = 1e6;
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0 && v <= kMaxNoise; };
  if (!(gate_confidence > 0.0 && gate_confidence < 1.0)) {
    why << "gate_confidence must be in (0, 1), got " << gate_confidence;
  } else if (!(duplicate_confidence > 0.0 && duplicate_confidence < 1.0)) {
    why << "duplicate_confidence must be in (0, 1), got " << duplicate_confidence;
  } else if (!(reid_confidence > 0.0 && reid_confidence < 1.0)) {
    why << "reid_confidence must be in (0, 1), got " << reid_confidence;
  } else if (!(min_iou >= 0.0 && min_iou <= 1.0)) {
    why << "min_iou must be in [0, 1], got " << min_iou;
  } else if (!positive(accel_psd)) {
    why << "accel_psd must be in (0, 1e6], got " << accel_psd;
  } else if (!positive(measurement_std)) {
    why << "measurement_std must be in (0, 1e6], got " << measurement_std;
  } else if (!positive(initial_velocity_std)) {
    why << "initial_velocity_std must be in (0, 1e6], got " << initial_velocity_std;
  } else if (min_hits < 1 || min_hits > 1000) {
    why << "min_hits must be in [1, 1000], got " << min_hits;
  } else if (!(start_confirm_score >= 0.0 && start_confirm_score <= 1.0)) {
    why << "start_confirm_score must be in [0, 1], got " << start_confirm_score;
  } else if (!(max_age_s >= 0.0 && max_age_s <= kMaxAgeS)) {
    // Bounded: coasting tracks are memory, and one that never dies keeps a slot forever.
    why << "max_age_s must be in [0, 3600] s, got " << max_age_s;
  } else if (!(low_score >= 0.0 && low_score <= high_score && high_score <= 1.0)) {
    why << "need 0 <= low_score <= high_score <= 1, got " << low_score << " and " << high_score;
  }
  return why.str();
}

TrackerConfig TrackerConfig::defaultsFor(Mode mode) {
  TrackerConfig config;
  config.mode = mode;
  if (mode == Mode::kImage) {
    config.min_hits = 2;
    config.confirm_at_start = true;
    config.maximize_matches = false;
  }
  return config;
}

std::vector<std::pair<std::string, double>> TrackerConfig::modeSpecificDefaults(Mode mode) {
  const TrackerConfig metric = defaultsFor(Mode::kMetric);
  const TrackerConfig own = defaultsFor(mode);
  // Every numeric field a YAML can set (the dynamic_reconfigure names).
  const std::vector<std::pair<std::string, std::pair<double, double>>> fields = {
      {"gate_confidence", {metric.gate_confidence, own.gate_confidence}},
      {"duplicate_confidence", {metric.duplicate_confidence, own.duplicate_confidence}},
      {"reid_confidence", {metric.reid_confidence, own.reid_confidence}},
      {"min_iou", {metric.min_iou, own.min_iou}},
      {"accel_psd", {metric.accel_psd, own.accel_psd}},
      {"measurement_std", {metric.measurement_std, own.measurement_std}},
      {"initial_velocity_std", {metric.initial_velocity_std, own.initial_velocity_std}},
      {"min_hits", {metric.min_hits, own.min_hits}},
      {"confirm_at_start", {metric.confirm_at_start, own.confirm_at_start}},
      {"maximize_matches", {metric.maximize_matches, own.maximize_matches}},
      {"start_confirm_score", {metric.start_confirm_score, own.start_confirm_score}},
      {"max_age_s", {metric.max_age_s, own.max_age_s}},
      {"high_score", {metric.high_score, own.high_score}},
      {"low_score", {metric.low_score, own.low_score}},
  };
  std::vector<std::pair<std::string, double>> differing;
  for (const auto& [name, values] : fields) {
    if (values.first != values.second) differing.emplace_back(name, values.second);
  }
  return differing;
}

void TrackerStats::accumulate(const TrackerStats& o) {
  detections += o.detections;
  detections_ignored_low_score += o.detections_ignored_low_score;
  detections_rejected_invalid += o.detections_rejected_invalid;
  detections_rejected_out_of_range += o.detections_rejected_out_of_range;
  matched_first_pass += o.matched_first_pass;
  matched_second_pass += o.matched_second_pass;
  unmatched_outside_gate += o.unmatched_outside_gate;
  births += o.births;
  duplicates_removed += o.duplicates_removed;
  reidentified += o.reidentified;
  deaths += o.deaths;
  id_switches += o.id_switches;
  tracks = o.tracks;
  confirmed = o.confirmed;
}

namespace {

/// Smallest width / height (px) a coasting image box keeps (its size has a velocity too).
constexpr double kMinBoxSizePx = 1.0;

/// Slack (s) on max_age_s: a limit of k frame periods (k / fps) and the age of k frames differ
/// in the last bits (and a ROS stamp near 1.7e9 s is only exact to about 2e-7 s), so without it
/// a track died one frame early for some k. Far below any frame period.
constexpr double kAgeToleranceS = 1e-6;

enum class Verdict { kOk, kInvalid, kOutOfRange };

Verdict checkDetection(const Detection& d, TrackerConfig::Mode mode) {
  if (!std::isfinite(d.score)) return Verdict::kInvalid;
  const auto beyond = [](double v, double limit) { return std::abs(v) > limit; };
  if (mode == TrackerConfig::Mode::kImage) {
    const Box& b = d.box;
    if (!b.validate().empty() || !(b.height() > 0.0) || !(b.width() > 0.0)) {
      return Verdict::kInvalid;
    }
    const double limit = TrackerConfig::kMaxBoxCoordinatePx;
    return beyond(b.x_min, limit) || beyond(b.y_min, limit) || beyond(b.x_max, limit) ||
                   beyond(b.y_max, limit)
               ? Verdict::kOutOfRange
               : Verdict::kOk;
  }
  if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.cov_xx) ||
      !std::isfinite(d.cov_xy) || !std::isfinite(d.cov_yy) || !std::isfinite(d.size_x) ||
      !std::isfinite(d.size_y) || d.size_x < 0.0 || d.size_y < 0.0) {
    return Verdict::kInvalid;
  }
  const double limit = TrackerConfig::kMaxPositionM;
  if (beyond(d.x, limit) || beyond(d.y, limit) || d.size_x > limit || d.size_y > limit ||
      beyond(d.cov_xx, limit * limit) || beyond(d.cov_xy, limit * limit) ||
      beyond(d.cov_yy, limit * limit)) {
    return Verdict::kOutOfRange;
  }
  // A covariance must be symmetric positive semi-definite (all zero = "use the default").
  return d.cov_xx >= 0.0 && d.cov_yy >= 0.0 && d.cov_xx * d.cov_yy - d.cov_xy * d.cov_xy >= 0.0
             ? Verdict::kOk
             : Verdict::kInvalid;
}

}  // namespace

// ------------------------------------------------------------------------------------------
struct Tracker::Impl {
  explicit Impl(const TrackerConfig& c) { setConfig(c); }
  void setConfig(const TrackerConfig& c) {
    config = c;
    gate = chiSquareQuantile(2, c.gate_confidence);
    duplicate_gate = chiSquareQuantile(2, c.duplicate_confidence);
    reid_gate = chiSquareQuantile(2, c.reid_confidence);
  }
  /// ID-switch bookkeeping against truth ids. As MOT metrics do, only tracks that are reported
  /// (confirmed) can switch identity.
  void noteTruth(const Track& track, TrackerStats* stats) {
    if (track.truth_id < 0 || track.state != TrackState::kConfirmed) return;
    auto it = track_of_truth.find(track.truth_id);
    if (it != track_of_truth.end() && it->second != track.id) ++stats->id_switches;
    track_of_truth[track.truth_id] = track.id;
  }
  virtual ~Impl() = default;
  virtual TrackerStats step(double stamp_s, const std::vector<Detection>& detections) = 0;
  virtual void clear() = 0;

  TrackerConfig config;
  double gate = 9.21;
  double duplicate_gate = 4.61;
  double reid_gate = 23.0;
  std::vector<Track> tracks;
  std::vector<std::uint64_t> assignment;
  std::uint64_t next_id = 1;
  bool started = false;
  double last_stamp = 0.0;
  std::map<int, std::uint64_t> track_of_truth;
};

namespace {

template <int D>
struct Core : Tracker::Impl {
  using Filter = ConstantVelocityKalman<D>;
  using Vec = typename Filter::Vec;
  using Mat = typename Filter::Mat;

  struct State {
    Filter filter;
    double birth_s = 0.0;
    double last_update_s = 0.0;
    double lambda_max = 0.0;  ///< largest eigenvalue of the position covariance (metric gate)
    int detection = -1;       ///< index of this frame's detection, -1 if none
  };

  // Largest eigenvalue of a symmetric 2 x 2 matrix (closed form); unused for D = 4.
  static double maxEigen(const Mat& m) {
    if constexpr (D == 2) {
      const double mean = 0.5 * (m(0, 0) + m(1, 1));
      const double half_diff = 0.5 * (m(0, 0) - m(1, 1));
      return mean + std::sqrt(half_diff * half_diff + m(0, 1) * m(1, 0));
    } else {
      return m.trace();
    }
  }
  std::vector<State> states;  // parallel to tracks

  explicit Core(const TrackerConfig& c) : Tracker::Impl(c) {}

  void clear() override {
    tracks.clear();
    states.clear();
    assignment.clear();
    track_of_truth.clear();
    started = false;
  }

  // Measurement and its noise for a detection.
  void measurement(const Detection& d, Vec* z, Mat* R) const {
    if constexpr (D == 2) {
      (*z) << d.x, d.y;
      if (d.cov_xx > 0.0 || d.cov_yy > 0.0) {
        (*R) << d.cov_xx, d.cov_xy, d.cov_xy, d.cov_yy;
      } else {
        *R = Mat::Identity() * config.measurement_std * config.measurement_std;
      }
    } else {
      (*z) << d.box.centerX(), d.box.centerY(), d.box.width(), d.box.height();
      const double s = config.measurement_std * d.box.height();
      *R = Mat::Identity() * s * s;
    }
  }

  Vec processNoise(const State& s) const {
    if constexpr (D == 2) {
      return Vec::Constant(config.accel_psd);
    } else {
      const double h = std::max(1.0, s.filter.position()(3));
      return Vec::Constant(config.accel_psd * h * h);
    }
  }

  // Cost of giving detection d to track t (kForbidden outside the gate).
  double cost(std::size_t t, const Detection& d, const Vec& z, const Mat& R) const {
    if (config.class_aware && d.class_id >= 0 && tracks[t].class_id >= 0 &&
        d.class_id != tracks[t].class_id) {
      return kForbidden;
    }
    if constexpr (D == 2) {
      // Cheap bound first: d^2 >= |r|^2 / lambda_max(S) and lambda_max(S) <= lambda_max(P) +
      // lambda_max(R), so far pairs are rejected without forming S (most pairs in a crowd).
      const Vec r = z - states[t].filter.position();
      const double r2 = r.squaredNorm();
      if (r2 > gate * (states[t].lambda_max + maxEigen(R))) return kForbidden;
      const Mat S = states[t].filter.innovationCov(R);
      const double det = S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0);
      if (!(det > 0.0)) return kForbidden;
      const double d2 =
          (S(1, 1) * r(0) * r(0) - (S(0, 1) + S(1, 0)) * r(0) * r(1) + S(0, 0) * r(1) * r(1)) / det;
      return d2 <= gate ? d2 + std::log(det) : kForbidden;
    } else {
      (void)z, (void)R;
      const Vec p = states[t].filter.position();
      const double overlap = iou(Box::fromCenter(p(0), p(1), p(2), p(3)), d.box);
      return overlap >= config.min_iou && overlap > 0.0 ? 1.0 - overlap : kForbidden;
    }
  }

  // What leaving a track and a detection unpaired costs the assignment (solveAssignment):
  // infinite maximises the pairs; in image mode without maximize_matches, the cost of a pair at
  // min_iou (1 - min_iou, nudged up so that such a pair may still be made, as the gate allows).
  double unmatchedPairCost() const {
    if (D == 2 || config.maximize_matches) return kForbidden;
    return std::nextafter(1.0 - config.min_iou, kForbidden);
  }

  // Assigns detections `dets` (indices) to tracks `cands` (indices); fills match_of_track.
  std::size_t associate(const std::vector<std::size_t>& cands, const std::vector<std::size_t>& dets,
                        const std::vector<Detection>& all, const std::vector<Vec>& z,
                        const std::vector<Mat>& R, std::vector<int>* det_of_track,
                        std::vector<int>* track_of_det) {
    if (cands.empty() || dets.empty()) return 0;
    std::vector<CostEntry> entries;
    const auto consider = [&](std::size_t i, std::size_t j) {
      const double c = cost(cands[i], all[dets[j]], z[dets[j]], R[dets[j]]);
      if (std::isfinite(c)) {
        entries.push_back({static_cast<int>(i), static_cast<int>(j), c});
      }
    };
    if constexpr (D == 2) {
      // Sweep and prune along x: a pair can pass the gate only if |dx| <= sqrt(gate *
      // (lambda_max(P) + lambda_max(R))), so with tracks sorted by x each detection looks at the
      // tracks within the largest such reach instead of all of them.
      double max_lambda_r = 0.0;
      for (const std::size_t j : dets) max_lambda_r = std::max(max_lambda_r, maxEigen(R[j]));
      std::vector<std::pair<double, std::size_t>> by_x;
      by_x.reserve(cands.size());
      double reach = 0.0;
      for (std::size_t i = 0; i < cands.size(); ++i) {
        const State& s = states[cands[i]];
        by_x.emplace_back(s.filter.position()(0), i);
        reach = std::max(reach, std::sqrt(gate * (s.lambda_max + max_lambda_r)));
      }
      std::sort(by_x.begin(), by_x.end());
      for (std::size_t j = 0; j < dets.size(); ++j) {
        const double x = z[dets[j]](0);
        auto it =
            std::lower_bound(by_x.begin(), by_x.end(), std::make_pair(x - reach, std::size_t{0}));
        for (; it != by_x.end() && it->first <= x + reach; ++it) consider(it->second, j);
      }
    } else {
      // Sweep and prune along x: two boxes overlap only if their centres are closer in x than
      // half their summed widths, so with tracks sorted by centre x each detection looks at
      // the tracks within (widest track + its width) / 2. Entries are then put back in
      // row-major order, so the solver sees exactly what the all-pairs loop gave it.
      std::vector<std::pair<double, std::size_t>> by_x;
      by_x.reserve(cands.size());
      double widest = 0.0;
      for (std::size_t i = 0; i < cands.size(); ++i) {
        const Vec p = states[cands[i]].filter.position();
        by_x.emplace_back(p(0), i);
        widest = std::max(widest, std::abs(p(2)));
      }
      std::sort(by_x.begin(), by_x.end());
      for (std::size_t j = 0; j < dets.size(); ++j) {
        const double x = z[dets[j]](0);
        const double reach = 0.5 * (widest + z[dets[j]](2));
        auto it =
            std::lower_bound(by_x.begin(), by_x.end(), std::make_pair(x - reach, std::size_t{0}));
        for (; it != by_x.end() && it->first <= x + reach; ++it) consider(it->second, j);
      }
      std::sort(entries.begin(), entries.end(), [](const CostEntry& a, const CostEntry& b) {
        return a.row != b.row ? a.row < b.row : a.col < b.col;
      });
    }
    const std::vector<int> match =
        solveAssignment(static_cast<int>(cands.size()), static_cast<int>(dets.size()), entries,
                        unmatchedPairCost());
    std::size_t matched = 0;
    for (std::size_t i = 0; i < cands.size(); ++i) {
      if (match[i] < 0) continue;
      (*det_of_track)[cands[i]] = static_cast<int>(dets[match[i]]);
      (*track_of_det)[dets[match[i]]] = static_cast<int>(cands[i]);
      ++matched;
    }
    return matched;
  }

  // A confirmed track that coasted (occlusion, misses) may come back as a new track born from
  // a detection just outside its gate. When that newcomer is confirmed, it takes the coasting
  // track's id (and history) if their positions agree within the re-identification gate
  // (squared Mahalanobis distance under the sum of both covariances). Only tracks that were
  // already coasting when the newcomer was born qualify: a track that was updated meanwhile
  // follows another object. Pairs are chosen by one global assignment.
  std::size_t reidentify(const std::vector<std::size_t>& newcomers, std::vector<char>* gone) {
    if (newcomers.empty()) return 0;
    std::vector<std::size_t> lost;
    for (std::size_t t = 0; t < tracks.size(); ++t) {
      if (tracks[t].state == TrackState::kCoasting) lost.push_back(t);
    }
    if (lost.empty()) return 0;
    std::vector<CostEntry> entries;
    for (std::size_t i = 0; i < newcomers.size(); ++i) {
      const std::size_t n = newcomers[i];
      for (std::size_t k = 0; k < lost.size(); ++k) {
        const std::size_t o = lost[k];
        if (states[o].last_update_s > states[n].birth_s) continue;
        if (config.class_aware && tracks[n].class_id >= 0 && tracks[o].class_id >= 0 &&
            tracks[n].class_id != tracks[o].class_id) {
          continue;
        }
        const double d2 = pairDistance2(n, o);
        if (d2 <= reid_gate) entries.push_back({static_cast<int>(i), static_cast<int>(k), d2});
      }
    }
    const std::vector<int> match =
        solveAssignment(static_cast<int>(newcomers.size()), static_cast<int>(lost.size()), entries);
    std::size_t count = 0;
    for (std::size_t i = 0; i < newcomers.size(); ++i) {
      if (match[i] < 0) continue;
      Track& young = tracks[newcomers[i]];
      const std::size_t o = lost[match[i]];
      young.id = tracks[o].id;
      young.hits += tracks[o].hits;
      if (young.class_id < 0) young.class_id = tracks[o].class_id;
      states[newcomers[i]].birth_s = states[o].birth_s;
      (*gone)[o] = 1;
      ++count;
    }
    return count;
  }

  // Squared Mahalanobis distance between two tracks' positions under the sum of covariances.
  double pairDistance2(std::size_t a, std::size_t b) const {
    const Vec r = states[b].filter.position() - states[a].filter.position();
    const Mat S = states[a].filter.positionCov() + states[b].filter.positionCov();
    return r.dot(S.ldlt().solve(r));
  }

  // Two established tracks on one object (one born while the other coasted, and not
  // re-identified) would take turns with its detections. When a coasting track sits within the
  // duplicate gate of a track that took a detection this frame and was born while the coasting
  // one was already coasting, the coasting one goes. Two tracks that both took detections are
  // two objects, however close, and so is a coasting track next to an older one (an object
  // walking behind another keeps its track).
  std::size_t removeDuplicates(std::vector<char>* gone, double now) {
    const double limit = duplicate_gate;
    std::size_t removed = 0;
    for (std::size_t a = 0; a < tracks.size(); ++a) {
      if ((*gone)[a] || tracks[a].state != TrackState::kCoasting) continue;
      for (std::size_t b = 0; b < tracks.size(); ++b) {
        // b == a: a coasting track updated at this very stamp passes every test below.
        if (b == a || (*gone)[b] || tracks[b].state == TrackState::kTentative) continue;
        if (states[b].last_update_s != now || states[b].birth_s < states[a].last_update_s) {
          continue;
        }
        const Vec r = states[b].filter.position() - states[a].filter.position();
        if (r.squaredNorm() > limit * (states[a].lambda_max + states[b].lambda_max)) continue;
        if (pairDistance2(a, b) > limit) continue;
        (*gone)[a] = 1;
        ++removed;
        break;
      }
    }
    return removed;
  }

  // Drops the tracks marked gone (order kept).
  void compact(const std::vector<char>& gone) {
    std::size_t out = 0;
    for (std::size_t t = 0; t < tracks.size(); ++t) {
      if (gone[t]) continue;
      tracks[out] = tracks[t];
      states[out] = states[t];
      ++out;
    }
    tracks.resize(out);
    states.resize(out);
  }

  void refresh(std::size_t t, double now) {
    Track& track = tracks[t];
    const State& s = states[t];
    const Vec p = s.filter.position();
    const Vec v = s.filter.velocity();
    track.position = p.template head<2>();
    track.velocity = v.template head<2>();
    track.position_cov = s.filter.positionCov().template topLeftCorner<2, 2>();
    track.velocity_cov = s.filter.velocityCov().template topLeftCorner<2, 2>();
    if constexpr (D == 4) {
      track.size_x = p(2);
      track.size_y = p(3);
    }
    track.age_s = now - s.birth_s;
    track.time_since_update_s = now - s.last_update_s;
  }

  /// This frame's detections as the filters see them, and who took which.
  struct Frame {
    std::vector<Vec> z;                  ///< measurement per detection
    std::vector<Mat> R;                  ///< its noise
    std::vector<std::size_t> high;       ///< accepted detections at or above high_score
    std::vector<std::size_t> low;        ///< accepted detections for the second pass only
    std::vector<int> det_of_track;       ///< per track: its detection's index, -1 if none
    std::vector<int> track_of_det;       ///< per detection: its track's index, -1 if none
    std::vector<std::size_t> newcomers;  ///< tracks confirmed this frame
  };

  TrackerStats step(double now, const std::vector<Detection>& detections) override {
    const bool first_frame = !started;  // the first step since construction or reset()
    const double dt = advanceClock(now);
    TrackerStats stats;
    stats.detections = detections.size();
    predictAll(dt);
    Frame frame = acceptDetections(detections, &stats);
    associateAll(detections, &frame, &stats);
    updateOrRetireTracks(detections, now, &frame, &stats);
    mergeReturningTracks(frame.newcomers, now, &stats);
    bearTracks(detections, now, first_frame, frame, &stats);
    publish(detections.size(), now, &stats);
    return stats;
  }

  // Checks the stamp and returns the time since the previous frame (0 on the first). One stamp
  // is one frame: a repeated stamp would be a frame with dt = 0, in which a lost track misses
  // again without ageing (it never died), so it is refused like an older one.
  double advanceClock(double now) {
    if (!(std::abs(now) <= TrackerConfig::kMaxStampS)) {
      throw std::invalid_argument("tracker: stamp must be finite and within 1e10 s, got " +
                                  std::to_string(now));
    }
    if (started && now <= last_stamp) {
      throw std::invalid_argument("tracker: stamp " + std::to_string(now) + " s is " +
                                  (now == last_stamp ? "the previous frame's (one stamp, one frame)"
                                                     : "older than the previous frame's " +
                                                           std::to_string(last_stamp) + " s"));
    }
    const double dt = started ? now - last_stamp : 0.0;
    started = true;
    last_stamp = now;
    return dt;
  }

  void predictAll(double dt) {
    for (State& s : states) {
      s.detection = -1;
      s.filter.predict(dt, processNoise(s));
      if constexpr (D == 2) s.lambda_max = maxEigen(s.filter.positionCov());
      if constexpr (D == 4) {  // image boxes: width and height stay positive while coasting
        s.filter.clampPositionBelow(2, kMinBoxSizePx);
        s.filter.clampPositionBelow(3, kMinBoxSizePx);
      }
    }
  }

  // Refuses invalid detections, splits the rest by score; measurements once per detection.
  Frame acceptDetections(const std::vector<Detection>& detections, TrackerStats* stats) const {
    Frame frame;
    frame.z.resize(detections.size());
    frame.R.resize(detections.size());
    for (std::size_t j = 0; j < detections.size(); ++j) {
      const Detection& d = detections[j];
      const Verdict verdict = checkDetection(d, config.mode);
      if (verdict != Verdict::kOk) {
        ++(verdict == Verdict::kInvalid ? stats->detections_rejected_invalid
                                        : stats->detections_rejected_out_of_range);
        continue;
      }
      if (d.score < config.low_score || (d.score < config.high_score && !config.second_pass)) {
        ++stats->detections_ignored_low_score;
        continue;
      }
      measurement(d, &frame.z[j], &frame.R[j]);
      (d.score >= config.high_score ? frame.high : frame.low).push_back(j);
    }
    return frame;
  }

  // High-score detections go to established tracks, then to tentative ones; low-score ones
  // (second pass) only continue established tracks.
  void associateAll(const std::vector<Detection>& detections, Frame* frame, TrackerStats* stats) {
    frame->det_of_track.assign(tracks.size(), -1);
    frame->track_of_det.assign(detections.size(), -1);
    const auto pass = [&](const std::vector<std::size_t>& cands,
                          const std::vector<std::size_t>& dets) {
      return associate(cands, dets, detections, frame->z, frame->R, &frame->det_of_track,
                       &frame->track_of_det);
    };
    // Established tracks choose first, so a tentative duplicate (born from one detection that
    // fell outside a coasting track's gate) cannot take the object's next detection from it.
    std::vector<std::size_t> established, tentative;
    for (std::size_t t = 0; t < tracks.size(); ++t) {
      (tracks[t].state == TrackState::kTentative ? tentative : established).push_back(t);
    }
    stats->matched_first_pass = pass(established, frame->high);
    std::vector<std::size_t> high_left;
    for (const std::size_t j : frame->high) {
      if (frame->track_of_det[j] < 0) high_left.push_back(j);
    }
    stats->matched_first_pass += pass(tentative, high_left);
    if (config.second_pass && !frame->low.empty()) {
      std::vector<std::size_t> rest;
      for (std::size_t t = 0; t < tracks.size(); ++t) {
        if (frame->det_of_track[t] < 0 && tracks[t].state != TrackState::kTentative) {
          rest.push_back(t);
        }
      }
      stats->matched_second_pass = pass(rest, frame->low);
    }
  }

  // Matched tracks take their detection; unmatched ones coast or die (and are dropped). Fills
  // frame->newcomers with the indices, after the drop, of the tracks confirmed this frame.
  void updateOrRetireTracks(const std::vector<Detection>& detections, double now, Frame* frame,
                            TrackerStats* stats) {
    std::vector<Track> kept_tracks;
    std::vector<State> kept_states;
    kept_tracks.reserve(tracks.size() + frame->high.size());
    kept_states.reserve(tracks.size() + frame->high.size());
    for (std::size_t t = 0; t < tracks.size(); ++t) {
      const int j = frame->det_of_track[t];
      if (j >= 0) {
        if (updateMatched(&tracks[t], &states[t], detections[j], j, *frame, now)) {
          frame->newcomers.push_back(kept_tracks.size());
        }
      } else if (!survivesMiss(&tracks[t], states[t], now)) {
        ++stats->deaths;
        continue;
      }
      kept_tracks.push_back(tracks[t]);
      kept_states.push_back(states[t]);
    }
    tracks.swap(kept_tracks);
    states.swap(kept_states);
  }

  // Updates a track with detection j; true if this confirms it.
  bool updateMatched(Track* track, State* s, const Detection& d, int j, const Frame& frame,
                     double now) const {
    s->filter.update(frame.z[j], frame.R[j]);
    s->last_update_s = now;
    s->detection = j;
    ++track->hits;
    track->score = d.score;
    if constexpr (D == 2) {
      track->size_x = d.size_x;
      track->size_y = d.size_y;
    }
    if (track->class_id < 0) track->class_id = d.class_id;
    track->truth_id = d.truth_id;
    if (track->state == TrackState::kTentative && track->hits >= config.min_hits) {
      track->state = TrackState::kConfirmed;
      return true;
    }
    if (track->state == TrackState::kCoasting) track->state = TrackState::kConfirmed;
    return false;
  }

  // A track without a detection this frame: false if it dies (tentative, or coasted too long),
  // else it coasts.
  bool survivesMiss(Track* track, const State& s, double now) const {
    if (track->state == TrackState::kTentative ||
        now - s.last_update_s > config.max_age_s + kAgeToleranceS) {
      return false;
    }
    track->state = TrackState::kCoasting;
    return true;
  }

  // Metric mode: re-identification of tracks confirmed this frame, then duplicate removal.
  void mergeReturningTracks(const std::vector<std::size_t>& newcomers, double now,
                            TrackerStats* stats) {
    if constexpr (D == 2) {
      std::vector<char> gone(tracks.size(), 0);
      stats->reidentified = reidentify(newcomers, &gone);
      stats->duplicates_removed = removeDuplicates(&gone, now);
      compact(gone);
    }
    stats->deaths += stats->duplicates_removed;
  }

  // A new track's state: confirmed at once with min_hits 1, or in the first frame for a score
  // that passes start_confirm_score (ByteTrack activates its frame-1 tracks at once); else
  // tentative until min_hits updates.
  TrackState birthState(const Detection& d, bool first_frame) const {
    const bool at_start =
        first_frame && config.confirm_at_start && d.score >= config.start_confirm_score;
    return config.min_hits <= 1 || at_start ? TrackState::kConfirmed : TrackState::kTentative;
  }

  // Births from high-score detections no track took.
  void bearTracks(const std::vector<Detection>& detections, double now, bool first_frame,
                  const Frame& frame, TrackerStats* stats) {
    for (const std::size_t j : frame.high) {
      if (frame.track_of_det[j] >= 0) continue;
      ++stats->unmatched_outside_gate;
      const Detection& d = detections[j];
      Track track;
      track.id = next_id++;
      track.class_id = d.class_id;
      track.state = birthState(d, first_frame);
      track.hits = 1;
      track.score = d.score;
      track.truth_id = d.truth_id;
      track.size_x = d.size_x;
      track.size_y = d.size_y;
      double velocity_std = config.initial_velocity_std;
      if constexpr (D == 4) velocity_std *= d.box.height();
      State s{Filter(frame.z[j], frame.R[j], velocity_std), now, now};
      s.detection = static_cast<int>(j);
      tracks.push_back(track);
      states.push_back(s);
      ++stats->births;
    }
  }

  // The assignment (ids are final now: re-identification may have changed some), truth
  // bookkeeping, the public track fields and the counts.
  void publish(std::size_t detection_count, double now, TrackerStats* stats) {
    assignment.assign(detection_count, 0);
    for (std::size_t t = 0; t < tracks.size(); ++t) {
      const int j = states[t].detection;
      if (j < 0) continue;
      assignment[j] = tracks[t].id;
      noteTruth(tracks[t], stats);
    }
    for (std::size_t t = 0; t < tracks.size(); ++t) refresh(t, now);
    stats->tracks = tracks.size();
    for (const Track& t : tracks) stats->confirmed += t.state != TrackState::kTentative;
  }
};

}  // namespace

Tracker::Tracker(const TrackerConfig& config) {
  const std::string why = config.validate();
  if (!why.empty()) throw std::invalid_argument("tracker: " + why);
  if (config.mode == TrackerConfig::Mode::kImage) {
    impl_ = std::make_unique<Core<4>>(config);
  } else {
    impl_ = std::make_unique<Core<2>>(config);
  }
}

Tracker::~Tracker() = default;
Tracker::Tracker(Tracker&&) noexcept = default;
Tracker& Tracker::operator=(Tracker&&) noexcept = default;

TrackerStats Tracker::step(double stamp_s, const std::vector<Detection>& detections) {
  return impl_->step(stamp_s, detections);
}
const std::vector<Track>& Tracker::tracks() const {
  return impl_->tracks;
}
const std::vector<std::uint64_t>& Tracker::lastAssignment() const {
  return impl_->assignment;
}
const TrackerConfig& Tracker::config() const {
  return impl_->config;
}
void Tracker::reset() {
  impl_->clear();
}

void Tracker::setConfig(const TrackerConfig& config) {
  const std::string why = config.validate();
  if (!why.empty()) throw std::invalid_argument("tracker: " + why);
  if (config.mode != impl_->config.mode) {
    throw std::invalid_argument("tracker: the mode cannot change on a running tracker");
  }
  impl_->setConfig(config);
}

}  // namespace downstream_perception
