// Python bindings of the core's log-odds grid, scan and cloud integration, static map, inflation
// and footprint.
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

namespace {

// LogOddsConfig, LogOddsGrid and the probability conversions.
void bindLogOddsGrid(py::module& m) {
  py::class_<LogOddsConfig>(m, "LogOddsConfig",
                            "Inverse sensor model and thresholds of the log-odds obstacle grid "
                            "(probabilities, log-odds).")
      .def(py::init<>())
      .def_readwrite("p_hit", &LogOddsConfig::p_hit,
                     "inverse sensor model: P(occupied) given a return in the cell")
      .def_readwrite("p_miss", &LogOddsConfig::p_miss,
                     "P(occupied) given a beam passing through the cell")
      .def_readwrite("clamp_min", &LogOddsConfig::clamp_min,
                     "lower log-odds clamp (keeps free cells re-learnable)")
      .def_readwrite("clamp_max", &LogOddsConfig::clamp_max,
                     "upper log-odds clamp (keeps walls un-learnable in bounded time)")
      .def_readwrite("occupied_threshold", &LogOddsConfig::occupied_threshold,
                     "log-odds above this -> occupied (p > 0.881)")
      .def_readwrite("free_threshold", &LogOddsConfig::free_threshold,
                     "log-odds below this -> free (p < 0.119)")
      .def("validate", &LogOddsConfig::validate, "Empty string if valid, else the reason.");

  py::class_<LogOddsGrid>(m, "LogOddsGrid",
                          "Fixed-point log-odds occupancy grid (2 bytes per cell, quantum 1/1024).")
      .def(py::init<const GridGeometry&, const LogOddsConfig&>(), py::arg("geometry"),
           py::arg_v("config", LogOddsConfig{}, "LogOddsConfig()"))
      .def_property_readonly("geometry", &LogOddsGrid::geometry, "the grid's geometry")
      .def_property_readonly("config", &LogOddsGrid::config, "the configuration in use")
      .def_property_readonly_static(
          "quantum", [](py::object) { return LogOddsGrid::kQuantum; },
          "log-odds per stored unit (1/1024)")
      .def_property_readonly(
          "hit_increment",
          [](const LogOddsGrid& g) { return LogOddsGrid::dequantize(g.hitUnits()); },
          "log-odds added by a return, after rounding to the quantum")
      .def_property_readonly(
          "miss_increment",
          [](const LogOddsGrid& g) { return LogOddsGrid::dequantize(g.missUnits()); },
          "log-odds added by a pass, after rounding to the quantum")
      .def(
          "log_odds",
          [](const LogOddsGrid& g) {
            return gridArray<float>(
                g, [&g](std::size_t i) { return static_cast<float>(g.logOdds(i)); });
          },
          "(size_y, size_x) float32 log-odds.")
      .def(
          "probability",
          [](const LogOddsGrid& g) {
            return gridArray<float>(
                g, [&g](std::size_t i) { return static_cast<float>(g.probability(i)); });
          },
          "(size_y, size_x) float32 P(occupied).")
      .def(
          "states",
          [](const LogOddsGrid& g) {
            return gridArray<std::int8_t>(
                g, [&g](std::size_t i) { return static_cast<std::int8_t>(g.state(i)); });
          },
          "(size_y, size_x) int8: -1 unknown, 0 free, 1 occupied (by the thresholds).")
      .def(
          "set_log_odds",
          [](LogOddsGrid& g,
             py::array_t<double, py::array::c_style | py::array::forcecast> values) {
            const GridGeometry& geo = g.geometry();
            if (values.ndim() != 2 || values.shape(0) != geo.sizeY() ||
                values.shape(1) != geo.sizeX()) {
              throw std::invalid_argument("expected an array of shape (size_y, size_x)");
            }
            const double* v = values.data();
            for (std::size_t i = 0; i < geo.cellCount(); ++i) g.setLogOdds(i, v[i]);
          },
          "Sets every cell's log-odds from a (size_y, size_x) array (clamped, quantised).")
      .def(
          "add_hit",
          [](LogOddsGrid& g, int x, int y) {
            checkIndex(g, x, y);
            return LogOddsGrid::dequantize(g.addHit(g.geometry().index(x, y)));
          },
          "Adds one hit (l_hit) to cell (x, y).")
      .def(
          "add_miss",
          [](LogOddsGrid& g, int x, int y) {
            checkIndex(g, x, y);
            return LogOddsGrid::dequantize(g.addMiss(g.geometry().index(x, y)));
          },
          "Adds one miss (l_miss) to cell (x, y).")
      .def(
          "cell_log_odds",
          [](const LogOddsGrid& g, int x, int y) {
            checkIndex(g, x, y);
            return g.logOdds(g.geometry().index(x, y));
          },
          "The log-odds of cell (x, y).")
      .def(
          "cell_probability",
          [](const LogOddsGrid& g, int x, int y) {
            checkIndex(g, x, y);
            return g.probability(g.geometry().index(x, y));
          },
          "The occupancy probability of cell (x, y).")
      .def("reset", &LogOddsGrid::reset, "All cells back to unknown (log-odds 0).")
      .def("shift", &LogOddsGrid::shift, py::arg("dx"), py::arg("dy"),
           "Moves the grid's origin by (dx, dy) whole cells (rolling window); cells that come into "
           "view are unknown.")
      .def(
          "decay",
          [](LogOddsGrid& self, double factor) {
            CellBounds all;
            all.expand(0, 0);
            all.expand(self.geometry().sizeX() - 1, self.geometry().sizeY() - 1);
            std::size_t changed = 0;
            self.decay(factor, all, &changed);
            return changed;
          },
          py::arg("factor"),
          "Every cell's log-odds times factor in [0, 1] (exp(-dt / tau)), rounded toward zero. "
          "Returns how many cells changed state.")
      .def("max_abs_log_odds", &LogOddsGrid::maxAbsLogOdds,
           "Largest |log-odds| over the grid (health metric: at the clamp, never beyond).")
      .def_property_readonly("memory_bytes", &LogOddsGrid::memoryBytes, "bytes held by the cells");

  m.def("log_odds_of", &LogOddsGrid::logOddsOf, "log(p / (1 - p))");
  m.def("probability_of", &LogOddsGrid::probabilityOf, "1 - 1 / (1 + exp(l))");
}

// Scans and clouds into a log-odds grid: ScanIntegrator with its config and stats.
void bindScanIntegration(py::module& m) {
  py::class_<ScanIntegratorConfig>(
      m, "ScanIntegratorConfig",
      "Ranges (m) and REP-117 options of the scan integrator (costmap_2d's obstacle-source keys).")
      .def(py::init<>())
      .def_readwrite("marking", &ScanIntegratorConfig::marking, "returns mark their cell")
      .def_readwrite("clearing", &ScanIntegratorConfig::clearing,
                     "beams clear the cells they cross")
      .def_readwrite("obstacle_min_range", &ScanIntegratorConfig::obstacle_min_range,
                     "m: returns nearer than this do not mark")
      .def_readwrite("obstacle_max_range", &ScanIntegratorConfig::obstacle_max_range,
                     "m: returns farther than this do not mark")
      .def_readwrite("raytrace_min_range", &ScanIntegratorConfig::raytrace_min_range,
                     "m: clearing starts this far from the sensor")
      .def_readwrite("raytrace_max_range", &ScanIntegratorConfig::raytrace_max_range,
                     "m: clearing stops this far from the sensor")
      .def_readwrite("inf_is_valid", &ScanIntegratorConfig::inf_is_valid,
                     "+Inf means \"no return\": clear, do not mark")
      .def_readwrite("range_max_is_no_return", &ScanIntegratorConfig::range_max_is_no_return,
                     "treat r == range_max as +Inf")
      .def("validate", &ScanIntegratorConfig::validate,
           "Empty string if the configuration is valid, else the reason (what the constructors "
           "raise).");

  py::class_<IntegrationStats>(m, "IntegrationStats",
                               "What one scan integration did: beams by kind, cells cleared, "
                               "marked and changed, touched and changed windows.")
      .def_readonly("beams", &IntegrationStats::beams, "beams offered")
      .def_readonly("beams_marked", &IntegrationStats::beams_marked,
                    "beams whose hit cell got (or shared) a hit update")
      .def_readonly("beams_no_return", &IntegrationStats::beams_no_return,
                    "+Inf (or range_max when treated so) beams that cleared")
      .def_readonly("beams_invalid", &IntegrationStats::beams_invalid,
                    "NaN, -Inf, outside [range_min, range_max]")
      .def_readonly("beams_beyond_obstacle_range", &IntegrationStats::beams_beyond_obstacle_range,
                    "returns too far (or near) to mark")
      .def_readonly(
          "cells_cleared", &IntegrationStats::cells_cleared,
          "Cells walked by clearing rays, per beam (a cell two beams cross counts twice, as in the "
          "lesson's \"a 10 m beam clears ~200 cells\"). Each cell still receives at most one miss "
          "update per scan, and none if it was hit in the same scan.")
      .def_readonly("cells_marked", &IntegrationStats::cells_marked,
                    "cells that received a hit update")
      .def_readonly("cells_changed", &IntegrationStats::cells_changed,
                    "cells whose state (free/occupied/unknown) changed")
      .def_readonly("points_outside_height", &IntegrationStats::points_outside_height,
                    "cloud points outside [min, max]_obstacle_height")
      .def_readonly("points_merged", &IntegrationStats::points_merged,
                    "cloud points sharing a merge cell with an earlier one")
      .def_property_readonly(
          "touched", [](const IntegrationStats& s) { return boundsToTuple(s.touched); },
          "(min_x, min_y, max_x, max_y) inclusive, or () if nothing was touched")
      .def_property_readonly(
          "changed", [](const IntegrationStats& s) { return boundsToTuple(s.changed); },
          "(x0, y0, x1, y1) cells whose state changed, or None")
      .def("clear_mark_ratio", &IntegrationStats::clearMarkRatio,
           "Cells cleared per cell marked (the phantom-wall diagnostic; healthy >> 1).");

  py::class_<ScanIntegrator>(m, "ScanIntegrator",
                             "Integrates laser scans (ranges in metres) into a LogOddsGrid: hits "
                             "first, then each cell cleared at most once per scan.")
      .def(py::init<const ScanIntegratorConfig&>(),
           py::arg_v("config", ScanIntegratorConfig{}, "ScanIntegratorConfig()"))
      .def_property_readonly("config", &ScanIntegrator::config, "the configuration in use")
      .def_property("threads", &ScanIntegrator::threads, &ScanIntegrator::setThreads,
                    "threads of the clearing walk: 1, or 2 (the default where the machine has "
                    "two cores) for dense scans (200,000 ray cells or more); the grid is the same "
                    "bit for bit")
      .def_property_readonly(
          "walk_runs",
          [](const ScanIntegrator& self) {
            const auto& runs = self.walkChooser().runs();
            py::dict d;
            d["per_ray"] = runs[WalkChooser::kPerRay];
            d["blocks"] = runs[WalkChooser::kBlocks];
            d["reverse_query"] = runs[WalkChooser::kReverseQuery];
            d["first_visit"] = runs[WalkChooser::kFirstVisit];
            d["per_ray_shared"] = runs[WalkChooser::kPerRayShared];
            d["blocks_shared"] = runs[WalkChooser::kBlocksShared];
            d["first_visit_shared"] = runs[WalkChooser::kFirstVisitShared];
            return d;
          },
          "scans over seen space walked by each clearing walk, as timed and chosen by the "
          "integrator (per_ray, blocks, reverse_query, first_visit; *_shared: on two "
          "threads); the grid is the same whichever ran")
      .def(
          "integrate",
          [](ScanIntegrator& self, LogOddsGrid& grid,
             py::array_t<float, py::array::c_style | py::array::forcecast> ranges, double angle_min,
             double angle_increment, double range_min, double range_max,
             std::tuple<double, double, double> pose) {
            if (ranges.ndim() != 1) throw std::invalid_argument("ranges must be 1-D");
            LaserScanView view{ranges.data(), static_cast<std::size_t>(ranges.shape(0)),
                               angle_min,     angle_increment,
                               range_min,     range_max};
            const Pose2D p{std::get<0>(pose), std::get<1>(pose), std::get<2>(pose)};
            py::gil_scoped_release release;
            return self.integrate(grid, view, p);
          },
          py::arg("grid"), py::arg("ranges"), py::arg("angle_min"), py::arg("angle_increment"),
          py::arg("range_min"), py::arg("range_max"), py::arg("sensor_pose"),
          "Integrates one LaserScan (REP-117 semantics) taken at sensor_pose = (x, y, yaw) in the "
          "grid frame. Raises ValueError for a malformed scan header.")
      .def(
          "integrate_moving",
          [](ScanIntegrator& self, LogOddsGrid& grid,
             py::array_t<float, py::array::c_style | py::array::forcecast> ranges, double angle_min,
             double angle_increment, double range_min, double range_max,
             std::tuple<double, double, double> first, std::tuple<double, double, double> last) {
            if (ranges.ndim() != 1) throw std::invalid_argument("ranges must be 1-D");
            LaserScanView view{ranges.data(), static_cast<std::size_t>(ranges.shape(0)),
                               angle_min,     angle_increment,
                               range_min,     range_max};
            const std::string why = view.validate();
            if (!why.empty()) throw std::invalid_argument(why);
            const Pose2D a{std::get<0>(first), std::get<1>(first), std::get<2>(first)};
            const Pose2D b{std::get<0>(last), std::get<1>(last), std::get<2>(last)};
            py::gil_scoped_release release;
            std::vector<BeamUpdate> beams;
            IntegrationStats decisions;
            self.beamsFromMovingScan(view, a, b, &beams, &decisions);
            return self.integrate(grid, beams, decisions);
          },
          py::arg("grid"), py::arg("ranges"), py::arg("angle_min"), py::arg("angle_increment"),
          py::arg("range_min"), py::arg("range_max"), py::arg("first_beam_pose"),
          py::arg("last_beam_pose"),
          "Like integrate(), for a scan swept while the sensor moved: each beam is cast from the "
          "pose interpolated between the first and the last beam's pose (per-beam correction).")
      .def(
          "integrate_cloud",
          [](ScanIntegrator& self, LogOddsGrid& grid,
             py::array_t<float, py::array::c_style | py::array::forcecast> points,
             py::array_t<double, py::array::c_style | py::array::forcecast> grid_from_sensor,
             double min_obstacle_height, double max_obstacle_height, bool merge_cells) {
            if (points.ndim() != 2 || points.shape(1) != 3) {
              throw std::invalid_argument("points must be an (N, 3) array");
            }
            if (grid_from_sensor.ndim() != 2 || grid_from_sensor.shape(0) != 4 ||
                grid_from_sensor.shape(1) != 4) {
              throw std::invalid_argument("grid_from_sensor must be a 4 x 4 matrix");
            }
            CloudBeamsConfig config;
            config.min_obstacle_height = min_obstacle_height;
            config.max_obstacle_height = max_obstacle_height;
            if (merge_cells) config.merge_grid = grid.geometry();
            const std::string why = config.validate();
            if (!why.empty()) throw std::invalid_argument(why);
            Eigen::Matrix4d m;
            for (int r = 0; r < 4; ++r) {
              for (int c = 0; c < 4; ++c) m(r, c) = grid_from_sensor.at(r, c);
            }
            Eigen::Isometry3d pose(m);
            py::gil_scoped_release release;
            std::vector<BeamUpdate> beams;
            IntegrationStats decisions;
            beamsFromCloud(self, config, reinterpret_cast<const unsigned char*>(points.data()),
                           static_cast<std::size_t>(points.shape(0)), 3 * sizeof(float), pose,
                           &beams, &decisions);
            return self.integrate(grid, beams, decisions);
          },
          py::arg("grid"), py::arg("points"), py::arg("grid_from_sensor"),
          py::arg("min_obstacle_height") = 0.0, py::arg("max_obstacle_height") = 2.0,
          py::arg("merge_cells") = false,
          "Integrates an (N, 3) point cloud in the sensor frame placed by the 4 x 4 transform "
          "grid_from_sensor; points outside the height band (grid frame z, m) are skipped; with "
          "merge_cells one beam per grid cell (the first point in it).");
}

// The static map layer and its occupancy-grid conversion.
void bindStaticMap(py::module& m) {
  py::class_<StaticMapConfig>(m, "StaticMapConfig",
                              "How an OccupancyGrid becomes costs (map_server's thresholds, "
                              "track_unknown_space, trinary_costmap).")
      .def(py::init<>())
      .def_readwrite("track_unknown_space", &StaticMapConfig::track_unknown_space,
                     "costmap_2d's StaticLayer default (layer level)")
      .def_readwrite("use_maximum", &StaticMapConfig::use_maximum,
                     "combine with the master by max instead of overwriting")
      .def_readwrite("lethal_cost_threshold", &StaticMapConfig::lethal_cost_threshold,
                     "occupancy value (0..100) from which a cell is lethal")
      .def_readwrite("unknown_cost_value", &StaticMapConfig::unknown_cost_value,
                     "occupancy value meaning unknown (compared as a byte)")
      .def_readwrite("trinary_costmap", &StaticMapConfig::trinary_costmap,
                     "false: below-lethal values scale to 0..253")
      .def_readwrite(
          "max_cells", &StaticMapConfig::max_cells,
          "Largest map accepted (cells); a bigger one is refused. Bounds the layer's memory (one "
          "byte per cell here, one in the master, one in each published grid).");
  m.def(
      "static_map_values",
      [](py::array_t<std::int8_t, py::array::c_style | py::array::forcecast> occupancy,
         const StaticMapConfig& config) {
        const auto table = staticValueTable(config);
        py::array_t<std::uint8_t> out(
            std::vector<py::ssize_t>(occupancy.shape(), occupancy.shape() + occupancy.ndim()));
        const std::int8_t* in = occupancy.data();
        std::uint8_t* o = out.mutable_data();
        for (py::ssize_t k = 0; k < occupancy.size(); ++k) {
          o[k] = table[static_cast<std::uint8_t>(in[k])];
        }
        return out;
      },
      py::arg("occupancy"), py::arg_v("config", StaticMapConfig{}, "StaticMapConfig()"),
      "nav_msgs/OccupancyGrid values (int8, any shape) -> costs, costmap_2d's StaticLayer "
      "mapping.");
  py::class_<StaticMap>(m, "StaticMap",
                        "A static map (nav_msgs/OccupancyGrid values) as costmap costs, with "
                        "costmap_2d StaticLayer's translation.")
      .def(py::init<const StaticMapConfig&>(),
           py::arg_v("config", StaticMapConfig{}, "StaticMapConfig()"))
      .def(
          "set_map",
          [](StaticMap& self,
             py::array_t<std::int8_t, py::array::c_style | py::array::forcecast> data,
             double resolution, double origin_x, double origin_y) {
            if (data.ndim() != 2) throw std::invalid_argument("data must be a 2-D [y, x] array");
            StaticMapInfo info;
            info.height = data.shape(0), info.width = data.shape(1);
            info.resolution = resolution, info.origin_x = origin_x, info.origin_y = origin_y;
            info.data_size = static_cast<std::size_t>(data.size());
            const std::string why = self.setMap(info, data.data());
            if (!why.empty()) throw std::invalid_argument(why);
          },
          py::arg("data"), py::arg("resolution"), py::arg("origin_x") = 0.0,
          py::arg("origin_y") = 0.0,
          "Replaces the map ([y, x] int8 occupancy); ValueError (map kept) if it is refused.")
      .def(
          "apply_update",
          [](StaticMap& self, std::int64_t x, std::int64_t y,
             py::array_t<std::int8_t, py::array::c_style | py::array::forcecast> data) {
            if (data.ndim() != 2) throw std::invalid_argument("data must be a 2-D [y, x] array");
            const std::string why =
                self.applyUpdate(x, y, data.shape(1), data.shape(0), data.data(),
                                 static_cast<std::size_t>(data.size()));
            if (!why.empty()) throw std::invalid_argument(why);
          },
          py::arg("x"), py::arg("y"), py::arg("data"),
          "map_msgs/OccupancyGridUpdate: rewrites [x, x + w) x [y, y + h); ValueError (nothing "
          "written) if the window is not inside the map.")
      .def_property_readonly("has_map", &StaticMap::hasMap, "whether a map was accepted")
      .def_property_readonly(
          "geometry", [](const StaticMap& self) { return self.costs().geometry(); },
          "the grid's geometry")
      .def(
          "costs",
          [](const StaticMap& self) {
            const GridGeometry& g = self.costs().geometry();
            py::array_t<std::uint8_t> out({g.sizeY(), g.sizeX()});
            std::copy(self.costs().cells().begin(), self.costs().cells().end(), out.mutable_data());
            return out;
          },
          "[y, x] uint8 costs.")
      .def_property_readonly(
          "last_change",
          [](const StaticMap& self) {
            const CellBounds& b = self.lastChange();
            return py::make_tuple(b.min_x, b.min_y, b.max_x, b.max_y);
          },
          "(min_x, min_y, max_x, max_y) cells, inclusive; min > max if nothing changed");
}

// Inflation (cost, inflate) and the footprint helpers.
void bindInflationAndFootprint(py::module& m) {
  py::class_<InflationConfig>(m, "InflationConfig",
                              "Inflation radius and inscribed radius (m) and cost_scaling_factor "
                              "(1/m), as costmap_2d's InflationLayer.")
      .def(py::init<>())
      .def_readwrite("inflation_radius", &InflationConfig::inflation_radius,
                     "m: cells farther than this from any lethal cell get 0")
      .def_readwrite("cost_scaling_factor", &InflationConfig::cost_scaling_factor,
                     "1/m: exponential decay rate beyond the inscribed radius")
      .def_readwrite("inscribed_radius", &InflationConfig::inscribed_radius,
                     "m: from the footprint; cells this close get 253")
      .def_readwrite("inflate_unknown", &InflationConfig::inflate_unknown,
                     "write inflated costs over NO_INFORMATION cells (costmap_2d)")
      .def_readonly_static("MAX_RADIUS_CELLS", &InflationConfig::kMaxRadiusCells,
                           "largest inflation_radius / resolution accepted")
      .def("validate", py::overload_cast<>(&InflationConfig::validate, py::const_),
           "Empty string if the configuration is valid, else the reason (what the constructors "
           "raise).")
      .def("validate", py::overload_cast<double>(&InflationConfig::validate, py::const_),
           py::arg("resolution_m"), "Also checks the radius in cells at this resolution.");
  m.def("inflation_cost", &inflationCost, py::arg("distance_m"), py::arg("config"),
        "costmap_2d's cost for a cell at distance_m from the nearest lethal cell.");
  m.def(
      "inflate",
      [](py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast> costs,
         double resolution, const InflationConfig& config) {
        if (costs.ndim() != 2) throw std::invalid_argument("costs must be a 2-D [y, x] array");
        const int h = static_cast<int>(costs.shape(0));
        const int w = static_cast<int>(costs.shape(1));
        Costmap master(GridGeometry(w, h, resolution, 0.0, 0.0), cost::kFreeSpace);
        std::copy(costs.data(), costs.data() + costs.size(), master.data());
        Inflator inflator(config, resolution);
        CellBounds all;
        all.expand(0, 0);
        all.expand(w - 1, h - 1);
        inflator.update(&master, all);
        py::array_t<std::uint8_t> out({h, w});
        std::copy(master.cells().begin(), master.cells().end(), out.mutable_data());
        return out;
      },
      py::arg("costs"), py::arg("resolution"), py::arg("config"),
      "Inflates a whole [y, x] uint8 cost grid (254 = lethal) and returns the merged grid.");
  m.def(
      "footprint_radii",
      [](const std::vector<std::pair<double, double>>& points) {
        Footprint polygon;
        for (const auto& [x, y] : points) polygon.push_back({x, y});
        const std::string why = validateFootprint(polygon);
        if (!why.empty()) throw std::invalid_argument(why);
        return std::make_pair(inscribedRadius(polygon), circumscribedRadius(polygon));
      },
      py::arg("points"), "(inscribed, circumscribed) radius of a footprint polygon, m.");
  m.def(
      "footprint_cells",
      [](const std::vector<std::pair<double, double>>& points,
         std::tuple<double, double, double> pose, const GridGeometry& geometry) {
        Footprint polygon;
        for (const auto& [x, y] : points) polygon.push_back({x, y});
        const std::string why = validateFootprint(polygon);
        if (!why.empty()) throw std::invalid_argument(why);
        std::vector<std::size_t> cells;
        polygonCells(transformFootprint(
                         polygon, Pose2D{std::get<0>(pose), std::get<1>(pose), std::get<2>(pose)}),
                     geometry, &cells);
        py::array_t<bool> mask({geometry.sizeY(), geometry.sizeX()});
        bool* m = mask.mutable_data();
        std::fill(m, m + geometry.cellCount(), false);
        for (const std::size_t i : cells) m[i] = true;
        return mask;
      },
      py::arg("points"), py::arg("pose"), py::arg("geometry"),
      "[y, x] bool mask of the cells whose centre lies inside the footprint placed at pose = "
      "(x, y, yaw): the cells the obstacle layer clears under the robot.");
}

}  // namespace

void bindCostmap(py::module& m) {
  bindLogOddsGrid(m);
  bindScanIntegration(m);
  bindStaticMap(m);
  bindInflationAndFootprint(m);
}
