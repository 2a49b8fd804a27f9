// Python bindings of the ROS-free core: numpy arrays in and out, same numbers as the C++ tests.
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

void bindTsdf(py::module& m);  // bind_tsdf.cpp

namespace {

py::array_t<int> cellsToArray(const std::vector<CellIndex>& cells) {
  py::array_t<int> out({static_cast<py::ssize_t>(cells.size()), py::ssize_t{2}});
  auto a = out.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < static_cast<py::ssize_t>(cells.size()); ++i) {
    a(i, 0) = cells[i].x;
    a(i, 1) = cells[i].y;
  }
  return out;
}

py::tuple boundsToTuple(const CellBounds& b) {
  if (b.empty()) return py::make_tuple();
  return py::make_tuple(b.min_x, b.min_y, b.max_x, b.max_y);
}

template <class T, class F>
py::array_t<T> gridArray(const LogOddsGrid& grid, F&& value) {
  const GridGeometry& g = grid.geometry();
  py::array_t<T> out({static_cast<py::ssize_t>(g.sizeY()), static_cast<py::ssize_t>(g.sizeX())});
  T* data = out.mutable_data();
  for (std::size_t i = 0; i < g.cellCount(); ++i) data[i] = value(i);
  return out;
}

void checkIndex(const LogOddsGrid& grid, int x, int y) {
  if (!grid.geometry().inBounds(x, y)) throw py::index_error("cell outside the grid");
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "downstream_perception ROS-free core (C++), with numpy arrays in and out.";
  // The package refuses numpy 2 with a pybind11 older than 2.12 (see __init__.py).
  m.attr("pybind11_version") = py::make_tuple(PYBIND11_VERSION_MAJOR, PYBIND11_VERSION_MINOR);
  bindTsdf(m);

  // ----------------------------------------------------------------- grid geometry
  py::class_<GridGeometry>(m, "GridGeometry",
                           "Grid placement: size in cells, resolution (m), origin (m) of the "
                           "lower-left corner. Arrays are indexed [y, x].")
      .def(py::init<int, int, double, double, double>(), py::arg("size_x"), py::arg("size_y"),
           py::arg("resolution"), py::arg("origin_x") = 0.0, py::arg("origin_y") = 0.0)
      .def_property_readonly("size_x", &GridGeometry::sizeX)
      .def_property_readonly("size_y", &GridGeometry::sizeY)
      .def_property_readonly("resolution", &GridGeometry::resolution)
      .def_property_readonly("origin_x", &GridGeometry::originX)
      .def_property_readonly("origin_y", &GridGeometry::originY)
      .def(
          "world_to_cell",
          [](const GridGeometry& g, double wx, double wy) {
            const CellIndex c = g.worldToCellUnbounded(wx, wy);
            return py::make_tuple(c.x, c.y);
          },
          "Cell (x, y) containing the point, by floor; may lie outside the grid.")
      .def("in_bounds", &GridGeometry::inBounds)
      .def("cell_centre",
           [](const GridGeometry& g, int x, int y) {
             double wx = 0;
             double wy = 0;
             g.cellCentre(x, y, &wx, &wy);
             return py::make_tuple(wx, wy);
           })
      .def("__repr__", [](const GridGeometry& g) {
        return "GridGeometry(" + std::to_string(g.sizeX()) + ", " + std::to_string(g.sizeY()) +
               ", " + std::to_string(g.resolution()) + ", " + std::to_string(g.originX()) + ", " +
               std::to_string(g.originY()) + ")";
      });

  // ----------------------------------------------------------------- ray traversal
  m.def(
      "bresenham_line",
      [](int x0, int y0, int x1, int y1) { return cellsToArray(bresenhamLine(x0, y0, x1, y1)); },
      "Integer Bresenham cells from (x0, y0) to (x1, y1), both included; (N, 2) int array.");
  m.def(
      "ray_cells",
      [](const GridGeometry& g, double x0, double y0, double x1, double y1, bool include_end) {
        return cellsToArray(rayCells(g, x0, y0, x1, y1, include_end));
      },
      py::arg("geometry"), py::arg("x0"), py::arg("y0"), py::arg("x1"), py::arg("y1"),
      py::arg("include_end") = true,
      "Every cell the world segment crosses (Amanatides-Woo), clipped to the grid, in order.");

  // ----------------------------------------------------------------- log-odds grid
  py::class_<LogOddsConfig>(m, "LogOddsConfig")
      .def(py::init<>())
      .def_readwrite("p_hit", &LogOddsConfig::p_hit)
      .def_readwrite("p_miss", &LogOddsConfig::p_miss)
      .def_readwrite("clamp_min", &LogOddsConfig::clamp_min)
      .def_readwrite("clamp_max", &LogOddsConfig::clamp_max)
      .def_readwrite("occupied_threshold", &LogOddsConfig::occupied_threshold)
      .def_readwrite("free_threshold", &LogOddsConfig::free_threshold)
      .def("validate", &LogOddsConfig::validate, "Empty string if valid, else the reason.");

  py::class_<LogOddsGrid>(m, "LogOddsGrid",
                          "Fixed-point log-odds occupancy grid (2 bytes per cell, quantum 1/1024).")
      .def(py::init<const GridGeometry&, const LogOddsConfig&>(), py::arg("geometry"),
           py::arg("config") = LogOddsConfig{})
      .def_property_readonly("geometry", &LogOddsGrid::geometry)
      .def_property_readonly("config", &LogOddsGrid::config)
      .def_property_readonly_static("quantum", [](py::object) { return LogOddsGrid::kQuantum; })
      .def_property_readonly(
          "hit_increment",
          [](const LogOddsGrid& g) { return LogOddsGrid::dequantize(g.hitUnits()); })
      .def_property_readonly(
          "miss_increment",
          [](const LogOddsGrid& g) { return LogOddsGrid::dequantize(g.missUnits()); })
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
      .def("set_log_odds",
           [](LogOddsGrid& g,
              py::array_t<double, py::array::c_style | py::array::forcecast> values) {
             const GridGeometry& geo = g.geometry();
             if (values.ndim() != 2 || values.shape(0) != geo.sizeY() ||
                 values.shape(1) != geo.sizeX()) {
               throw std::invalid_argument("expected an array of shape (size_y, size_x)");
             }
             const double* v = values.data();
             for (std::size_t i = 0; i < geo.cellCount(); ++i) g.setLogOdds(i, v[i]);
           })
      .def("add_hit",
           [](LogOddsGrid& g, int x, int y) {
             checkIndex(g, x, y);
             return LogOddsGrid::dequantize(g.addHit(g.geometry().index(x, y)));
           })
      .def("add_miss",
           [](LogOddsGrid& g, int x, int y) {
             checkIndex(g, x, y);
             return LogOddsGrid::dequantize(g.addMiss(g.geometry().index(x, y)));
           })
      .def("cell_log_odds",
           [](const LogOddsGrid& g, int x, int y) {
             checkIndex(g, x, y);
             return g.logOdds(g.geometry().index(x, y));
           })
      .def("cell_probability",
           [](const LogOddsGrid& g, int x, int y) {
             checkIndex(g, x, y);
             return g.probability(g.geometry().index(x, y));
           })
      .def("reset", &LogOddsGrid::reset)
      .def("shift", &LogOddsGrid::shift, py::arg("dx"), py::arg("dy"))
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
      .def("max_abs_log_odds", &LogOddsGrid::maxAbsLogOdds)
      .def_property_readonly("memory_bytes", &LogOddsGrid::memoryBytes);

  m.def("log_odds_of", &LogOddsGrid::logOddsOf, "log(p / (1 - p))");
  m.def("probability_of", &LogOddsGrid::probabilityOf, "1 - 1 / (1 + exp(l))");

  // ----------------------------------------------------------------- scan integration
  py::class_<ScanIntegratorConfig>(m, "ScanIntegratorConfig")
      .def(py::init<>())
      .def_readwrite("marking", &ScanIntegratorConfig::marking)
      .def_readwrite("clearing", &ScanIntegratorConfig::clearing)
      .def_readwrite("obstacle_min_range", &ScanIntegratorConfig::obstacle_min_range)
      .def_readwrite("obstacle_max_range", &ScanIntegratorConfig::obstacle_max_range)
      .def_readwrite("raytrace_min_range", &ScanIntegratorConfig::raytrace_min_range)
      .def_readwrite("raytrace_max_range", &ScanIntegratorConfig::raytrace_max_range)
      .def_readwrite("inf_is_valid", &ScanIntegratorConfig::inf_is_valid)
      .def_readwrite("range_max_is_no_return", &ScanIntegratorConfig::range_max_is_no_return)
      .def("validate", &ScanIntegratorConfig::validate);

  py::class_<IntegrationStats>(m, "IntegrationStats")
      .def_readonly("beams", &IntegrationStats::beams)
      .def_readonly("beams_marked", &IntegrationStats::beams_marked)
      .def_readonly("beams_no_return", &IntegrationStats::beams_no_return)
      .def_readonly("beams_invalid", &IntegrationStats::beams_invalid)
      .def_readonly("beams_beyond_obstacle_range", &IntegrationStats::beams_beyond_obstacle_range)
      .def_readonly("cells_cleared", &IntegrationStats::cells_cleared)
      .def_readonly("cells_marked", &IntegrationStats::cells_marked)
      .def_readonly("cells_changed", &IntegrationStats::cells_changed)
      .def_readonly("points_outside_height", &IntegrationStats::points_outside_height)
      .def_readonly("points_merged", &IntegrationStats::points_merged)
      .def_property_readonly(
          "touched", [](const IntegrationStats& s) { return boundsToTuple(s.touched); },
          "(min_x, min_y, max_x, max_y) inclusive, or () if nothing was touched")
      .def_property_readonly("changed",
                             [](const IntegrationStats& s) { return boundsToTuple(s.changed); })
      .def("clear_mark_ratio", &IntegrationStats::clearMarkRatio);

  py::class_<ScanIntegrator>(m, "ScanIntegrator")
      .def(py::init<const ScanIntegratorConfig&>(), py::arg("config") = ScanIntegratorConfig{})
      .def_property_readonly("config", &ScanIntegrator::config)
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

  // ----------------------------------------------------------------- SE(2)
  py::class_<Pose2D>(m, "Pose2D")
      .def(py::init<double, double, double>(), py::arg("x") = 0.0, py::arg("y") = 0.0,
           py::arg("yaw") = 0.0)
      .def_readwrite("x", &Pose2D::x)
      .def_readwrite("y", &Pose2D::y)
      .def_readwrite("yaw", &Pose2D::yaw)
      .def("as_tuple", [](const Pose2D& p) { return py::make_tuple(p.x, p.y, p.yaw); })
      .def("__repr__", [](const Pose2D& p) {
        return "Pose2D(" + std::to_string(p.x) + ", " + std::to_string(p.y) + ", " +
               std::to_string(p.yaw) + ")";
      });
  m.def("compose", &compose, "a ∘ b (parent<-mid ∘ mid<-child = parent<-child)");
  m.def("inverse", &inverse);
  m.def(
      "apply",
      [](const Pose2D& a, py::array_t<double, py::array::c_style | py::array::forcecast> points) {
        if (points.ndim() != 2 || points.shape(1) != 2)
          throw std::invalid_argument("points must be (N, 2)");
        const py::ssize_t n = points.shape(0);
        py::array_t<double> out({n, py::ssize_t{2}});
        const double* in = points.data();
        double* o = out.mutable_data();
        for (py::ssize_t i = 0; i < n; ++i) {
          const Point2 q = apply(a, {in[2 * i], in[2 * i + 1]});
          o[2 * i] = q.x;
          o[2 * i + 1] = q.y;
        }
        return out;
      },
      "R p + t for each row of an (N, 2) array.");
  m.def("interpolate", &interpolate, py::arg("a"), py::arg("t_a"), py::arg("b"), py::arg("t_b"),
        py::arg("t"), "Linear in translation, shortest arc in yaw.");
  m.def("normalize_angle", &normalizeAngle);
  m.def("shortest_angular_distance", &shortestAngularDistance);

  // ----------------------------------------------------------------- costs
  m.attr("FREE_SPACE") = cost::kFreeSpace;
  m.attr("INSCRIBED_INFLATED_OBSTACLE") = cost::kInscribedInflatedObstacle;
  m.attr("LETHAL_OBSTACLE") = cost::kLethalObstacle;
  m.attr("NO_INFORMATION") = cost::kNoInformation;
  m.def(
      "occupancy_table",
      []() {
        constexpr auto table = cost::occupancyTable();
        py::array_t<std::int8_t> out(256);
        std::copy(table.begin(), table.end(), out.mutable_data());
        return out;
      },
      "cost (0..255) -> nav_msgs/OccupancyGrid value, costmap_2d's translation.");

  // ----------------------------------------------------------------- static map
  py::class_<StaticMapConfig>(m, "StaticMapConfig")
      .def(py::init<>())
      .def_readwrite("track_unknown_space", &StaticMapConfig::track_unknown_space)
      .def_readwrite("use_maximum", &StaticMapConfig::use_maximum)
      .def_readwrite("lethal_cost_threshold", &StaticMapConfig::lethal_cost_threshold,
                     "occupancy value 0..100 (clamped) from which a cell is lethal")
      .def_readwrite("unknown_cost_value", &StaticMapConfig::unknown_cost_value,
                     "occupancy value meaning unknown, compared as a byte (-1 = 255)")
      .def_readwrite("trinary_costmap", &StaticMapConfig::trinary_costmap)
      .def_readwrite("max_cells", &StaticMapConfig::max_cells, "largest map accepted, cells");
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
      py::arg("occupancy"), py::arg("config") = StaticMapConfig(),
      "nav_msgs/OccupancyGrid values (int8, any shape) -> costs, costmap_2d's StaticLayer "
      "mapping.");
  py::class_<StaticMap>(m, "StaticMap")
      .def(py::init<const StaticMapConfig&>(), py::arg("config") = StaticMapConfig())
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
      .def_property_readonly("has_map", &StaticMap::hasMap)
      .def_property_readonly("geometry",
                             [](const StaticMap& self) { return self.costs().geometry(); })
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

  // ----------------------------------------------------------------- inflation
  py::class_<InflationConfig>(m, "InflationConfig")
      .def(py::init<>())
      .def_readwrite("inflation_radius", &InflationConfig::inflation_radius, "m")
      .def_readwrite("cost_scaling_factor", &InflationConfig::cost_scaling_factor, "1/m")
      .def_readwrite("inscribed_radius", &InflationConfig::inscribed_radius, "m")
      .def_readwrite("inflate_unknown", &InflationConfig::inflate_unknown)
      .def_readonly_static("MAX_RADIUS_CELLS", &InflationConfig::kMaxRadiusCells,
                           "largest inflation_radius / resolution accepted")
      .def("validate", py::overload_cast<>(&InflationConfig::validate, py::const_))
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
  // ----------------------------------------------------------------- seam health
  m.def("expected_smear", &expectedSmear, py::arg("range_m"), py::arg("yaw_rate_rps"),
        py::arg("age_s"), "range * tan(|yaw rate| * age): sideways throw of a late transform, m.");
  py::class_<CorrectionMonitorConfig>(m, "CorrectionMonitorConfig")
      .def(py::init<>())
      .def_readwrite("window_s", &CorrectionMonitorConfig::window_s, "s")
      .def_readwrite("reset_drop_m", &CorrectionMonitorConfig::reset_drop_m, "m")
      .def_readwrite("max_correction_m", &CorrectionMonitorConfig::max_correction_m, "m")
      .def_readwrite("zero_epsilon_m", &CorrectionMonitorConfig::zero_epsilon_m, "m")
      .def_readwrite("min_travel_m", &CorrectionMonitorConfig::min_travel_m, "m")
      .def_readwrite("ramp_m", &CorrectionMonitorConfig::ramp_m, "m")
      .def("validate", &CorrectionMonitorConfig::validate);
  py::class_<CorrectionMonitor>(m, "CorrectionMonitor", "Watches |map <- odom| over time.")
      .def(py::init<const CorrectionMonitorConfig&>(),
           py::arg("config") = CorrectionMonitorConfig())
      .def("add", &CorrectionMonitor::add, py::arg("time_s"), py::arg("correction_m"),
           py::arg("travelled_m"))
      .def(
          "add_many",
          [](CorrectionMonitor& m, const Eigen::VectorXd& t, const Eigen::VectorXd& c,
             const Eigen::VectorXd& d) {
            if (t.size() != c.size() || t.size() != d.size()) {
              throw std::invalid_argument("time_s, correction_m, travelled_m differ in length");
            }
            for (Eigen::Index i = 0; i < t.size(); ++i) m.add(t[i], c[i], d[i]);
          },
          py::arg("time_s"), py::arg("correction_m"), py::arg("travelled_m"))
      .def_property_readonly("resets", &CorrectionMonitor::resets)
      .def("never_resets", &CorrectionMonitor::neverResets)
      .def("stuck_at_zero", &CorrectionMonitor::stuckAtZero)
      .def("too_large", &CorrectionMonitor::tooLarge)
      .def("findings", &CorrectionMonitor::findings);

  // ----------------------------------------------------------------- predicted obstacles
  py::class_<PredictionConfig>(m, "PredictionConfig")
      .def(py::init<>())
      .def_readwrite("prediction_horizon_s", &PredictionConfig::prediction_horizon_s, "s")
      .def_readwrite("uncertainty_sigmas", &PredictionConfig::uncertainty_sigmas)
      .def_readwrite("max_uncertainty_m", &PredictionConfig::max_uncertainty_m, "m")
      .def_readwrite("min_object_size_m", &PredictionConfig::min_object_size_m, "m")
      .def_readwrite("max_object_size_m", &PredictionConfig::max_object_size_m, "m")
      .def_readwrite("max_speed_mps", &PredictionConfig::max_speed_mps, "m/s")
      .def("validate", &PredictionConfig::validate);
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
      .def_readwrite("position", &PlanarTrack::position, "m")
      .def_readwrite("velocity", &PlanarTrack::velocity, "m/s")
      .def_readwrite("position_covariance", &PlanarTrack::position_covariance, "m^2")
      .def_readwrite("velocity_covariance", &PlanarTrack::velocity_covariance, "m^2/s^2")
      .def_readwrite("size_x", &PlanarTrack::size_x, "m")
      .def_readwrite("size_y", &PlanarTrack::size_y, "m")
      .def_readwrite("box_yaw", &PlanarTrack::box_yaw, "rad")
      .def("validate", &PlanarTrack::validate);
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
      "solve_assignment", [](const Eigen::MatrixXd& cost) { return solveAssignment(cost); },
      py::arg("cost"),
      "Min-cost assignment of rows to columns; inf = forbidden. Returns the column per row or -1.");

  py::enum_<TrackState>(m, "TrackState")
      .value("TENTATIVE", TrackState::kTentative)
      .value("CONFIRMED", TrackState::kConfirmed)
      .value("COASTING", TrackState::kCoasting);
  py::class_<TrackerConfig> tc(m, "TrackerConfig");
  py::enum_<TrackerConfig::Mode>(tc, "Mode")
      .value("METRIC", TrackerConfig::Mode::kMetric)
      .value("IMAGE", TrackerConfig::Mode::kImage);
  tc.def(py::init<>())
      .def_readonly_static("MAX_BOX_COORDINATE_PX", &TrackerConfig::kMaxBoxCoordinatePx,
                           "image mode: larger |box coordinates| are rejected (out of range)")
      .def_readonly_static("MAX_POSITION_M", &TrackerConfig::kMaxPositionM,
                           "metric mode: larger |position| / size are rejected (out of range)")
      .def_readwrite("mode", &TrackerConfig::mode)
      .def_readwrite("gate_confidence", &TrackerConfig::gate_confidence)
      .def_readwrite("duplicate_confidence", &TrackerConfig::duplicate_confidence)
      .def_readwrite("reid_confidence", &TrackerConfig::reid_confidence)
      .def_readwrite("min_iou", &TrackerConfig::min_iou)
      .def_readwrite("accel_psd", &TrackerConfig::accel_psd)
      .def_readwrite("measurement_std", &TrackerConfig::measurement_std)
      .def_readwrite("initial_velocity_std", &TrackerConfig::initial_velocity_std)
      .def_readwrite("min_hits", &TrackerConfig::min_hits)
      .def_readwrite("max_age_s", &TrackerConfig::max_age_s)
      .def_readwrite("high_score", &TrackerConfig::high_score)
      .def_readwrite("low_score", &TrackerConfig::low_score)
      .def_readwrite("second_pass", &TrackerConfig::second_pass)
      .def_readwrite("class_aware", &TrackerConfig::class_aware)
      .def("validate", &TrackerConfig::validate);
  py::class_<TrackerStats>(m, "TrackerStats")
      .def_readonly("detections", &TrackerStats::detections)
      .def_readonly("detections_ignored_low_score", &TrackerStats::detections_ignored_low_score)
      .def_readonly("detections_rejected_invalid", &TrackerStats::detections_rejected_invalid)
      .def_readonly("detections_rejected_out_of_range",
                    &TrackerStats::detections_rejected_out_of_range)
      .def_readonly("matched_first_pass", &TrackerStats::matched_first_pass)
      .def_readonly("matched_second_pass", &TrackerStats::matched_second_pass)
      .def_readonly("unmatched_outside_gate", &TrackerStats::unmatched_outside_gate)
      .def_readonly("births", &TrackerStats::births)
      .def_readonly("deaths", &TrackerStats::deaths)
      .def_readonly("duplicates_removed", &TrackerStats::duplicates_removed)
      .def_readonly("reidentified", &TrackerStats::reidentified)
      .def_readonly("id_switches", &TrackerStats::id_switches)
      .def_readonly("tracks", &TrackerStats::tracks)
      .def_readonly("confirmed", &TrackerStats::confirmed);
  py::class_<Tracker>(m, "Tracker",
                      "SORT-style multi-object tracker (see core/tracking/tracker.h).")
      .def(py::init<const TrackerConfig&>(), py::arg("config") = TrackerConfig{})
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
      .def("reset", &Tracker::reset);
}
