#include "downstream_perception/ros/costmap/stvl_keys.h"

#include <ros/console.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace downstream_perception {

namespace {

// STVL's defaults (spatio_temporal_voxel_layer.cpp, onInitialize).
constexpr double kStvlVoxelDecayS = -1.0;  // < 0: voxels never decay
constexpr double kStvlVoxelSizeM = 0.05;
constexpr double kStvlMaxZ = 10.0;  // m, a clearing source's range
constexpr int kStvlDecayModelLinear = 0;
constexpr int kStvlDecayModelPersistent = -1;

void note(std::vector<std::string>* notes, const std::string& who, const std::string& msg) {
  ROS_WARN("%s: %s", who.c_str(), msg.c_str());
  notes->push_back(msg);
}

// Reads a key only when it is set (STVL's defaults stay in the caller's variables).
struct NodeParams {
  ros::NodeHandle& nh;
  template <class T>
  bool get(const std::string& key, T* value) const {
    return nh.hasParam(key) && nh.getParam(key, *value);
  }
};

}  // namespace

const std::vector<std::string>& stvlLayerKeys() {
  static const std::vector<std::string> keys = {"voxel_size",   "voxel_decay",
                                                "decay_model",  "update_footprint_enabled",
                                                "mapping_mode", "map_save_duration"};
  return keys;
}

const std::vector<std::string>& stvlSourceKeys() {
  static const std::vector<std::string> keys = {"min_z",
                                                "max_z",
                                                "model_type",
                                                "horizontal_fov_angle",
                                                "vertical_fov_angle",
                                                "vertical_fov_padding",
                                                "decay_acceleration",
                                                "clear_after_reading",
                                                "filter",
                                                "voxel_min_points"};
  return keys;
}

namespace {

void adoptSourceKeys(ros::NodeHandle& nh, const std::string& who, std::vector<std::string>* notes) {
  if (!nh.hasParam("data_type")) nh.setParam("data_type", "PointCloud2");  // STVL's default
  bool clearing = false;
  NodeParams{nh}.get("clearing", &clearing);
  double max_z = kStvlMaxZ;
  NodeParams{nh}.get("max_z", &max_z);
  if (clearing && !nh.hasParam("raytrace_range")) nh.setParam("raytrace_range", max_z);
  const bool frustum = nh.hasParam("model_type") || nh.hasParam("horizontal_fov_angle") ||
                       nh.hasParam("vertical_fov_angle") || nh.hasParam("vertical_fov_padding") ||
                       nh.hasParam("decay_acceleration") || nh.hasParam("min_z");
  if (clearing && frustum) {
    note(notes, who,
         "STVL's clearing frustum (model_type, fov angles, min_z, decay_acceleration) is not "
         "used: each point clears the voxels along its own ray in 3-D up to raytrace_range "
         "(max_z)");
  }
  std::string filter;
  int min_points = 0;
  NodeParams{nh}.get("voxel_min_points", &min_points);
  if (NodeParams{nh}.get("filter", &filter) && filter == "voxel") {
    note(notes, who,
         "STVL filter 'voxel' (voxel_min_points " + std::to_string(min_points) +
             ") is not applied: every point marks its voxel");
  }
  bool clear_after_reading = true;
  if (NodeParams{nh}.get("clear_after_reading", &clear_after_reading) && !clear_after_reading) {
    note(notes, who,
         "STVL clear_after_reading false: each observation is integrated once, as with true");
  }
}

}  // namespace

std::vector<std::string> adoptStvlKeys(ros::NodeHandle& nh, double costmap_resolution_m,
                                       const std::string& who) {
  // Tells the layer that STVL's keys are its own here (else they are unknown keys).
  nh.setParam("stvl_configuration", true);
  std::vector<std::string> notes;
  double voxel_size = kStvlVoxelSizeM;
  NodeParams{nh}.get("voxel_size", &voxel_size);
  if (!(std::isfinite(voxel_size) && voxel_size > 0.0)) {
    note(&notes, who,
         "STVL voxel_size " + std::to_string(voxel_size) +
             " m is not a positive size; z_resolution and z_voxels keep their own values");
  } else {
    if (!nh.hasParam("z_resolution")) nh.setParam("z_resolution", voxel_size);
    if (std::abs(voxel_size - costmap_resolution_m) > 1e-9) {
      std::ostringstream msg;
      msg << "STVL voxel_size " << voxel_size << " m: voxels here are the costmap's resolution "
          << costmap_resolution_m << " m in x and y, voxel_size in z";
      note(&notes, who, msg.str());
    }
    if (!nh.hasParam("z_voxels")) {
      // STVL's voxels have no column limit; ours reach max_obstacle_height from origin_z.
      double top = 2.0, origin = 0.0;
      NodeParams{nh}.get("max_obstacle_height", &top);
      NodeParams{nh}.get("origin_z", &origin);
      const double layers = std::ceil((top - origin) / voxel_size - 1e-9);
      nh.setParam("z_voxels", static_cast<int>(std::clamp(layers, 1.0, 1024.0)));
    }
  }
  double decay_s = kStvlVoxelDecayS;
  int model = kStvlDecayModelLinear;
  NodeParams{nh}.get("voxel_decay", &decay_s);
  NodeParams{nh}.get("decay_model", &model);
  if (!nh.hasParam("decay_time_s")) {
    const bool persistent = model == kStvlDecayModelPersistent || !(decay_s > 0.0);
    nh.setParam("decay_time_s", persistent ? 0.0 : decay_s);
    if (!persistent) {
      std::ostringstream msg;
      msg << "STVL decay_model " << model << " with voxel_decay " << decay_s
          << " s: decay here is exponential toward unknown with time constant decay_time_s = "
          << decay_s << " s (a voxel marked once stops being lethal after about 0.53 x that; "
          << "STVL's linear model drops it after voxel_decay)";
      note(&notes, who, msg.str());
    }
  }
  bool footprint = true;
  if (NodeParams{nh}.get("update_footprint_enabled", &footprint) &&
      !nh.hasParam("footprint_clearing_enabled")) {
    nh.setParam("footprint_clearing_enabled", footprint);
  }
  bool mapping = false;
  double save_period_s = 60.0;
  NodeParams{nh}.get("map_save_duration", &save_period_s);
  if (NodeParams{nh}.get("mapping_mode", &mapping) && mapping) {
    note(&notes, who,
         "STVL mapping_mode (saving the voxel grid every map_save_duration, " +
             std::to_string(save_period_s) +
             " s) is not supported; the layer runs as for navigation");
  }
  std::string sources;
  NodeParams{nh}.get("observation_sources", &sources);
  std::istringstream names(sources);
  std::string name;
  while (names >> name) {
    ros::NodeHandle source_nh(nh, name);
    adoptSourceKeys(source_nh, who + ", source '" + name + "'", &notes);
  }
  return notes;
}

}  // namespace downstream_perception
