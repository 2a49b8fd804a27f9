// Python bindings of the 3-D voxel obstacle map: VoxelMapConfig, VoxelRayConfig, VoxelMap and
// voxel_ray, numpy arrays in and out. Registered after bindTsdf (PinholeCamera) and bindCostmap
// (LogOddsConfig).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

#include "downstream_perception/core/voxel/depth_rays.h"
#include "downstream_perception/core/voxel/voxel_map.h"
#include "downstream_perception/core/voxel/voxel_traversal.h"

namespace py = pybind11;
using namespace downstream_perception;  // NOLINT

namespace {

using PointRows = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

std::vector<float> toFloats(const PointRows& points) {
  std::vector<float> out(static_cast<std::size_t>(points.size()));
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    for (int k = 0; k < 3; ++k) out[3 * i + k] = static_cast<float>(points(i, k));
  }
  return out;
}

Eigen::Isometry3d toIsometry(const Eigen::Matrix4d& m) {
  if (!m.allFinite() || (m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9) {
    throw std::invalid_argument("T_world_camera must be a finite 4 x 4 homogeneous transform");
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if ((r * r.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-6) {
    throw std::invalid_argument("T_world_camera's rotation is not orthonormal");
  }
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = r;
  t.translation() = m.topRightCorner<3, 1>();
  return t;
}

py::dict statsToDict(const VoxelIntegrationStats& s) {
  py::dict d;
  d["rays"] = s.rays;
  d["invalid_points"] = s.invalid_points;
  d["marked"] = s.marked;
  d["cleared"] = s.cleared;
  d["voxels_walked"] = s.voxels_walked;
  d["dropped_updates"] = s.dropped_updates;
  // Both branches as py::tuple: pybind11 3 gives each make_tuple its own typed tuple type.
  d["touched"] = s.touched.empty() ? py::tuple(py::make_tuple())
                                   : py::tuple(py::make_tuple(s.touched.min_x, s.touched.min_y,
                                                              s.touched.max_x, s.touched.max_y));
  return d;
}

py::array_t<std::int32_t> voxelsToArray(const std::vector<VoxelIndex>& v) {
  py::array_t<std::int32_t> out({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
  auto a = out.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < static_cast<py::ssize_t>(v.size()); ++i) {
    a(i, 0) = v[i].x;
    a(i, 1) = v[i].y;
    a(i, 2) = v[i].z;
  }
  return out;
}

void checkVoxel(const VoxelMap& m, int x, int y, int z) {
  if (x < 0 || y < 0 || z < 0 || x >= m.nx() || y >= m.ny() || z >= m.nz()) {
    throw py::index_error("voxel outside the window");
  }
}

}  // namespace

void bindVoxel(py::module& m) {
  py::class_<VoxelMapConfig>(m, "VoxelMapConfig",
                             "3-D voxel obstacle map settings (costmap_2d VoxelLayer's meaning).")
      .def(py::init<>())
      .def_readwrite(
          "resolution_m", &VoxelMapConfig::resolution_m,
          "Edge of a voxel in x and y, m (the layer uses the costmap's resolution). Default 0.05.")
      .def_readwrite("z_resolution_m", &VoxelMapConfig::z_resolution_m,
                     "Height of a voxel, m (costmap_2d VoxelLayer `z_resolution`). Default 0.2.")
      .def_readwrite("origin_z_m", &VoxelMapConfig::origin_z_m,
                     "Height of the bottom of voxel layer 0, m (costmap_2d `origin_z`). Default 0.")
      .def_readwrite("z_voxels", &VoxelMapConfig::z_voxels,
                     "Voxels per column (costmap_2d `z_voxels`, there at most 16; here at most "
                     "kMaxZVoxels). Default 10.")
      .def_readwrite("mark_threshold", &VoxelMapConfig::mark_threshold,
                     "A column with MORE than this many occupied voxels in the height band is "
                     "lethal (costmap_2d `mark_threshold`). Default 0: one occupied voxel marks.")
      .def_readwrite(
          "unknown_threshold", &VoxelMapConfig::unknown_threshold,
          "A column with AT MOST this many unknown voxels is known; a known column that is not "
          "lethal is free, any other is unknown (costmap_2d `unknown_threshold`). Counted as "
          "costmap_2d counts: the band's unknown voxels plus 16 - band when the band has fewer "
          "than 16 voxels (costmap_2d's 16-bit column). Default 15: with 10 voxels, a column is "
          "free once one of its voxels is known, and unknown until then.")
      .def_readwrite("min_obstacle_height_m", &VoxelMapConfig::min_obstacle_height_m,
                     "The robot's height band, m: only voxels whose centre lies in [min, max] are "
                     "projected into the 2-D costmap (an overhang above the robot is kept in 3-D "
                     "but ignored). Defaults 0 and 2.")
      .def_readwrite("max_obstacle_height_m", &VoxelMapConfig::max_obstacle_height_m,
                     "top of the band projected into the costmap, m")
      .def_readwrite("log_odds", &VoxelMapConfig::log_odds,
                     "Inverse sensor model per voxel. Defaults: p_hit 0.7 (+0.847), p_miss 0.4 "
                     "(-0.405), clamp [-2, 3.5] (octomap's 0.12 / 0.97), occupied above 0.5 (one "
                     "hit marks, as in costmap_2d), free below -0.3 (one miss frees).")
      .def_readwrite("decay_time_s", &VoxelMapConfig::decay_time_s,
                     "Time constant of the decay toward unknown, s: evidence is multiplied by "
                     "exp(-dt / tau) for the time dt since the voxel's last update. 0 = no decay "
                     "(costmap_2d has none). Default 0.")
      .def_readwrite("max_memory_mib", &VoxelMapConfig::max_memory_mib,
                     "Memory bound for the voxel blocks, MiB. Updates that would need a block "
                     "beyond it are dropped and counted. Default 64.")
      .def("validate", &VoxelMapConfig::validate, "Empty string if valid, else the reason.");

  py::class_<VoxelRayConfig>(m, "VoxelRayConfig", "How far a source's rays mark and clear.")
      .def(py::init<>())
      .def_readwrite("obstacle_max_range_m", &VoxelRayConfig::obstacle_max_range_m,
                     "returns farther than this do not mark (3-D distance)")
      .def_readwrite("raytrace_max_range_m", &VoxelRayConfig::raytrace_max_range_m,
                     "rays clear at most this far, m")
      .def_readwrite("no_return_range_m", &VoxelRayConfig::no_return_range_m,
                     "a no-return ray clears this far, m")
      .def_readwrite("marking", &VoxelRayConfig::marking, "returns mark their voxel")
      .def_readwrite("clearing", &VoxelRayConfig::clearing, "rays clear the voxels they cross")
      .def_readwrite("one_ray_per_end_voxel", &VoxelRayConfig::one_ray_per_end_voxel,
                     "Of the rays of a frame that end in the same voxel, cast only the first "
                     "(every return still marks). Each cast ray is still walked exactly; a voxel "
                     "crossed only by a skipped ray (beside the cast one, near the end, where rays "
                     "to one voxel diverge by less than a voxel) is not cleared in that frame. "
                     "Trades that for far fewer rays: a 640x480 depth image has ~40 pixels per 5 "
                     "cm voxel at 4 m. Default false (every ray exact, costmap_2d's behaviour).")
      .def("validate", &VoxelRayConfig::validate, "Empty string if valid, else the reason.");

  py::class_<VoxelMap>(m, "VoxelMap", "Sparse 3-D log-odds voxels over a rolling window.")
      .def(py::init<const VoxelMapConfig&, double, double, int, int>(), py::arg("config"),
           py::arg("anchor_x_m"), py::arg("anchor_y_m"), py::arg("nx"), py::arg("ny"),
           "Raises ValueError for an invalid config, anchor or window size.")
      .def_property_readonly("config", &VoxelMap::config, "the configuration in use")
      .def_property_readonly(
          "shape", [](const VoxelMap& s) { return py::make_tuple(s.nx(), s.ny(), s.nz()); },
          "(nx, ny, nz) voxels of the window")
      .def_property_readonly(
          "window_offset",
          [](const VoxelMap& s) { return py::make_tuple(s.windowX0(), s.windowY0()); },
          "(x, y) index of the window's first column on the map's lattice")
      .def_property_readonly(
          "window_origin",
          [](const VoxelMap& s) { return py::make_tuple(s.windowOriginX(), s.windowOriginY()); },
          "(x, y) of the window's lower-left corner, m")
      .def_property_readonly(
          "band", [](const VoxelMap& s) { return py::make_tuple(s.bandFirst(), s.bandLast()); },
          "(first, last) voxel layers inside the height band")
      .def_property_readonly("blocks", &VoxelMap::blocks, "allocated 8^3-voxel blocks")
      .def_property_readonly("max_blocks", &VoxelMap::maxBlocks, "blocks allowed by max_memory_mib")
      .def_property_readonly("memory_bytes", &VoxelMap::memoryBytes,
                             "bytes held by blocks and the block table")
      .def("set_window", &VoxelMap::setWindow, py::arg("x0"), py::arg("y0"), py::arg("nx"),
           py::arg("ny"),
           "Moves / resizes the window to nx x ny columns from column (x0, y0) (voxel indices); "
           "voxels inside both windows are kept, the others forgotten.")
      .def(
          "integrate",
          [](VoxelMap& self, const Eigen::Vector3d& origin, const PointRows& hits,
             const PointRows& no_returns, double stamp_s, const VoxelRayConfig& rays) {
            const std::vector<float> h = toFloats(hits);
            const std::vector<float> n = toFloats(no_returns);
            VoxelIntegrationStats s;
            {
              py::gil_scoped_release release;
              s = self.integrate(origin, h.data(), h.size() / 3, n.data(), n.size() / 3, stamp_s,
                                 rays);
            }
            return statsToDict(s);
          },
          py::arg("origin"), py::arg("hits"), py::arg("no_returns"), py::arg("stamp_s"),
          py::arg("rays"),
          "One frame: hits (N x 3, world, m) mark and clear; no_returns (M x 3) give directions "
          "that clear no_return_range_m. Returns the counts.")
      .def(
          "integrate_depth",
          [](VoxelMap& self, py::array_t<float, py::array::c_style | py::array::forcecast> depth,
             const PinholeCamera& camera, const Eigen::Matrix4d& T_world_camera, double stamp_s,
             const VoxelRayConfig& rays, bool zero_is_no_return, int stride,
             const std::string& clearing_mode) {
            const std::string why = camera.validate();
            if (!why.empty()) throw std::invalid_argument("camera: " + why);
            if (clearing_mode != "ray" && clearing_mode != "frustum") {
              throw std::invalid_argument("clearing_mode must be 'ray' or 'frustum', got '" +
                                          clearing_mode + "'");
            }
            if (depth.ndim() != 2 || depth.shape(0) != camera.height ||
                depth.shape(1) != camera.width) {
              throw std::invalid_argument("depth must be (height, width)");
            }
            const Eigen::Isometry3d pose = toIsometry(T_world_camera);
            VoxelIntegrationStats s;
            DepthRays r;
            {
              py::gil_scoped_release release;
              if (clearing_mode == "frustum") {
                s = self.integrateDepthFrustum(depth.data(), camera, pose, zero_is_no_return,
                                               stride, stamp_s, rays);
              } else {
                depthToRays(depth.data(), camera, pose, zero_is_no_return, stride, &r);
                s = self.integrate(pose.translation(), r.hits.data(), r.hits.size() / 3,
                                   r.no_returns.data(), r.no_returns.size() / 3, stamp_s, rays);
              }
            }
            py::dict d = statsToDict(s);
            d["invalid_pixels"] = r.invalid;
            return d;
          },
          py::arg("depth"), py::arg("camera"), py::arg("T_world_camera"), py::arg("stamp_s"),
          py::arg("rays"), py::arg("zero_is_no_return") = false, py::arg("stride") = 1,
          py::arg("clearing_mode") = "ray",
          "A depth image (metres, REP 118: +Inf = no return) as one frame. clearing_mode 'ray': "
          "every stride-th pixel's ray clears the voxels it crosses (exact 3-D traversal); "
          "'frustum': every voxel in view nearer than the depth of the pixel it projects to (by "
          "more than half its diagonal) gets a miss, the spatio-temporal voxel layer's way, and "
          "every stride-th pixel marks. invalid_pixels is counted in 'ray' mode only.")
      .def(
          "log_odds",
          [](const VoxelMap& self, int x, int y, int z, double now_s) {
            checkVoxel(self, x, y, z);
            return self.logOdds(x, y, z, now_s);
          },
          py::arg("x"), py::arg("y"), py::arg("z"), py::arg("now_s"),
          "Log-odds of voxel (x, y, z) at time now_s (s; after decay).")
      .def(
          "state",
          [](const VoxelMap& self, int x, int y, int z, double now_s) {
            checkVoxel(self, x, y, z);
            return static_cast<int>(self.state(x, y, z, now_s));
          },
          py::arg("x"), py::arg("y"), py::arg("z"), py::arg("now_s"),
          "-1 unknown, 0 free, 1 occupied.")
      .def(
          "column",
          [](const VoxelMap& self, int x, int y, double now_s) {
            checkVoxel(self, x, y, 0);
            const VoxelColumn c = self.column(x, y, now_s);
            return py::make_tuple(c.occupied, c.unknown, self.columnCost(c));
          },
          py::arg("x"), py::arg("y"), py::arg("now_s"),
          "(occupied, unknown, cost) of a column within the height band.")
      .def(
          "project",
          [](const VoxelMap& self, double now_s) {
            std::vector<std::uint8_t> costs;
            self.project(now_s, &costs);
            py::array_t<std::uint8_t> out(
                {static_cast<py::ssize_t>(self.ny()), static_cast<py::ssize_t>(self.nx())});
            std::copy(costs.begin(), costs.end(), out.mutable_data());
            return out;
          },
          py::arg("now_s"), "Column costs (ny, nx): 254 lethal, 0 free, 255 unknown.")
      .def(
          "occupied_centres",
          [](const VoxelMap& self, double now_s) {
            const auto c = self.occupiedCentres(now_s);
            py::array_t<float> out({static_cast<py::ssize_t>(c.size()), py::ssize_t{3}});
            auto a = out.mutable_unchecked<2>();
            for (py::ssize_t i = 0; i < static_cast<py::ssize_t>(c.size()); ++i) {
              for (int k = 0; k < 3; ++k) a(i, k) = c[i](k);
            }
            return out;
          },
          py::arg("now_s"), "Centres (N x 3, m) of the occupied voxels.")
      .def("prune", &VoxelMap::prune, py::arg("now_s"),
           "Frees the blocks in which no voxel is known any more at now_s (decay); returns the "
           "blocks freed.")
      .def(
          "clear_columns",
          [](VoxelMap& self,
             const py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>& columns,
             double stamp_s) {
            if (columns.ndim() != 2 || (columns.shape(1) != 2 && columns.shape(0) != 0)) {
              throw std::invalid_argument("columns must be (N, 2) window column indices (x, y)");
            }
            std::vector<std::pair<int, int>> cols;
            const auto a = columns.unchecked<2>();
            constexpr std::int64_t kLimit = std::int64_t{1} << 30;
            for (py::ssize_t i = 0; i < columns.shape(0); ++i) {
              // Far outside any window (and any int): skipped, as clearColumns skips outsiders.
              const auto far = [](std::int64_t v) { return v < -kLimit || v > kLimit; };
              if (far(a(i, 0)) || far(a(i, 1))) continue;
              cols.emplace_back(static_cast<int>(a(i, 0)), static_cast<int>(a(i, 1)));
            }
            VoxelIntegrationStats s;
            {
              py::gil_scoped_release release;
              s = self.clearColumns(cols, stamp_s);
            }
            return statsToDict(s);
          },
          py::arg("columns"), py::arg("stamp_s"),
          "costmap_2d's footprint clearing in 3-D: every band voxel of the given window columns "
          "(N x 2: x, y) becomes free; columns outside the window are skipped. Returns the "
          "counts.")
      .def("clear", &VoxelMap::clear, "Forgets everything (all voxels unknown).");

  m.def(
      "voxel_ray",
      [](const Eigen::Vector3i& box, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
         bool include_end) {
        const double a[3] = {p0.x(), p0.y(), p0.z()};
        const double b[3] = {p1.x(), p1.y(), p1.z()};
        return voxelsToArray(voxelRay(VoxelBox{box.x(), box.y(), box.z()}, a, b, include_end));
      },
      py::arg("box"), py::arg("p0"), py::arg("p1"), py::arg("include_end") = true,
      "The voxels (N x 3) of the segment p0-p1 (voxel units) in the box [0, nx) x [0, ny) x "
      "[0, nz), in order, each once; empty when it misses the box or is not finite.");
}
