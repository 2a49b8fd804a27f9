#include "downstream_perception/ros/tsdf/tsdf_params.h"

#include <cmath>
#include <cstddef>

#include <ros/console.h>

#include "downstream_perception/ros/common/param_reader.h"

namespace downstream_perception {

std::string setNamedTsdfSettings(const std::string& weighting, const std::string& edge_guard_rule,
                                 int max_blocks, TsdfConfig* c) {
  if (max_blocks < 1) return "max_blocks must be >= 1, got " + std::to_string(max_blocks);
  if (weighting != "constant" && weighting != "inverse_square_depth") {
    return "weighting must be 'constant' or 'inverse_square_depth', got '" + weighting + "'";
  }
  if (edge_guard_rule != "rim_distance" && edge_guard_rule != "fixed_radius") {
    return "edge_guard_rule must be 'rim_distance' or 'fixed_radius', got '" + edge_guard_rule +
           "'";
  }
  c->max_blocks = static_cast<std::size_t>(max_blocks);
  c->edge_guard_rule = edge_guard_rule == "rim_distance" ? TsdfConfig::EdgeGuardRule::kRimDistance
                                                         : TsdfConfig::EdgeGuardRule::kFixedRadius;
  c->weighting = weighting == "constant" ? TsdfConfig::Weighting::kConstant
                                         : TsdfConfig::Weighting::kInverseSquareDepth;
  return {};
}

TsdfConfig loadTsdfConfig(const ros::NodeHandle& pnh, ConfigErrorLog* errors) {
  TsdfConfig c;
  readParam(pnh, "voxel_size_m", &c.voxel_size_m, errors);
  readParam(pnh, "truncation_voxels", &c.truncation_voxels, errors);
  readParam(pnh, "max_weight", &c.max_weight, errors);
  readParam(pnh, "behind_surface_dropoff", &c.behind_surface_dropoff, errors);
  readParam(pnh, "behind_surface_dropoff_start_voxels", &c.behind_surface_dropoff_start_voxels,
            errors);
  readParam(pnh, "confirm_depth_voxels", &c.confirm_depth_voxels, errors);
  readParam(pnh, "confirm_depth_max_m", &c.confirm_depth_max_m, errors);
  readParam(pnh, "unconfirmed_update_weight", &c.unconfirmed_update_weight, errors);
  readParam(pnh, "far_free_guess_weight", &c.far_free_guess_weight, errors);
  readParam(pnh, "incidence_window_radius_px", &c.incidence_window_radius_px, errors);
  readParam(pnh, "interpolate_depth", &c.interpolate_depth, errors);
  readParam(pnh, "carve_free_space", &c.carve_free_space, errors);
  readParam(pnh, "no_return_carve_min_valid_fraction", &c.no_return_carve_min_valid_fraction,
            errors);
  readParam(pnh, "edge_guard_rad", &c.edge_guard_rad, errors);
  readParam(pnh, "edge_guard_near_side_only", &c.edge_guard_near_side_only, errors);
  readParam(pnh, "edge_guard_grazing_voxels", &c.edge_guard_grazing_voxels, errors);
  readParam(pnh, "edge_guard_rim_scale", &c.edge_guard_rim_scale, errors);
  readParam(pnh, "grazing_reach_voxels", &c.grazing_reach_voxels, errors);
  readParam(pnh, "grazing_reach_max_voxels", &c.grazing_reach_max_voxels, errors);
  readParam(pnh, "min_depth_m", &c.min_depth_m, errors);
  readParam(pnh, "max_depth_m", &c.max_depth_m, errors);
  readParam(pnh, "min_weight", &c.min_weight, errors);
  readParam(pnh, "mesh_extrapolate_voxels", &c.mesh_extrapolate_voxels, errors);
  readParam(pnh, "max_block_distance_m", &c.max_block_distance_m, errors);
  int max_blocks = static_cast<int>(c.max_blocks);
  readParam(pnh, "max_blocks", &max_blocks, errors);
  std::string weighting = "constant";
  readParam(pnh, "weighting", &weighting, errors);
  std::string edge_guard_rule = "rim_distance";
  readParam(pnh, "edge_guard_rule", &edge_guard_rule, errors);

  std::string why = setNamedTsdfSettings(weighting, edge_guard_rule, max_blocks, &c);
  if (why.empty()) why = c.validate();
  if (why.empty()) {
    const std::string inert = c.inertSettings();
    if (!inert.empty()) ROS_WARN_STREAM(pnh.getNamespace() << ": " << inert);
    return c;
  }
  errors->add("invalid TSDF parameters (" + why + "); using the defaults");
  return TsdfConfig{};
}

namespace {

/// ~slice_window_m and ~slice_max_cells, each checked on its own (SliceWindow::validate's
/// limits): an invalid one is reported and its default kept, the other still applies.
SliceWindow readSliceWindow(const ros::NodeHandle& pnh, ConfigErrorLog* errors) {
  SliceWindow w;
  double side_m = w.side_m;
  readParam(pnh, "slice_window_m", &side_m, errors);
  if (!(std::isfinite(side_m) && side_m >= 0.0 && side_m <= SliceWindow::kMaxSideM)) {
    errors->add("parameter ~slice_window_m = " + toText(side_m) + " must be in [0, " +
                toText(SliceWindow::kMaxSideM) + "] m (0 = the whole map); using 0");
    side_m = 0.0;
  }
  w.side_m = side_m;
  // Read as a double: an int parameter overflows (or is refused by XmlRpc) long before a
  // typo like 4e10 could be reported.
  double max_cells = static_cast<double>(w.max_cells);
  readParam(pnh, "slice_max_cells", &max_cells, errors);
  if (!(max_cells >= 1.0 && max_cells <= static_cast<double>(GridGeometry::kMaxCells) &&
        max_cells == std::floor(max_cells))) {
    errors->add("parameter ~slice_max_cells = " + toText(max_cells) +
                " must be a whole number in [1, " + std::to_string(GridGeometry::kMaxCells) +
                "]; using " + std::to_string(SliceWindow::kDefaultMaxCells));
    max_cells = static_cast<double>(SliceWindow::kDefaultMaxCells);
  }
  w.max_cells = static_cast<std::size_t>(max_cells);
  return w;
}

}  // namespace

TsdfNodeSettings readTsdfNodeSettings(const ros::NodeHandle& pnh, ConfigErrorLog* errors) {
  TsdfNodeSettings s;
  readParam(pnh, "mesh_rate_hz", &s.mesh_rate_hz, errors);
  if (!(std::isfinite(s.mesh_rate_hz) && s.mesh_rate_hz > 0.0 && s.mesh_rate_hz <= 100.0)) {
    errors->add("parameter ~mesh_rate_hz = " + toText(s.mesh_rate_hz) +
                " must be in (0, 100] Hz; using 1");
    s.mesh_rate_hz = 1.0;
  }
  readParam(pnh, "health_period_s", &s.health_period_s, errors);
  if (!(std::isfinite(s.health_period_s) && s.health_period_s >= 0.0)) {
    errors->add("parameter ~health_period_s must be >= 0 s (0 = off); using 10");
    s.health_period_s = 10.0;
  }
  readParam(pnh, "slice_min_z_m", &s.slice.min_z_m, errors);
  readParam(pnh, "slice_max_z_m", &s.slice.max_z_m, errors);
  const std::string slice_why = s.slice.validate();
  if (!slice_why.empty()) {
    errors->add("slice parameters invalid (" + slice_why + "); using 0.05 .. 1.8 m");
    s.slice = TsdfSliceConfig{};
  }
  readParam(pnh, "slice_distance_max_m", &s.slice_distance_max_m, errors);
  if (!(std::isfinite(s.slice_distance_max_m) && s.slice_distance_max_m >= 0.0 &&
        s.slice_distance_max_m <= 100.0)) {
    errors->add("parameter ~slice_distance_max_m = " + toText(s.slice_distance_max_m) +
                " must be in [0, 100] m (0 = off); using 2");
    s.slice_distance_max_m = 2.0;
  }
  s.slice_window = readSliceWindow(pnh, errors);
  readParam(pnh, "esdf_max_distance_m", &s.esdf_max_distance_m, errors);
  if (!(std::isfinite(s.esdf_max_distance_m) && s.esdf_max_distance_m >= 0.0)) {
    errors->add("parameter ~esdf_max_distance_m = " + toText(s.esdf_max_distance_m) +
                " must be finite and >= 0 m (0 = no ESDF); using 1");
    s.esdf_max_distance_m = 1.0;
  }
  readParam(pnh, "esdf_slice_z_m", &s.esdf_slice_z_m, errors);
  if (!std::isfinite(s.esdf_slice_z_m)) {
    errors->add("parameter ~esdf_slice_z_m must be finite; using 1");
    s.esdf_slice_z_m = 1.0;
  }
  readParam(pnh, "tf_queue_size", &s.tf_queue_size, errors);
  if (s.tf_queue_size < 1 || s.tf_queue_size > 1000) {
    errors->add("parameter ~tf_queue_size must be in [1, 1000]; using 10");
    s.tf_queue_size = 10;
  }
  return s;
}

OctomapSettings readOctomapSettings(const ros::NodeHandle& pnh, const TsdfConfig& map,
                                    ConfigErrorLog* errors) {
  OctomapSettings s;
  OctreeConfig& octree = s.octree;
  readParam(pnh, "octomap_resolution_m", &octree.resolution_m, errors);
  readParam(pnh, "octomap_depth_stride_px", &octree.depth_stride_px, errors);
  octree.max_range_m = map.max_depth_m;
  octree.max_distance_m = map.max_block_distance_m;  // the TSDF's bound
  double max_memory_mb = static_cast<double>(octree.max_memory_bytes) / (1 << 20);
  readParam(pnh, "octomap_max_memory_mb", &max_memory_mb, errors);
  if (!(std::isfinite(max_memory_mb) && max_memory_mb >= 1.0 && max_memory_mb <= 1e6)) {
    errors->add("parameter ~octomap_max_memory_mb = " + toText(max_memory_mb) +
                " must be in [1, 1e6] MiB; using 256");
    max_memory_mb = 256.0;
  }
  octree.max_memory_bytes = static_cast<std::size_t>(max_memory_mb * (1 << 20));
  readParam(pnh, "octomap_queue_size", &s.queue_size, errors);
  if (s.queue_size < 1 || s.queue_size > 100) {
    errors->add("parameter ~octomap_queue_size must be in [1, 100]; using 2");
    s.queue_size = 2;
  }
  if (s.enabled()) {
    const std::string why = octree.validate();
    if (!why.empty()) {
      errors->add("OctoMap parameters invalid (" + why + "); using the defaults");
      octree = OctreeConfig{};
      octree.max_distance_m = map.max_block_distance_m;
    }
  }
  return s;
}

}  // namespace downstream_perception
