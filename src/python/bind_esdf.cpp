// Python bindings of the ESDF: EsdfConfig, EsdfUpdateStats and the esdf_* methods of Tsdf
// (registered by bindTsdf first), numpy batches in and out.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "downstream_perception/core/tsdf/esdf.h"
#include "downstream_perception/core/tsdf/esdf_band.h"
#include "tsdf_object.h"

namespace py = pybind11;
using namespace downstream_perception;  // NOLINT
using downstream_perception::python::Tsdf;

namespace {

using PointRows = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

Esdf& esdfOf(Tsdf& self) {
  if (!self.esdf) self.esdf = std::make_unique<Esdf>(EsdfConfig{}, self.map.voxelSize());
  return *self.esdf;
}

py::dict knownVoxels(const Esdf& esdf) {
  py::ssize_t n = 0;
  for (const auto& kv : esdf.blocks()) {
    for (const std::uint8_t s : kv.second->state) n += s != 0;
  }
  py::array_t<std::int32_t> voxels({n, py::ssize_t{3}});
  py::array_t<float> distance(n);
  py::array_t<std::int8_t> occupied(n);
  auto v = voxels.mutable_unchecked<2>();
  auto d = distance.mutable_unchecked<1>();
  auto o = occupied.mutable_unchecked<1>();
  py::ssize_t i = 0;
  for (const auto& [key, block] : esdf.blocks()) {
    for (int k = 0; k < kTsdfBlockVoxels; ++k) {
      if (block->state[k] == 0) continue;
      const Eigen::Vector3i local(k % kTsdfBlockSide, k / kTsdfBlockSide % kTsdfBlockSide,
                                  k / (kTsdfBlockSide * kTsdfBlockSide));
      const Eigen::Vector3i voxel = key * kTsdfBlockSide + local;
      for (int a = 0; a < 3; ++a) v(i, a) = voxel(a);
      d(i) = block->distance[k];
      o(i) = block->state[k] == static_cast<std::uint8_t>(EsdfState::kOccupied);
      ++i;
    }
  }
  py::dict out;
  out["voxels"] = voxels;
  out["distance"] = distance;
  out["occupied"] = occupied;
  return out;
}

}  // namespace

void bindEsdf(py::module& m) {
  py::class_<EsdfConfig>(
      m, "EsdfConfig",
      "Parameters of the Euclidean signed distance field computed from the TSDF (metres).")
      .def(py::init<>())
      .def_readwrite("max_distance_m", &EsdfConfig::max_distance_m,
                     "Distances are clamped at this (m). Also the reach of a change: a voxel that "
                     "changes state alters distances within this radius only.")
      .def("validate", &EsdfConfig::validate, py::arg("voxel_size_m"),
           "Empty string if valid for TSDF voxels of voxel_size_m (m), else the reason.");
  py::class_<EsdfUpdateStats>(
      m, "EsdfUpdateStats",
      "What one ESDF update did: full or incremental, regions, voxels changed.")
      .def_readonly("full", &EsdfUpdateStats::full, "every block recomputed")
      .def_readonly("blocks_read", &EsdfUpdateStats::blocks_read,
                    "TSDF blocks re-read (integrated since the last update)")
      .def_readonly("blocks_removed", &EsdfUpdateStats::blocks_removed,
                    "blocks the TSDF no longer has")
      .def_readonly("voxels_changed", &EsdfUpdateStats::voxels_changed,
                    "voxels whose state changed")
      .def_readonly("blocks_written", &EsdfUpdateStats::blocks_written,
                    "blocks whose distances were recomputed")
      .def_readonly("regions", &EsdfUpdateStats::regions, "distance-transform regions")
      .def_readonly("region_voxels", &EsdfUpdateStats::region_voxels,
                    "voxels in those regions (seed margins included)");

  auto tsdf = py::reinterpret_borrow<py::class_<Tsdf>>(m.attr("Tsdf"));
  tsdf.def_property_readonly(
          "esdf_config", [](Tsdf& self) { return esdfOf(self).config(); },
          "The ESDF's settings (EsdfConfig's defaults until set_esdf_config).")
      .def(
          "set_esdf_config",
          [](Tsdf& self, const EsdfConfig& c) {
            const std::string why = c.validate(self.map.voxelSize());
            if (!why.empty()) throw std::invalid_argument(why);
            if (self.esdf) {
              self.esdf->setConfig(c);
            } else {  // not through esdfOf: the defaults may not suit this voxel size
              self.esdf = std::make_unique<Esdf>(c, self.map.voxelSize());
            }
          },
          py::arg("config"), "Raises ValueError if invalid; the next esdf_update is full.")
      .def(
          "esdf_update",
          [](Tsdf& self) {
            Esdf& esdf = esdfOf(self);
            py::gil_scoped_release release;
            return esdf.update(self.map);
          },
          "Brings the ESDF up to date with the map: recomputes only within max_distance_m of "
          "voxels whose state (unknown / free / occupied) changed since the last update.")
      .def(
          "esdf_recompute",
          [](Tsdf& self) {
            Esdf& esdf = esdfOf(self);
            py::gil_scoped_release release;
            return esdf.recompute(self.map);
          },
          "Recomputes the whole ESDF.")
      .def(
          "esdf_distance",
          [](Tsdf& self, const PointRows& points) {
            const Esdf& esdf = esdfOf(self);
            const auto n = static_cast<py::ssize_t>(points.rows());
            py::array_t<double> distance(n);
            py::array_t<double> gradient({n, py::ssize_t{3}});
            auto d = distance.mutable_unchecked<1>();
            auto g = gradient.mutable_unchecked<2>();
            {
              py::gil_scoped_release release;
              for (py::ssize_t i = 0; i < n; ++i) {
                const EsdfSample s = esdf.sample(points.row(i).transpose());
                d(i) = s.distance;
                for (int a = 0; a < 3; ++a) g(i, a) = s.gradient(a);
              }
            }
            return py::make_tuple(distance, gradient);
          },
          py::arg("points"),
          "Signed distance (N,) in m and its gradient (N, 3) at points (N, 3), trilinear "
          "between the 8 voxel centres around each point; NaN where one of them is unknown. "
          "As of the last esdf_update.")
      .def(
          "esdf_voxels", [](Tsdf& self) { return knownVoxels(esdfOf(self)); },
          "Every known ESDF voxel: dict of voxels (N, 3) int32 lattice indices (centre = index "
          "* voxel_size_m), distance (N,) float32 m, occupied (N,) int8.")
      .def(
          "esdf_band_slice",
          [](const Tsdf& self, double min_z_m, double max_z_m, double max_distance_m,
             const std::optional<GridGeometry>& grid, std::size_t max_computed_columns) {
            EsdfBandConfig c;
            c.max_computed_columns = max_computed_columns;
            c.min_z_m = min_z_m;
            c.max_z_m = max_z_m;
            c.max_distance_m = max_distance_m;
            c.grid = grid;
            const std::string why = c.validate(self.map.voxelSize());
            if (!why.empty()) throw std::invalid_argument("esdf_band_slice: " + why);
            EsdfBandSlice band;
            {
              py::gil_scoped_release release;
              band = esdfBandSlice(self.map, c);
            }
            py::array_t<float> distance({static_cast<py::ssize_t>(band.grid.sizeY()),
                                         static_cast<py::ssize_t>(band.grid.sizeX())});
            std::copy(band.distance_m.begin(), band.distance_m.end(), distance.mutable_data());
            py::dict out;
            out["grid"] = band.grid;
            out["distance"] = distance;
            out["columns_occupied"] = band.stats.columns_occupied;
            out["columns_free"] = band.stats.columns_free;
            out["columns_computed"] = band.stats.columns_computed;
            out["voxels_in_band"] = band.stats.voxels_in_band;
            out["padding_voxels"] = band.stats.padding_voxels;
            out["padding_cut"] = band.stats.padding_cut;
            return out;
          },
          py::arg("min_z_m") = 0.05, py::arg("max_z_m") = 1.8, py::arg("max_distance_m") = 2.0,
          py::arg("grid") = py::none(), py::arg("max_computed_columns") = 0,
          "The height band's 2-D ESDF (what the nodelet publishes as ~slice_distance): a column "
          "is occupied when a voxel of the band (centres in [min_z_m, max_z_m], m) over it is "
          "occupied (D < 0, the ESDF's rule), free when it has only free and unknown ones. dict "
          "of grid (GridGeometry: the argument, else the cells of Tsdf.slice over the map) and "
          "distance (float32 [y, x], m): (sqrt(k) - 1/2) * voxel size to the nearest occupied "
          "column (k in squared voxels), negative on occupied columns (to the nearest free "
          "one), clamped at max_distance_m, NaN on unknown columns; columns_occupied, "
          "columns_free (over the "
          "grid), columns_computed (the grid grown by the cap, within the blocks), "
          "voxels_in_band (known band voxels over the grid), padding_voxels (columns computed "
          "beyond the grid on each side) and padding_cut. grid: a window (Tsdf.slice_window) "
          "instead of the whole map; its values equal the whole map's there unless "
          "max_computed_columns (0: no bound) narrowed the padding (padding_cut: a cell nearer "
          "the edge than the cap may then read farther). Read from the map "
          "now (no esdf_update needed). Raises ValueError on an inverted band, a cap outside "
          "[one voxel, 1e6] m or a grid off the voxel lattice.")
      .def_property_readonly(
          "esdf_block_count", [](Tsdf& self) { return esdfOf(self).blockCount(); },
          "ESDF blocks (at most one per TSDF block)")
      .def_property_readonly(
          "esdf_memory_bytes", [](Tsdf& self) { return esdfOf(self).memoryBytes(); },
          "Bytes held by the ESDF's blocks, hash table and scratch.");
}
