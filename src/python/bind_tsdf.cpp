// Python bindings of the TSDF core: depth images and points in, field samples and meshes out.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "downstream_perception/core/grid/grid_geometry.h"
#include "downstream_perception/core/tsdf/marching_cubes.h"
#include "downstream_perception/core/tsdf/occupancy_octree.h"
#include "downstream_perception/core/tsdf/tsdf_health.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "downstream_perception/core/tsdf/tsdf_slice.h"
#include "tsdf_object.h"

namespace py = pybind11;
using namespace downstream_perception;  // NOLINT
using downstream_perception::python::Tsdf;

namespace {

Eigen::Isometry3d toIsometry(const Eigen::Matrix4d& m) {
  if (!m.allFinite() || (m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9) {
    throw std::invalid_argument("T_map_camera must be a finite 4 x 4 homogeneous transform");
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if ((r * r.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-6) {
    throw std::invalid_argument("T_map_camera's rotation is not orthonormal");
  }
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = r;
  t.translation() = m.topRightCorner<3, 1>();
  return t;
}

py::dict meshToDict(const TriangleMesh& mesh) {
  const auto nv = static_cast<py::ssize_t>(mesh.vertices.size());
  const auto nt = static_cast<py::ssize_t>(mesh.triangleCount());
  py::array_t<float> vertices({nv, py::ssize_t{3}}), normals({nv, py::ssize_t{3}});
  py::array_t<std::uint32_t> triangles({nt, py::ssize_t{3}});
  auto v = vertices.mutable_unchecked<2>();
  auto n = normals.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) {
      v(i, k) = mesh.vertices[i](k);
      n(i, k) = mesh.normals[i](k);
    }
  }
  std::copy(mesh.triangles.begin(), mesh.triangles.end(), triangles.mutable_data());
  py::dict out;
  out["vertices"] = vertices;
  out["normals"] = normals;
  out["triangles"] = triangles;
  return out;
}

}  // namespace

using PointsRows = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

std::vector<Eigen::Vector3d> toPoints(const PointsRows& rows) {
  std::vector<Eigen::Vector3d> out(rows.rows());
  for (Eigen::Index i = 0; i < rows.rows(); ++i) out[i] = rows.row(i).transpose();
  return out;
}

void bindOctree(py::module& m) {
  py::class_<OctreeConfig>(
      m, "OctreeConfig",
      "Parameters of the OctoMap occupancy octree (metres, probabilities, bytes).")
      .def(py::init<>())
      .def_readwrite("resolution_m", &OctreeConfig::resolution_m, "leaf size, m")
      .def_readwrite("prob_hit", &OctreeConfig::prob_hit, "log-odds +0.847 per hit")
      .def_readwrite("prob_miss", &OctreeConfig::prob_miss, "log-odds -0.405 per pass")
      .def_readwrite("max_range_m", &OctreeConfig::max_range_m, "rays are cut at this range, m")
      .def_readwrite("depth_stride_px", &OctreeConfig::depth_stride_px,
                     "depth images: every n-th pixel in each direction is a ray")
      .def_readwrite("max_distance_m", &OctreeConfig::max_distance_m,
                     "Memory bounds, the OctoMap's counterparts of the TSDF's (applied by "
                     "maintain()): leaves farther than this from the sensor are deleted (0 = "
                     "never; the TSDF node passes its max_block_distance_m); rays are also cut at "
                     "this range (what lies beyond would go at the next maintenance anyway).")
      .def_readwrite(
          "max_memory_bytes", &OctreeConfig::max_memory_bytes,
          "Cap on memoryBytes() (octomap's count: nodes and child arrays; the heap adds the "
          "allocator's overhead, about a third more). At the cap maintain() deletes the leaves "
          "farthest from the sensor until the tree is below 90 % of it (0 = no cap).")
      .def("validate", &OctreeConfig::validate,
           "Empty string if the configuration is valid, else the reason (what the constructors "
           "raise).");
  // Before the octree, whose insert_depth takes a camera (the signature names the Python type).
  py::class_<PinholeCamera>(m, "PinholeCamera",
                            "Pinhole intrinsics (pixels), ROS optical convention.")
      .def(py::init([](double fx, double fy, double cx, double cy, int width, int height) {
             PinholeCamera c{fx, fy, cx, cy, width, height};
             const std::string why = c.validate();
             if (!why.empty()) throw std::invalid_argument("camera: " + why);
             return c;
           }),
           py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"), py::arg("width"),
           py::arg("height"))
      .def_readonly("fx", &PinholeCamera::fx, "focal length along x, px")
      .def_readonly("fy", &PinholeCamera::fy, "focal length along y, px")
      .def_readonly("cx", &PinholeCamera::cx, "principal point x, px (pixel centres at integers)")
      .def_readonly("cy", &PinholeCamera::cy, "principal point y, px")
      .def_readonly("width", &PinholeCamera::width, "image width, px")
      .def_readonly("height", &PinholeCamera::height, "image height, px");
  py::class_<OccupancyOctree>(m, "OccupancyOctree",
                              "OctoMap occupancy (octomap::OcTree) from the same observations.")
      .def(py::init<const OctreeConfig&>(), py::arg_v("config", OctreeConfig{}, "OctreeConfig()"))
      .def(
          "insert_points",
          [](OccupancyOctree& self, const PointsRows& points, const Eigen::Vector3d& origin) {
            const auto p = toPoints(points);
            py::gil_scoped_release release;
            self.insertPoints(p, origin);
          },
          py::arg("points"), py::arg("origin"),
          "Inserts an (N, 3) point cloud (m) seen from `origin`: rays cleared, end points marked.")
      .def(
          "insert_depth",
          [](OccupancyOctree& self,
             py::array_t<float, py::array::c_style | py::array::forcecast> depth,
             const PinholeCamera& camera, const Eigen::Matrix4d& T_map_camera) {
            if (depth.ndim() != 2 || depth.shape(0) != camera.height ||
                depth.shape(1) != camera.width) {
              throw std::invalid_argument("depth must be (height, width)");
            }
            const Eigen::Isometry3d pose = toIsometry(T_map_camera);
            py::gil_scoped_release release;
            self.insertDepth(depth.data(), camera, pose);
          },
          py::arg("depth"), py::arg("camera"), py::arg("T_map_camera"),
          "Inserts a depth image (m, (height, width)) seen by `camera` at the given pose.")
      .def(
          "log_odds",
          [](const OccupancyOctree& self, const PointsRows& points) {
            py::array_t<double> out(points.rows());
            for (Eigen::Index i = 0; i < points.rows(); ++i) {
              double l = std::nan("");
              self.logOdds(points.row(i).transpose(), &l);
              out.mutable_at(i) = l;
            }
            return out;
          },
          py::arg("points"), "Log-odds of the leaf at each point (NaN where never observed).")
      .def(
          "occupied",
          [](const OccupancyOctree& self) {
            const auto c = self.occupiedCenters();
            py::array_t<double> out({static_cast<py::ssize_t>(c.size()), py::ssize_t{3}});
            for (std::size_t i = 0; i < c.size(); ++i) {
              for (int k = 0; k < 3; ++k) out.mutable_at(i, k) = c[i](k);
            }
            return out;
          },
          "Centres (N, 3) of the occupied leaves.")
      .def(
          "write_binary",
          [](const OccupancyOctree& self, const std::string& path) {
            const std::string why = self.writeBinary(path);
            if (!why.empty()) throw std::runtime_error(why);
          },
          py::arg("path"),
          "Writes the octree as an OctoMap .bt file (refuses to overwrite unless asked).")
      .def(
          "evict_farther_than",
          [](OccupancyOctree& self, const Eigen::Vector3d& center, double distance_m) {
            py::gil_scoped_release release;
            return self.evictFartherThan(center, distance_m);
          },
          py::arg("center"), py::arg("distance_m"),
          "Deletes the leaves whose centre is farther than distance_m from center; returns the "
          "number of nodes deleted.")
      .def(
          "maintain",
          [](OccupancyOctree& self, const Eigen::Vector3d& sensor_origin) {
            OctreeMaintenance m;
            {
              py::gil_scoped_release release;
              m = self.maintain(sensor_origin);
            }
            py::dict out;
            out["nodes_evicted_by_distance"] = m.nodes_evicted_by_distance;
            out["nodes_evicted_at_cap"] = m.nodes_evicted_at_cap;
            out["leaves"] = m.leaves;
            out["memory_bytes"] = m.memory_bytes;
            return out;
          },
          py::arg("sensor_origin"),
          "Applies the config's max_distance_m and max_memory_bytes around the sensor and prunes; "
          "returns what it deleted and the size after.")
      .def_property_readonly("node_count", &OccupancyOctree::nodeCount, "nodes in the tree")
      .def_property_readonly("leaf_count", &OccupancyOctree::leafCount, "leaves in the tree")
      .def_property_readonly(
          "memory_bytes", &OccupancyOctree::memoryBytes,
          "bytes (octomap's count for the OctoMap; the blocks' chunks for the TSDF)")
      .def("clear", &OccupancyOctree::clear, "Forgets every node.");
}

void bindTsdf(py::module& m) {
  bindOctree(m);
  py::enum_<TsdfConfig::Weighting>(m, "TsdfWeighting")
      .value("CONSTANT", TsdfConfig::Weighting::kConstant)
      .value("INVERSE_SQUARE_DEPTH", TsdfConfig::Weighting::kInverseSquareDepth);
  py::enum_<TsdfConfig::EdgeGuardRule>(m, "TsdfEdgeGuardRule")
      .value("RIM_DISTANCE", TsdfConfig::EdgeGuardRule::kRimDistance)
      .value("FIXED_RADIUS", TsdfConfig::EdgeGuardRule::kFixedRadius);
  py::class_<TsdfConfig>(m, "TsdfConfig",
                         "Parameters of the sparse TSDF (voxel size and truncation in metres, "
                         "weights, memory bounds).")
      .def(py::init<>())
      .def_readwrite("voxel_size_m", &TsdfConfig::voxel_size_m,
                     "voxel edge, m; fixed for the map's life")
      .def_readwrite(
          "truncation_voxels", &TsdfConfig::truncation_voxels,
          "Truncation distance mu in voxels (mu = truncation_voxels * voxel_size_m); 3-5 is usual.")
      .def_readwrite(
          "max_weight", &TsdfConfig::max_weight,
          "Cap on the fused weight, so the map keeps following a changing scene (0 = no cap).")
      .def_readwrite("weighting", &TsdfConfig::weighting, "weight of one observation")
      .def_readwrite("behind_surface_dropoff", &TsdfConfig::behind_surface_dropoff,
                     "Behind the surface (sdf < -voxel_size_m) the weight falls linearly to 0 at "
                     "-mu, so a surface seen from one side does not write a deep negative shell "
                     "that ghosts when seen from the other side (voxblox's weight drop-off). "
                     "Off by default: under pose noise it loses surface.")
      .def_readwrite("behind_surface_dropoff_start_voxels",
                     &TsdfConfig::behind_surface_dropoff_start_voxels,
                     "With behind_surface_dropoff, the weight stays 1 up to this many voxels "
                     "behind the surface, then falls linearly to 0 at -mu (1 = voxblox's ramp; "
                     ">= truncation_voxels = no ramp).")
      .def_readwrite("incidence_window_radius_px", &TsdfConfig::incidence_window_radius_px,
                     "Depth images: incidences (rim rule, grazing reach, confirm depth) from the "
                     "plane of the (2 r + 1)^2 pixels around each pixel where they all continue "
                     "one surface (then radius r / 2, then 1), robust to depth noise; 0 = the "
                     "nearest neighbours only.")
      .def_readwrite("confirm_depth_voxels", &TsdfConfig::confirm_depth_voxels,
                     "Depth images: a voxel only ever seen deeper than this many voxels behind a "
                     "surface (along its normal) is unconfirmed: it fuses and the ESDF, slice "
                     "and sample() read it, but the mesh leaves it out until a frame sees it "
                     "nearer a surface or in front of one (a thin slab's unseen underside). "
                     "0 = off.")
      .def_readwrite("confirm_depth_max_m", &TsdfConfig::confirm_depth_max_m,
                     "Caps the confirm depth (m along the normal; 0 = no cap), never below 1.25 "
                     "voxels: a slab thinner than a few coarse voxels grows no far side.")
      .def("confirm_depth", &TsdfConfig::confirmDepth,
           "The confirm depth in effect (m along the normal): confirm_depth_voxels voxels, at "
           "most confirm_depth_max_m unless that is under 1.25 voxels.")
      .def_readwrite("unconfirmed_update_weight", &TsdfConfig::unconfirmed_update_weight,
                     "Depth images: an update deeper than the confirm depth behind its surface "
                     "(it does not confirm its voxel) fuses with its weight times this, so frames "
                     "that see the voxel free outweigh it (no skirt under a thin slab seen from "
                     "above). In (0, 1]; 1 = equal weights.")
      .def_readwrite("far_free_guess_weight", &TsdfConfig::far_free_guess_weight,
                     "Depth images: an update deeper than the confirm depth on a voxel that reads "
                     "free and that some frame saw more than mu in front of its surface fuses "
                     "with its weight times this, and a far-free update of an unconfirmed voxel "
                     "with its weight over this: free space seen beats a guess, in either order. "
                     "In (0, 1]; 1 = off.")
      .def_readwrite("edge_guard_rule", &TsdfConfig::edge_guard_rule,
                     "Depth images: how deep behind the surface pixels next to a depth edge (an "
                     "object's rim) write inside values (rays grazing a rim would otherwise "
                     "write them into the free space beyond it: ghosts). RIM_DISTANCE: from each "
                     "pixel's distance to the nearest rim and its incidence angle; FIXED_RADIUS: "
                     "a voxel within edge_guard_rad of a rim (the rule before issue 22).")
      .def_readwrite("edge_guard_rad", &TsdfConfig::edge_guard_rad,
                     "0 disables the edge guard. FIXED_RADIUS: pixels within this angle (rad) of "
                     "a depth edge are guarded; RIM_DISTANCE: pixels without an incidence "
                     "estimate within it update a voxel deep. 0.0075 rad is 2 pixels at f = 262.")
      .def_readwrite("edge_guard_near_side_only", &TsdfConfig::edge_guard_near_side_only,
                     "Edge guard: only the nearer side of a depth edge (the object's rim) is a "
                     "rim (FIXED_RADIUS: guarded pixels at most mu farther than it); false: "
                     "both sides.")
      .def_readwrite("edge_guard_rim_scale", &TsdfConfig::edge_guard_rim_scale,
                     "RIM_DISTANCE: scales the depth a pixel's distance from the rim allows "
                     "(larger: more surface next to rims, more ghosts).")
      .def_readwrite("edge_guard_grazing_voxels", &TsdfConfig::edge_guard_grazing_voxels,
                     "FIXED_RADIUS only: a guarded pixel beside the rim (not the rim pixel "
                     "itself) still updates voxels up to voxel_size_m / cos(incidence) behind "
                     "its surface, at most this many voxels; 1 = a voxel at any incidence.")
      .def_readwrite("grazing_reach_voxels", &TsdfConfig::grazing_reach_voxels,
                     "Depth images: every pixel writes inside values down to this many voxels "
                     "below its surface (that / cos(incidence) along the ray), beyond mu if need "
                     "be, at most grazing_reach_max_voxels along the ray; 0 = off.")
      .def_readwrite("grazing_reach_max_voxels", &TsdfConfig::grazing_reach_max_voxels,
                     "Cap (voxels along the ray) of the grazing reach; below truncation_voxels "
                     "it acts as truncation_voxels.")
      .def_readwrite(
          "interpolate_depth", &TsdfConfig::interpolate_depth,
          "Depth images: read each voxel's depth by interpolating inverse depth between the four "
          "nearest pixels (exact on planes) instead of taking the nearest pixel; falls back to the "
          "nearest pixel across depth edges (neighbours differing by more than one voxel).")
      .def_readwrite(
          "carve_free_space", &TsdfConfig::carve_free_space,
          "Update the voxels along the whole ray from the sensor, not only the truncation band: an "
          "object that moved away is erased where its free space is seen again (voxblox's voxel "
          "carving). Off by default: it allocates blocks for all the free space in view, so memory "
          "and time grow with the range. Carving stays inside the camera's view frustum up to "
          "max_depth_m (PinholeCamera::validate refuses intrinsics whose frustum is absurdly wide "
          "or off-axis).")
      .def_readwrite(
          "no_return_carve_min_valid_fraction", &TsdfConfig::no_return_carve_min_valid_fraction,
          "With carve_free_space, a +Inf pixel (\"no return within range\", REP 118) carves its "
          "ray up to max_depth_m only in a frame where at least this fraction of all pixels are "
          "valid depths: the returns are the evidence that the sensor works and the pose is right. "
          "In other frames its +Inf pixels are ignored like invalid ones (and counted): one frame "
          "without any return (a covered or failing sensor) would otherwise carve through every "
          "wall in view. 0 = +Inf always carves; 1 = only frames without any invalid or +Inf pixel "
          "(so +Inf never carves). Without carving, +Inf pixels only free voxels of blocks the "
          "frame's returns allocate.")
      .def_readwrite("min_depth_m", &TsdfConfig::min_depth_m, "closer depths are invalid")
      .def_readwrite("max_depth_m", &TsdfConfig::max_depth_m,
                     "farther depths are invalid (at most 1000 m)")
      .def_readwrite(
          "min_weight", &TsdfConfig::min_weight,
          "Voxels whose weight is below this are \"unobserved\" for meshing and queries.")
      .def_readwrite(
          "mesh_extrapolate_voxels", &TsdfConfig::mesh_extrapolate_voxels,
          "Marching cubes fills a missing voxel (unobserved, not unconfirmed) next to the surface "
          "by linear extrapolation along a lattice axis from the two observed voxels before it, "
          "the nearer within this many voxels of the surface (keeping its sign), so the mesh "
          "reaches a surface's edge where the voxel beyond was not written. Mesh only. 0 = off; "
          "above truncation_voxels it acts as truncation_voxels.")
      .def_readwrite(
          "max_blocks", &TsdfConfig::max_blocks,
          "Hard cap: new blocks beyond it are not allocated. Lowering it on a live map (setConfig) "
          "evicts blocks down to the new cap at once: the least recently updated first, among "
          "equally recent ones the farthest from the last sensor origin.")
      .def_readwrite("max_block_distance_m", &TsdfConfig::max_block_distance_m,
                     "Blocks whose centre is farther than this from the last sensor origin are "
                     "evicted after each integration (0 = never).")
      .def("truncation", &TsdfConfig::truncation, "mu in metres")
      .def("validate", &TsdfConfig::validate,
           "Empty string if the configuration is valid, else the reason (what the constructors "
           "raise).");
  py::class_<TsdfIntegrationStats>(m, "TsdfIntegrationStats",
                                   "What one TSDF integration did: pixels by kind, blocks touched, "
                                   "allocated, refused, evicted, voxels updated.")
      .def_readonly("pixels_valid", &TsdfIntegrationStats::pixels_valid, "depths (or points) used")
      .def_readonly("pixels_invalid", &TsdfIntegrationStats::pixels_invalid,
                    "NaN, 0, negative or outside [min_depth_m, max_depth_m]")
      .def_readonly("pixels_no_return", &TsdfIntegrationStats::pixels_no_return,
                    "+Inf (REP-118: nothing within range)")
      .def_readonly("pixels_no_return_ignored", &TsdfIntegrationStats::pixels_no_return_ignored,
                    "+Inf pixels ignored: carving, in a frame with too few valid depths "
                    "(no_return_carve_min_valid_fraction); also counted in pixels_no_return.")
      .def_property_readonly(
          "refused",
          [](const TsdfIntegrationStats& s) -> py::object {
            return s.refused == nullptr ? py::object(py::none()) : py::str(s.refused);
          },
          "Why the whole frame was refused (its pixels counted invalid), or None.")
      .def_readonly("blocks_touched", &TsdfIntegrationStats::blocks_touched,
                    "blocks the frame's truncation band (or rays) reached")
      .def_readonly("blocks_allocated", &TsdfIntegrationStats::blocks_allocated,
                    "of them new this frame")
      .def_readonly("blocks_refused", &TsdfIntegrationStats::blocks_refused,
                    "not allocated: max_blocks reached (>= 1 if so)")
      .def_readonly("blocks_evicted", &TsdfIntegrationStats::blocks_evicted,
                    "farther than max_block_distance_m")
      .def_readonly("voxels_updated", &TsdfIntegrationStats::voxels_updated,
                    "voxels fused this frame");

  py::class_<Tsdf>(m, "Tsdf",
                   "Sparse TSDF (8^3-voxel blocks) with an incremental marching-cubes mesher.")
      .def(py::init([](const TsdfConfig& c) { return std::make_unique<Tsdf>(c); }),
           py::arg_v("config", TsdfConfig{}, "TsdfConfig()"))
      .def_property_readonly(
          "config", [](const Tsdf& t) { return t.map.config(); }, "the configuration in use")
      .def(
          "set_config",
          [](Tsdf& self, const TsdfConfig& c) {
            const std::string why = self.map.setConfig(c);
            if (!why.empty()) throw std::invalid_argument(why);
          },
          py::arg("config"),
          "Replaces the settings that keep the voxel lattice (weights, depth limits, edge guard, "
          "memory bounds; a lower max_blocks evicts the least recently updated blocks at once); "
          "raises ValueError for an invalid config or another voxel_size_m or "
          "truncation_voxels.")
      .def(
          "integrate_depth",
          [](Tsdf& self, const py::array& depth, const PinholeCamera& camera,
             const Eigen::Matrix4d& T_map_camera) {
            if (depth.ndim() != 2 || depth.shape(0) != camera.height ||
                depth.shape(1) != camera.width) {
              throw std::invalid_argument("depth must be (height, width) = (" +
                                          std::to_string(camera.height) + ", " +
                                          std::to_string(camera.width) + ")");
            }
            const Eigen::Isometry3d pose = toIsometry(T_map_camera);
            // float32 C-contiguous arrays are read in place (ensure() returns a view); other
            // float layouts are converted, millimetres scaled.
            py::array_t<float, py::array::c_style | py::array::forcecast> metres;
            std::vector<float> scaled;
            const float* data = nullptr;
            if (py::isinstance<py::array_t<std::uint16_t>>(depth)) {
              const auto mm = py::array_t<std::uint16_t, py::array::c_style>::ensure(depth);
              scaled.resize(static_cast<std::size_t>(depth.size()));
              millimetresToMetres(mm.data(), scaled.size(), scaled.data());
              data = scaled.data();
            } else if (py::isinstance<py::array_t<float>>(depth) ||
                       py::isinstance<py::array_t<double>>(depth)) {
              metres = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(depth);
              data = metres.data();
            } else {
              throw std::invalid_argument("depth must be float (m) or uint16 (mm)");
            }
            py::gil_scoped_release release;
            return self.integrator.integrate(&self.map, data, camera, pose);
          },
          py::arg("depth"), py::arg("camera"), py::arg("T_map_camera"),
          "Fuses a depth image: float32 metres (NaN/0 invalid, +Inf no return) or uint16 "
          "millimetres (0 invalid), T_map_camera a 4 x 4 pose of the optical frame.")
      .def(
          "integrate_points",
          [](Tsdf& self, const PointsRows& points, const Eigen::Vector3d& origin) {
            const std::vector<Eigen::Vector3d> p = toPoints(points);
            py::gil_scoped_release release;
            return integratePoints(&self.map, p, origin);
          },
          py::arg("points"), py::arg("origin"),
          "Fuses points (N, 3) in the map frame seen from origin (3,).")
      .def(
          "sample",
          [](const Tsdf& self, const PointsRows& points) {
            const auto n = static_cast<py::ssize_t>(points.rows());
            py::array_t<double> distance(n), weight(n);
            const double mu = self.map.config().truncation();
            for (py::ssize_t i = 0; i < n; ++i) {
              // Far or NaN points have no voxel (NaN, weight 0), not a clamped index's.
              const TsdfVoxel* v = self.map.voxelNear(points.row(i).transpose());
              const bool known = v != nullptr && v->observedWeight() > self.map.config().min_weight;
              distance.mutable_at(i) = known ? v->distance * mu : std::nan("");
              weight.mutable_at(i) = v == nullptr ? 0.0 : v->observedWeight();
            }
            return py::make_tuple(distance, weight);
          },
          py::arg("points"),
          "Signed distance (m, NaN where unobserved) and weight of the voxel nearest each point.")
      .def(
          "update_mesh", [](Tsdf& self) { return self.mesher.update(self.map); },
          "Re-extracts the blocks changed since the last call (every block after a change of "
          "min_weight or mesh_extrapolate_voxels); returns how many.")
      .def(
          "mesh", [](const Tsdf& self) { return meshToDict(self.mesher.combined()); },
          "The mesh as of the last update_mesh(): dict of vertices (V, 3) float32 m, normals "
          "(V, 3), triangles (T, 3) uint32.")
      .def(
          "write_ply",
          [](const Tsdf& self, const std::string& path) {
            const std::string why = self.mesher.combined().writePly(path);
            if (!why.empty()) throw std::runtime_error(why);
          },
          py::arg("path"), "Writes the welded mesh as a PLY file.")
      .def(
          "slice",
          [](const Tsdf& self, const GridGeometry& grid, double min_z_m, double max_z_m,
             double occupied_distance_m) {
            TsdfSliceConfig c;
            c.min_z_m = min_z_m;
            c.max_z_m = max_z_m;
            c.occupied_distance_m = occupied_distance_m;
            const std::vector<SliceCell> cells = sliceTsdf(self.map, grid, c);
            py::array_t<std::int8_t> out(
                {static_cast<py::ssize_t>(grid.sizeY()), static_cast<py::ssize_t>(grid.sizeX())});
            std::transform(cells.begin(), cells.end(), out.mutable_data(),
                           [](SliceCell v) { return static_cast<std::int8_t>(v); });
            return out;
          },
          py::arg("grid"), py::arg("min_z_m") = 0.05, py::arg("max_z_m") = 1.8,
          py::arg("occupied_distance_m") = -1.0,
          "2-D slice over grid ([y, x] int8: 1 occupied, 0 free, -1 unknown): a cell is occupied "
          "when a voxel in the height band (m) over it is within occupied_distance_m of a "
          "surface or inside (default one voxel).")
      .def(
          "slice_window",
          [](const Tsdf& self, double centre_x_m, double centre_y_m, double side_m,
             std::int64_t max_cells) {
            SliceWindow w;
            w.centre_x_m = centre_x_m;
            w.centre_y_m = centre_y_m;
            w.side_m = side_m;
            // A negative count would wrap to a huge size_t: refuse it as validate() refuses 0.
            w.max_cells = static_cast<std::size_t>(std::max<std::int64_t>(0, max_cells));
            bool capped = false;
            const GridGeometry grid =
                sliceWindowGeometry(blockColumns(self.map), self.map.voxelSize(), w, &capped);
            return py::make_tuple(grid, capped);
          },
          py::arg("centre_x_m"), py::arg("centre_y_m"), py::arg("side_m") = 0.0,
          py::arg("max_cells") = SliceWindow::kDefaultMaxCells,
          "The nodelet's slice grid (~slice_window_m, ~slice_max_cells): (GridGeometry, capped). "
          "A square of round(side_m / voxel) voxel columns whose middle column (n // 2) holds "
          "the centre (m), cut to the blocks' x-y extent; side_m 0: the whole extent. Larger "
          "than max_cells: cut to the floor(sqrt(max_cells)) square around the centre, capped "
          "True. An empty (0 x 0) grid when it misses every block. For Tsdf.slice and "
          "Tsdf.esdf_band_slice(grid=...). Raises ValueError on a side outside [0, 1e5] m, "
          "max_cells outside [1, 2^28] or a centre that is not finite.")
      .def(
          "health",
          [](const Tsdf& self) {
            const TsdfHealth h = tsdfHealth(self.map);
            py::dict out;
            out["crossings"] = h.crossings;
            out["mean_gradient_ratio"] = h.mean_gradient_ratio;
            out["low_gradient_fraction"] = h.low_gradient_fraction;
            out["double_crossings"] = h.double_crossings;
            return out;
          },
          "The lesson's health check: at zero crossings |grad (D mu)| (1 = clean), the share "
          "below 0.5, and double crossings within mu (pose drift's fingerprint).")
      .def_property_readonly(
          "block_count", [](const Tsdf& t) { return t.map.blockCount(); },
          "allocated 8^3-voxel blocks")
      .def_property_readonly(
          "memory_bytes", [](const Tsdf& t) { return t.map.memoryBytes(); },
          "bytes (octomap's count for the OctoMap; the blocks' chunks for the TSDF)")
      .def_property_readonly(
          "blocks_evicted_to_cap", [](const Tsdf& t) { return t.map.blocksEvictedToCap(); },
          "Blocks evicted because set_config lowered max_blocks below the block count (total).")
      .def(
          "clear",
          [](Tsdf& self) {
            self.map.clear();
            self.mesher.clear();
          },
          "Forgets every block, the mesh and the ESDF.");

  m.def(
      "slice_distance",
      [](py::array_t<std::int8_t, py::array::c_style | py::array::forcecast> slice,
         double resolution, double max_distance_m) {
        if (slice.ndim() != 2) {
          throw std::invalid_argument("slice_distance: slice must be 2-D [y, x], got " +
                                      std::to_string(slice.ndim()) + "-D");
        }
        const GridGeometry grid(static_cast<int>(slice.shape(1)), static_cast<int>(slice.shape(0)),
                                resolution, 0.0, 0.0);
        std::vector<SliceCell> cells(static_cast<std::size_t>(slice.size()));
        std::transform(slice.data(), slice.data() + slice.size(), cells.begin(), [](std::int8_t v) {
          return v > 0 ? SliceCell::kOccupied : (v == 0 ? SliceCell::kFree : SliceCell::kUnknown);
        });
        const std::vector<float> distance = sliceDistance(cells, grid, max_distance_m);
        py::array_t<float> out({slice.shape(0), slice.shape(1)});
        std::copy(distance.begin(), distance.end(), out.mutable_data());
        return out;
      },
      py::arg("slice"), py::arg("resolution"), py::arg("max_distance_m") = 2.0,
      "Euclidean distance (m, float32 [y, x]) from each cell of a slice ([y, x]: > 0 occupied, "
      "0 free, < 0 unknown; Tsdf.slice's output or an OccupancyGrid's data) to the nearest "
      "occupied cell, capped at max_distance_m; NaN on unknown cells.");
}
