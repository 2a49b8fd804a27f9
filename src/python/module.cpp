// The compiled core, downstream_perception._core: one binding function per capability
// (bind_<capability>.cpp), called in an order that registers every type before a default
// argument or another binding uses it.
#include <pybind11/pybind11.h>

namespace py = pybind11;

void bindTsdf(py::module& m);      // bind_tsdf.cpp
void bindEsdf(py::module& m);      // bind_esdf.cpp (adds to bindTsdf's Tsdf)
void bindGrid(py::module& m);      // bind_grid.cpp
void bindCostmap(py::module& m);   // bind_costmap.cpp
void bindTracking(py::module& m);  // bind_tracking.cpp
void bindHandoff(py::module& m);   // bind_handoff.cpp
void bindVoxel(py::module& m);     // bind_voxel.cpp (after Tsdf's PinholeCamera, LogOddsConfig)

PYBIND11_MODULE(_core, m) {
  m.doc() = "downstream_perception ROS-free core (C++), with numpy arrays in and out.";
  // The package refuses numpy 2 with a pybind11 older than 2.12 (see __init__.py).
  m.attr("pybind11_version") = py::make_tuple(PYBIND11_VERSION_MAJOR, PYBIND11_VERSION_MINOR);
  bindGrid(m);  // GridGeometry first: Tsdf.slice takes one
  bindTsdf(m);
  bindEsdf(m);
  bindCostmap(m);
  bindTracking(m);
  bindHandoff(m);
  bindVoxel(m);
}
