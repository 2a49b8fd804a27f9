// Python bindings of the core's grid geometry, ray traversal, SE(2), cost values.
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

void bindGrid(py::module& m) {
  // ----------------------------------------------------------------- grid geometry
  py::class_<GridGeometry>(m, "GridGeometry",
                           "Grid placement: size in cells, resolution (m), origin (m) of the "
                           "lower-left corner. Arrays are indexed [y, x].")
      .def(py::init<int, int, double, double, double>(), py::arg("size_x"), py::arg("size_y"),
           py::arg("resolution"), py::arg("origin_x") = 0.0, py::arg("origin_y") = 0.0)
      .def_property_readonly("size_x", &GridGeometry::sizeX, "cells along x")
      .def_property_readonly("size_y", &GridGeometry::sizeY, "cells along y")
      .def_property_readonly("resolution", &GridGeometry::resolution, "cell edge, m")
      .def_property_readonly("origin_x", &GridGeometry::originX, "x of the lower-left corner, m")
      .def_property_readonly("origin_y", &GridGeometry::originY, "y of the lower-left corner, m")
      .def(
          "world_to_cell",
          [](const GridGeometry& g, double wx, double wy) {
            const CellIndex c = g.worldToCellUnbounded(wx, wy);
            return py::make_tuple(c.x, c.y);
          },
          "Cell (x, y) containing the point, by floor; may lie outside the grid.")
      .def("in_bounds", &GridGeometry::inBounds, "Whether cell (x, y) lies inside the grid.")
      .def(
          "cell_centre",
          [](const GridGeometry& g, int x, int y) {
            double wx = 0;
            double wy = 0;
            g.cellCentre(x, y, &wx, &wy);
            return py::make_tuple(wx, wy);
          },
          "World coordinates (m) of the centre of cell (x, y).")
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

  // ----------------------------------------------------------------- SE(2)
  py::class_<Pose2D>(
      m, "Pose2D",
      "A 2-D pose (x, y in metres, yaw in radians, REP-103): child frame in parent frame.")
      .def(py::init<double, double, double>(), py::arg("x") = 0.0, py::arg("y") = 0.0,
           py::arg("yaw") = 0.0)
      .def_readwrite("x", &Pose2D::x, "m")
      .def_readwrite("y", &Pose2D::y, "m")
      .def_readwrite("yaw", &Pose2D::yaw, "rad, counter-clockwise from x")
      .def(
          "as_tuple", [](const Pose2D& p) { return py::make_tuple(p.x, p.y, p.yaw); },
          "(x, y, yaw) as a tuple.")
      .def("__repr__", [](const Pose2D& p) {
        return "Pose2D(" + std::to_string(p.x) + ", " + std::to_string(p.y) + ", " +
               std::to_string(p.yaw) + ")";
      });
  m.def("compose", &compose, "a ∘ b (parent<-mid ∘ mid<-child = parent<-child)");
  m.def("inverse", &inverse, "The inverse pose: child <- parent from parent <- child.");
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
  m.def("normalize_angle", &normalizeAngle, "The angle (rad) wrapped into [-pi, pi).");
  m.def("shortest_angular_distance", &shortestAngularDistance,
        "Signed shortest rotation (rad) from angle `from` to angle `to`.");

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
}
