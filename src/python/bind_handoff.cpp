// Python bindings of the core's seam health: smear and the map <- odom correction monitor.
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

namespace py = pybind11;
using namespace downstream_perception;  // NOLINT

void bindHandoff(py::module& m) {
  // ----------------------------------------------------------------- seam health
  m.def("expected_smear", &expectedSmear, py::arg("range_m"), py::arg("yaw_rate_rps"),
        py::arg("age_s"), "range * tan(|yaw rate| * age): sideways throw of a late transform, m.");
  py::class_<SeamLimits>(m, "SeamLimits", "The seam health's warning limits (handoff keys).")
      .def(py::init<>())
      .def_readwrite("reference_range_m", &SeamLimits::reference_range_m,
                     "m: the range at which the smear is judged")
      .def_readwrite("max_transform_age_s", &SeamLimits::max_transform_age_s,
                     "s: warn when an input's p95 transform age exceeds it")
      .def_readwrite("max_smear_m", &SeamLimits::max_smear_m,
                     "m: warn when the expected smear exceeds it")
      .def_readwrite("max_map_odom_age_s", &SeamLimits::max_map_odom_age_s,
                     "s: warn when map <- odom is older");
  py::class_<CorrectionMonitorConfig>(
      m, "CorrectionMonitorConfig",
      "Limits of the map <- odom correction monitor (metres, seconds).")
      .def(py::init<>())
      .def_readwrite("window_s", &CorrectionMonitorConfig::window_s, "s of history judged")
      .def_readwrite("reset_drop_m", &CorrectionMonitorConfig::reset_drop_m,
                     "m: a fall of the correction this large is a correction event")
      .def_readwrite("max_correction_m", &CorrectionMonitorConfig::max_correction_m,
                     "m: warn above (the lesson: 2 m ~ 100 m of 2 % drift)")
      .def_readwrite("zero_epsilon_m", &CorrectionMonitorConfig::zero_epsilon_m,
                     "m: a correction this small counts as zero")
      .def_readwrite("min_travel_m", &CorrectionMonitorConfig::min_travel_m,
                     "m of robot travel within the window after which a correction stuck at zero "
                     "is suspicious (the localiser may be silently rejecting fixes).")
      .def_readwrite("ramp_m", &CorrectionMonitorConfig::ramp_m,
                     "m the correction must grow within the window without a single reset before "
                     "it counts as \"never resets\" (loop closures not firing).")
      .def("validate", &CorrectionMonitorConfig::validate,
           "Empty string if the configuration is valid, else the reason (what the constructors "
           "raise).");
  py::class_<CorrectionMonitor>(m, "CorrectionMonitor", "Watches |map <- odom| over time.")
      .def(py::init<const CorrectionMonitorConfig&>(),
           py::arg_v("config", CorrectionMonitorConfig{}, "CorrectionMonitorConfig()"))
      .def("add", &CorrectionMonitor::add, py::arg("time_s"), py::arg("correction_m"),
           py::arg("travelled_m"),
           "One sample: time (s), the correction's translation magnitude (m), the distance "
           "travelled so far (m).")
      .def(
          "add_many",
          [](CorrectionMonitor& m, const Eigen::VectorXd& t, const Eigen::VectorXd& c,
             const Eigen::VectorXd& d) {
            if (t.size() != c.size() || t.size() != d.size()) {
              throw std::invalid_argument("time_s, correction_m, travelled_m differ in length");
            }
            for (Eigen::Index i = 0; i < t.size(); ++i) m.add(t[i], c[i], d[i]);
          },
          py::arg("time_s"), py::arg("correction_m"), py::arg("travelled_m"),
          "Samples from three equally long arrays: time_s, correction_m, travelled_m.")
      .def_property_readonly(
          "resets", &CorrectionMonitor::resets,
          "corrections seen to reset (drops larger than reset_drop_m) in the window")
      .def("never_resets", &CorrectionMonitor::neverResets,
           "Whether the correction grew by ramp_m over the window without a reset.")
      .def("stuck_at_zero", &CorrectionMonitor::stuckAtZero,
           "Whether the correction stayed ~0 over the window while the robot travelled "
           "min_travel_m.")
      .def("too_large", &CorrectionMonitor::tooLarge,
           "Whether the latest correction exceeds max_correction_m.")
      .def("findings", &CorrectionMonitor::findings,
           "What is wrong, one line per finding (empty if healthy).");
}
