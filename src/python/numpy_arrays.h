// Conversions between the core's types and numpy arrays, shared by the binding files.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <vector>

#include "downstream_perception/core/costmap/log_odds_grid.h"
#include "downstream_perception/core/grid/grid_geometry.h"
#include "downstream_perception/core/grid/ray_traversal.h"

namespace downstream_perception {
namespace python {

inline pybind11::array_t<int> cellsToArray(const std::vector<CellIndex>& cells) {
  pybind11::array_t<int> out({static_cast<pybind11::ssize_t>(cells.size()), pybind11::ssize_t{2}});
  auto a = out.mutable_unchecked<2>();
  for (pybind11::ssize_t i = 0; i < static_cast<pybind11::ssize_t>(cells.size()); ++i) {
    a(i, 0) = cells[i].x;
    a(i, 1) = cells[i].y;
  }
  return out;
}

inline pybind11::tuple boundsToTuple(const CellBounds& b) {
  if (b.empty()) return pybind11::make_tuple();
  return pybind11::make_tuple(b.min_x, b.min_y, b.max_x, b.max_y);
}

template <class T, class F>
inline pybind11::array_t<T> gridArray(const LogOddsGrid& grid, F&& value) {
  const GridGeometry& g = grid.geometry();
  pybind11::array_t<T> out(
      {static_cast<pybind11::ssize_t>(g.sizeY()), static_cast<pybind11::ssize_t>(g.sizeX())});
  T* data = out.mutable_data();
  for (std::size_t i = 0; i < g.cellCount(); ++i) data[i] = value(i);
  return out;
}

inline void checkIndex(const LogOddsGrid& grid, int x, int y) {
  if (!grid.geometry().inBounds(x, y)) throw pybind11::index_error("cell outside the grid");
}

}  // namespace python
}  // namespace downstream_perception
