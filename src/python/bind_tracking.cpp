// Python bindings of the core's detection geometry, assignment, Kalman, the tracker, predicted
// footprints.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <stdexcept>

#include "downstream_perception/core/costmap/cloud_beams.h"
#include "downstream_perception/core/costmap/footprint.h"
#include "downstream_perception/core/costmap/inflation.h"
#include "downstream_perception/core/costmap/log_odds_grid.h"
#include "downstream_perception/core/costmap/scan_integrator.h"
#include "downstream_perception/core/costmap/static_map.h"
#include "downstream_perception/core/grid/cost_values.h"
#include "downstream_perception/core/grid/grid_geometry.h"
#include "downstream_perception/core/grid/ray_traversal.h"
#include "downstream_perception/core/grid/se2.h"
#include "downstream_perception/core/handoff/seam_health.h"
#include "downstream_perception/core/tracking/assignment.h"
#include "downstream_perception/core/tracking/box.h"
#include "downstream_perception/core/tracking/kalman.h"
#include "downstream_perception/core/tracking/predicted_footprint.h"
#include "downstream_perception/core/tracking/tracker.h"

#include "numpy_arrays.h"

namespace py = pybind11;
using namespace downstream_perception;          // NOLINT
using namespace downstream_perception::python;  // NOLINT

void bindTracking(py::module& m) {
  // ----------------------------------------------------------------- detection and tracking
  const auto toBox = [](py::array_t<double, py::array::c_style | py::array::forcecast> a,
                        py::ssize_t row) {
    const auto b = a.unchecked<2>();
    return Box{b(row, 0), b(row, 1), b(row, 2), b(row, 3)};
  };
  const auto checkBoxes = [](const py::array& a, const char* name) {
    if (a.ndim() != 2 || a.shape(1) != 4) {
      throw std::invalid_argument(std::string(name) +
                                  " must be an (N, 4) array of x_min, y_min, x_max, y_max");
    }
  };
  m.def(
      "iou",
      [](std::tuple<double, double, double, double> a,
         std::tuple<double, double, double, double> b) {
        return iou({std::get<0>(a), std::get<1>(a), std::get<2>(a), std::get<3>(a)},
                   {std::get<0>(b), std::get<1>(b), std::get<2>(b), std::get<3>(b)});
      },
      py::arg("a"), py::arg("b"), "IoU of two boxes (x_min, y_min, x_max, y_max).");
  m.def(
      "nms",
      [toBox, checkBoxes](py::array_t<double, py::array::c_style | py::array::forcecast> boxes,
                          py::array_t<double, py::array::c_style | py::array::forcecast> scores,
                          double iou_threshold, std::optional<std::vector<int>> class_ids) {
        checkBoxes(boxes, "boxes");
        std::vector<Box> b;
        for (py::ssize_t i = 0; i < boxes.shape(0); ++i) b.push_back(toBox(boxes, i));
        const std::vector<double> s(scores.data(), scores.data() + scores.size());
        const auto kept = nms(b, s, iou_threshold, class_ids ? &*class_ids : nullptr);
        py::array_t<std::int64_t> out(static_cast<py::ssize_t>(kept.size()));
        std::copy(kept.begin(), kept.end(), out.mutable_data());
        return out;
      },
      py::arg("boxes"), py::arg("scores"), py::arg("iou_threshold") = 0.5,
      py::arg("class_ids") = py::none(),
      "Greedy NMS; returns the kept indices, best first. With class_ids, per class.");
  m.def(
      "mask_iou",
      [](py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast> a,
         py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast> b) {
        if (a.size() != b.size()) throw std::invalid_argument("masks must have the same size");
        return maskIou(a.data(), b.data(), static_cast<std::size_t>(a.size()));
      },
      py::arg("a"), py::arg("b"), "IoU of two binary masks (non-zero = foreground).");
  // ----------------------------------------------------------------- predicted obstacles
  py::class_<PredictionConfig>(m, "PredictionConfig",
                               "How tracks are predicted into the costmap: horizon and step (s), "
                               "uncertainty growth, footprint margin (m).")
      .def(py::init<>())
      .def_readwrite("prediction_horizon_s", &PredictionConfig::prediction_horizon_s,
                     "s: how far ahead of now the object is swept")
      .def_readwrite(
          "uncertainty_sigmas", &PredictionConfig::uncertainty_sigmas,
          "k: the shape grows by k standard deviations of the predicted position (0 = box only).")
      .def_readwrite(
          "max_uncertainty_m", &PredictionConfig::max_uncertainty_m,
          "m: cap on that growth, so a track with an absurd covariance cannot blank the map.")
      .def_readwrite("min_object_size_m", &PredictionConfig::min_object_size_m,
                     "m: smaller box sides are raised to this")
      .def_readwrite("max_object_size_m", &PredictionConfig::max_object_size_m,
                     "m: larger box sides are clamped to this (bad sizes)")
      .def_readwrite("max_speed_mps", &PredictionConfig::max_speed_mps,
                     "m/s: faster tracks are not swept (bad velocities)")
      .def("validate", &PredictionConfig::validate,
           "Empty string if the configuration is valid, else the reason (what the constructors "
           "raise).");
  py::class_<PlanarTrack>(m, "PlanarTrack", "One track in the costmap's frame.")
      .def(py::init([](const Eigen::Vector2d& position, const Eigen::Vector2d& velocity,
                       const Eigen::Matrix2d& position_covariance,
                       const Eigen::Matrix2d& velocity_covariance, double size_x, double size_y,
                       double box_yaw) {
             PlanarTrack t;
             t.position = position;
             t.velocity = velocity;
             t.position_covariance = position_covariance;
             t.velocity_covariance = velocity_covariance;
             t.size_x = size_x;
             t.size_y = size_y;
             t.box_yaw = box_yaw;
             return t;
           }),
           py::arg("position"), py::arg("velocity"),
           py::arg("position_covariance") = Eigen::Matrix2d::Zero().eval(),
           py::arg("velocity_covariance") = Eigen::Matrix2d::Zero().eval(), py::arg("size_x") = 0.0,
           py::arg("size_y") = 0.0, py::arg("box_yaw") = 0.0)
      .def_readwrite("position", &PlanarTrack::position, "m, at the measurement stamp")
      .def_readwrite("velocity", &PlanarTrack::velocity, "m/s")
      .def_readwrite("position_covariance", &PlanarTrack::position_covariance, "m² (m² (m^2))")
      .def_readwrite("velocity_covariance", &PlanarTrack::velocity_covariance,
                     "m²/s² (m²/s² (m^2/s^2))")
      .def_readwrite("size_x", &PlanarTrack::size_x, "m, box side along the box's x axis")
      .def_readwrite("size_y", &PlanarTrack::size_y, "m")
      .def_readwrite("box_yaw", &PlanarTrack::box_yaw, "rad: the box's x axis in the costmap frame")
      .def("validate", &PlanarTrack::validate,
           "Empty string if the configuration is valid, else the reason (what the constructors "
           "raise).");
  m.def("uncertainty_radius", &uncertaintyRadius, py::arg("track"), py::arg("dt_s"),
        py::arg("config"), "k sigma of the predicted position dt_s after the stamp, m (capped).");
  m.def(
      "swept_polygon",
      [](const PlanarTrack& track, double duration_s, const PredictionConfig& config) {
        const Footprint polygon = sweptPolygon(track, duration_s, config);
        py::array_t<double> out({static_cast<py::ssize_t>(polygon.size()), py::ssize_t{2}});
        auto a = out.mutable_unchecked<2>();
        for (py::ssize_t i = 0; i < static_cast<py::ssize_t>(polygon.size()); ++i) {
          a(i, 0) = polygon[i].x;
          a(i, 1) = polygon[i].y;
        }
        return out;
      },
      py::arg("track"), py::arg("duration_s"), py::arg("config"),
      "Convex polygon (N x 2, counter-clockwise) the box sweeps over duration_s.");
  m.def(
      "predicted_cells",
      [](const PlanarTrack& track, double age_s, const PredictionConfig& config,
         const GridGeometry& geometry) {
        const std::string why = validatePrediction(track, age_s, config);
        if (!why.empty()) throw std::invalid_argument(why);
        std::vector<std::size_t> cells;
        predictedCells(track, age_s, config, geometry, &cells);
        std::vector<CellIndex> xy;
        xy.reserve(cells.size());
        for (const std::size_t i : cells) xy.push_back(geometry.cellOf(i));
        return cellsToArray(xy);
      },
      py::arg("track"), py::arg("age_s"), py::arg("config"), py::arg("geometry"),
      "Cells (N x 2 [x, y]) the track covers from its stamp over age_s + prediction_horizon_s. "
      "Raises ValueError if the track, age_s or the config is invalid.");
  m.def(
      "recent_cells",
      [](const PlanarTrack& track, double lookback_s, double age_s, double margin_m,
         double max_object_size_m, const GridGeometry& geometry) {
        const std::string why =
            recentCellsReason(track, lookback_s, age_s, margin_m, max_object_size_m);
        if (!why.empty()) throw std::invalid_argument(why);
        std::vector<std::size_t> cells;
        recentCells(track, lookback_s, age_s, margin_m, max_object_size_m, geometry, &cells);
        std::vector<CellIndex> xy;
        xy.reserve(cells.size());
        for (const std::size_t i : cells) xy.push_back(geometry.cellOf(i));
        return cellsToArray(xy);
      },
      py::arg("track"), py::arg("lookback_s"), py::arg("age_s"), py::arg("margin_m"),
      py::arg("max_object_size_m"), py::arg("geometry"),
      "Cells (N x 2 [x, y]) under the track's box grown by margin_m, swept from lookback_s before "
      "its stamp to age_s after it (what clear_tracked_objects clears).");

  m.def("chi_square_quantile", &chiSquareQuantile, py::arg("dof"), py::arg("confidence"),
        "Squared-Mahalanobis gate: chi-square quantile (2, 0.99) -> 9.21.");
  m.def(
      "solve_assignment",
      [](const Eigen::MatrixXd& cost, double unmatched_pair_cost) {
        return solveAssignment(cost, unmatched_pair_cost);
      },
      py::arg("cost"), py::arg("unmatched_pair_cost") = kForbidden,
      "Min-cost assignment of rows to columns; inf = forbidden. Returns the column per row or -1. "
      "unmatched_pair_cost inf (default): as many pairs as possible, then the least total cost; "
      "finite L: the least sum of (cost - L), pairs costing L or more never taken (lap.lapjv "
      "with cost_limit L, as ByteTrack calls it).");

  py::enum_<TrackState>(m, "TrackState")
      .value("TENTATIVE", TrackState::kTentative)
      .value("CONFIRMED", TrackState::kConfirmed)
      .value("COASTING", TrackState::kCoasting);
  py::class_<TrackerConfig> tc(m, "TrackerConfig",
                               "Tracker parameters; metric defaults on construction, image "
                               "defaults from TrackerConfig.defaults_for(Mode.IMAGE).");
  py::enum_<TrackerConfig::Mode>(tc, "Mode")
      .value("METRIC", TrackerConfig::Mode::kMetric)
      .value("IMAGE", TrackerConfig::Mode::kImage);
  tc.def(py::init<>())
      .def_readonly_static("MAX_BOX_COORDINATE_PX", &TrackerConfig::kMaxBoxCoordinatePx,
                           "image mode: larger |box coordinates| are rejected (out of range)")
      .def_readonly_static("MAX_POSITION_M", &TrackerConfig::kMaxPositionM,
                           "metric mode: larger |position| / size are rejected (out of range)")
      .def_readwrite("mode", &TrackerConfig::mode,
                     "The member initialisers below are the metric defaults (a default-constructed "
                     "config is metric, as it always was). Image mode has its own defaults: start "
                     "from defaultsFor(kImage).")
      .def_readwrite("gate_confidence", &TrackerConfig::gate_confidence,
                     "chi-square gate (metric): 2 dof, 0.99 -> 9.21, 0.999 -> 13.8")
      .def_readwrite(
          "duplicate_confidence", &TrackerConfig::duplicate_confidence,
          "Metric mode: a coasting track this close (chi-square gate, 2 dof, sum of both position "
          "covariances) to a track born while it coasted and updated this frame is its duplicate "
          "and is removed. 0.9 -> 4.61, about 0.3 m at 0.1 m uncertainty.")
      .def_readwrite("reid_confidence", &TrackerConfig::reid_confidence,
                     "Metric mode: a track confirmed this frame takes the id of a track that was "
                     "already coasting at its birth when their positions agree within this "
                     "chi-square gate (2 dof, sum of covariances): re-identification after an "
                     "occlusion the gate could not bridge. 0.99999 -> 23.0.")
      .def_readwrite("min_iou", &TrackerConfig::min_iou, "image mode: minimum IoU to associate")
      .def_readwrite(
          "maximize_matches", &TrackerConfig::maximize_matches,
          "Image mode: true (member default, SORT) makes as many pairs as the gate allows, then "
          "the largest summed IoU; false (image default) the largest summed (IoU - min_iou), as "
          "ByteTrack's lapjv with a cost limit, so one good pair is not traded for two poor ones. "
          "Metric mode always maximises the pairs.")
      .def_readwrite(
          "accel_psd", &TrackerConfig::accel_psd,
          "Spectral density of the white acceleration noise. Metric: m^2/s^3 per axis. Image: box "
          "heights^2/s^3 (px^2/s^3 per px^2 of box height), so it scales with the apparent size.")
      .def_readwrite(
          "measurement_std", &TrackerConfig::measurement_std,
          "Metric: m, position noise of detections without a covariance. Image: box heights (std "
          "of each of centre x, centre y, width and height in px per px of box height).")
      .def_readwrite("initial_velocity_std", &TrackerConfig::initial_velocity_std,
                     "m/s (metric) or box heights/s (image)")
      .def_readwrite("min_hits", &TrackerConfig::min_hits,
                     "Updates before a track is confirmed; a tentative track that misses one is "
                     "dropped. Image default 2 (see defaultsFor).")
      .def_readwrite(
          "confirm_at_start", &TrackerConfig::confirm_at_start,
          "Start-up confirmation (ByteTrack's frame-1 rule): in the tracker's first frame (the "
          "first step() after construction or reset()), a track born from a detection whose "
          "score is at least start_confirm_score is confirmed at once instead of waiting "
          "min_hits updates. Tracks born later, and first-frame ones below the score, follow "
          "min_hits. Only the first step() counts, even when it holds no detections.")
      .def_readwrite("start_confirm_score", &TrackerConfig::start_confirm_score,
                     "Score in [0, 1] a first-frame detection needs for start-up confirmation. "
                     "ByteTrack's det_thresh = track_thresh + 0.1: 0.6 with high_score 0.5. "
                     "Births need high_score anyway.")
      .def_readwrite("max_age_s", &TrackerConfig::max_age_s,
                     "s a confirmed track coasts without detections (both modes)")
      .def_readwrite("high_score", &TrackerConfig::high_score,
                     "detections at or above: first pass, may start tracks")
      .def_readwrite("low_score", &TrackerConfig::low_score,
                     "below: ignored; in between: second pass only")
      .def_readwrite("second_pass", &TrackerConfig::second_pass,
                     "ByteTrack's low-score association")
      .def_readwrite("class_aware", &TrackerConfig::class_aware,
                     "tracks only take detections of their class")
      .def("validate", &TrackerConfig::validate,
           "Empty string if the configuration is valid, else the reason (what the constructors "
           "raise).")
      .def_static("defaults_for", &TrackerConfig::defaultsFor, py::arg("mode"),
                  "The mode's documented defaults. TrackerConfig() is the metric ones; setting "
                  "mode on it keeps every other field as it is.")
      .def_static("mode_specific_defaults", &TrackerConfig::modeSpecificDefaults, py::arg("mode"),
                  "[(name, value)] of the fields whose default in this mode differs from the "
                  "metric one.");
  py::class_<TrackerStats>(m, "TrackerStats",
                           "What one tracker step did: detections by kind, matches per pass, "
                           "births, deaths, duplicates, re-identifications.")
      .def_readonly("detections", &TrackerStats::detections, "detections given to step()")
      .def_readonly("detections_ignored_low_score", &TrackerStats::detections_ignored_low_score,
                    "scores below low_score")
      .def_readonly("detections_rejected_invalid", &TrackerStats::detections_rejected_invalid,
                    "NaN/Inf, boxes with min > max or no area, negative sizes, covariances that "
                    "are not positive semi-definite")
      .def_readonly(
          "detections_rejected_out_of_range", &TrackerStats::detections_rejected_out_of_range,
          "Finite but beyond TrackerConfig::kMaxBoxCoordinatePx (image) or kMaxPositionM (metric)")
      .def_readonly("matched_first_pass", &TrackerStats::matched_first_pass,
                    "high-score detections assigned to a track")
      .def_readonly("matched_second_pass", &TrackerStats::matched_second_pass,
                    "low-score detections assigned (ByteTrack's pass)")
      .def_readonly("unmatched_outside_gate", &TrackerStats::unmatched_outside_gate,
                    "high-score detections no track could take")
      .def_readonly("births", &TrackerStats::births, "new tentative tracks")
      .def_readonly("deaths", &TrackerStats::deaths, "includes duplicates removed")
      .def_readonly("duplicates_removed", &TrackerStats::duplicates_removed,
                    "coasting tracks removed as duplicates of new ones")
      .def_readonly("reidentified", &TrackerStats::reidentified,
                    "new tracks that took a coasting track's id")
      .def_readonly("id_switches", &TrackerStats::id_switches,
                    "truth objects whose track id changed (needs truth ids)")
      .def_readonly("tracks", &TrackerStats::tracks, "live tracks after the step (every state)")
      .def_readonly("confirmed", &TrackerStats::confirmed, "of them confirmed or coasting");
  py::class_<Tracker>(m, "Tracker",
                      "SORT-style multi-object tracker (see core/tracking/tracker.h).")
      .def(py::init<const TrackerConfig&>(),
           py::arg_v("config", TrackerConfig{}, "TrackerConfig()"))
      .def(
          "step",
          [](Tracker& self, double stamp,
             py::array_t<double, py::array::c_style | py::array::forcecast> positions,
             std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>> scores,
             std::optional<py::array_t<int, py::array::c_style | py::array::forcecast>> class_ids,
             std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>>
                 covariances,
             std::optional<py::array_t<int, py::array::c_style | py::array::forcecast>> truth_ids,
             std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>> sizes) {
            const bool image = self.config().mode == TrackerConfig::Mode::kImage;
            const py::ssize_t cols = image ? 4 : 2;
            if (positions.ndim() != 2 || positions.shape(1) != cols) {
              throw std::invalid_argument(image ? "boxes must be (N, 4)"
                                                : "positions must be (N, 2)");
            }
            const py::ssize_t n = positions.shape(0);
            const auto check = [n](const py::array& a, const char* name) {
              if (a.shape(0) != n)
                throw std::invalid_argument(std::string(name) + " must have N rows");
            };
            if (scores) check(*scores, "scores");
            if (class_ids) check(*class_ids, "class_ids");
            if (truth_ids) check(*truth_ids, "truth_ids");
            if (covariances && (covariances->ndim() != 3 || covariances->shape(0) != n ||
                                covariances->shape(1) != 2 || covariances->shape(2) != 2)) {
              throw std::invalid_argument("covariances must be (N, 2, 2)");
            }
            if (sizes && image) {
              throw std::invalid_argument("sizes are for metric mode (a box carries its size)");
            }
            if (sizes && (sizes->ndim() != 2 || sizes->shape(0) != n || sizes->shape(1) != 2)) {
              throw std::invalid_argument("sizes must be (N, 2)");
            }
            std::vector<Detection> dets(n);
            const auto p = positions.unchecked<2>();
            for (py::ssize_t i = 0; i < n; ++i) {
              Detection& d = dets[i];
              if (image) {
                d.box = {p(i, 0), p(i, 1), p(i, 2), p(i, 3)};
              } else {
                d.x = p(i, 0);
                d.y = p(i, 1);
              }
              if (scores) d.score = scores->at(i);
              if (class_ids) d.class_id = class_ids->at(i);
              if (truth_ids) d.truth_id = truth_ids->at(i);
              if (covariances) {
                d.cov_xx = covariances->at(i, 0, 0);
                d.cov_xy = covariances->at(i, 0, 1);
                d.cov_yy = covariances->at(i, 1, 1);
              }
              if (sizes) {
                d.size_x = sizes->at(i, 0);
                d.size_y = sizes->at(i, 1);
              }
            }
            py::gil_scoped_release release;
            return self.step(stamp, dets);
          },
          py::arg("stamp"), py::arg("positions"), py::arg("scores") = py::none(),
          py::arg("class_ids") = py::none(), py::arg("covariances") = py::none(),
          py::arg("truth_ids") = py::none(), py::arg("sizes") = py::none(),
          "One frame: positions (N, 2) in metres (metric mode) or boxes (N, 4) in pixels (image "
          "mode); sizes (N, 2) in metres (metric mode only: tracks()['size']). Returns "
          "TrackerStats.")
      .def(
          "tracks",
          [](const Tracker& self, bool include_tentative) {
            std::vector<Track> t;
            for (const Track& track : self.tracks()) {
              if (include_tentative || track.state != TrackState::kTentative) t.push_back(track);
            }
            const py::ssize_t n = static_cast<py::ssize_t>(t.size());
            py::array_t<std::uint64_t> ids(n);
            py::array_t<int> states(n), hits(n), truth(n);
            py::array_t<double> pos({n, py::ssize_t{2}}), vel({n, py::ssize_t{2}}),
                pos_cov({n, py::ssize_t{2}, py::ssize_t{2}}),
                vel_cov({n, py::ssize_t{2}, py::ssize_t{2}}), size({n, py::ssize_t{2}});
            for (py::ssize_t i = 0; i < n; ++i) {
              ids.mutable_at(i) = t[i].id;
              states.mutable_at(i) = static_cast<int>(t[i].state);
              hits.mutable_at(i) = t[i].hits;
              truth.mutable_at(i) = t[i].truth_id;
              for (int k = 0; k < 2; ++k) {
                pos.mutable_at(i, k) = t[i].position(k);
                vel.mutable_at(i, k) = t[i].velocity(k);
                for (int l = 0; l < 2; ++l) {
                  pos_cov.mutable_at(i, k, l) = t[i].position_cov(k, l);
                  vel_cov.mutable_at(i, k, l) = t[i].velocity_cov(k, l);
                }
              }
              size.mutable_at(i, 0) = t[i].size_x;
              size.mutable_at(i, 1) = t[i].size_y;
            }
            py::dict out;
            out["id"] = ids;
            out["state"] = states;
            out["hits"] = hits;
            out["truth_id"] = truth;
            out["position"] = pos;
            out["velocity"] = vel;
            out["position_cov"] = pos_cov;
            out["velocity_cov"] = vel_cov;
            out["size"] = size;
            return out;
          },
          py::arg("include_tentative") = true,
          "Live tracks as a dict of numpy arrays (id, state, hits, truth_id, position, velocity, "
          "position_cov, velocity_cov, size); state: 0 tentative, 1 confirmed, 2 coasting. "
          "include_tentative=False leaves out the tracks not yet confirmed.")
      .def("last_assignment", &Tracker::lastAssignment,
           "Per detection of the last step: the id of the track that took it, or 0.")
      .def("reset", &Tracker::reset, "Forgets every track (ids keep counting up).");
}
