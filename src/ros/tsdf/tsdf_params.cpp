#include "downstream_perception/ros/tsdf/tsdf_params.h"

namespace downstream_perception {

std::string setNamedTsdfSettings(const std::string& weighting, int max_blocks, TsdfConfig* c) {
  if (max_blocks < 1) return "max_blocks must be >= 1, got " + std::to_string(max_blocks);
  if (weighting != "constant" && weighting != "inverse_square_depth") {
    return "weighting must be 'constant' or 'inverse_square_depth', got '" + weighting + "'";
  }
  c->max_blocks = static_cast<std::size_t>(max_blocks);
  c->weighting = weighting == "constant" ? TsdfConfig::Weighting::kConstant
                                         : TsdfConfig::Weighting::kInverseSquareDepth;
  return {};
}

TsdfConfig loadTsdfConfig(const ros::NodeHandle& pnh, ConfigErrorLog* errors) {
  TsdfConfig c;
  pnh.param("voxel_size_m", c.voxel_size_m, c.voxel_size_m);
  pnh.param("truncation_voxels", c.truncation_voxels, c.truncation_voxels);
  pnh.param("max_weight", c.max_weight, c.max_weight);
  pnh.param("behind_surface_dropoff", c.behind_surface_dropoff, c.behind_surface_dropoff);
  pnh.param("interpolate_depth", c.interpolate_depth, c.interpolate_depth);
  pnh.param("carve_free_space", c.carve_free_space, c.carve_free_space);
  pnh.param("no_return_carve_min_valid_fraction", c.no_return_carve_min_valid_fraction,
            c.no_return_carve_min_valid_fraction);
  pnh.param("edge_guard_rad", c.edge_guard_rad, c.edge_guard_rad);
  pnh.param("min_depth_m", c.min_depth_m, c.min_depth_m);
  pnh.param("max_depth_m", c.max_depth_m, c.max_depth_m);
  pnh.param("min_weight", c.min_weight, c.min_weight);
  pnh.param("max_block_distance_m", c.max_block_distance_m, c.max_block_distance_m);
  int max_blocks = static_cast<int>(c.max_blocks);
  pnh.param("max_blocks", max_blocks, max_blocks);
  std::string weighting = "constant";
  pnh.param("weighting", weighting, weighting);

  std::string why = setNamedTsdfSettings(weighting, max_blocks, &c);
  if (why.empty()) why = c.validate();
  if (why.empty()) return c;
  errors->add("invalid TSDF parameters (" + why + "); using the defaults");
  return TsdfConfig{};
}

}  // namespace downstream_perception
