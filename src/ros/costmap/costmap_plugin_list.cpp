#include "downstream_perception/ros/costmap/costmap_plugin_list.h"

#include "downstream_perception/ros/costmap/stvl_keys.h"

#include <ros/console.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <map>
#include <sstream>

namespace downstream_perception {

namespace {

const std::map<std::string, std::string>& costmap2dTypes() {
  // costmap_2d::VoxelLayer: the 3-D voxel layer (its keys, sources and column rule); the 2-D
  // FlatVoxelLayer stays loadable by its own name.
  static const std::map<std::string, std::string> types{
      {"costmap_2d::StaticLayer", "downstream_perception/StaticLayer"},
      {"costmap_2d::ObstacleLayer", "downstream_perception/LogOddsObstacleLayer"},
      {"costmap_2d::VoxelLayer", "downstream_perception/VoxelObstacleLayer"},
      {"costmap_2d::InflationLayer", "downstream_perception/InflationLayer"},
      // The spatio-temporal voxel layer's configurations: its keys are written under ours first
      // (stvl_keys.h, CostmapRos::loadPlugins), differences named.
      {kStvlType, "downstream_perception/VoxelObstacleLayer"},
  };
  return types;
}

constexpr const char kMoveBaseSpelling[] = "downstream_perception::";

void warn(std::vector<std::string>* warnings, const std::string& msg) {
  ROS_WARN("costmap: %s", msg.c_str());
  if (warnings) warnings->push_back(msg);
}

// costmap_2d's parameter move: copy `key` from `from` into `to` (overwriting), then optionally
// delete it from `from`. Returns whether the key existed.
bool moveKey(ros::NodeHandle& from, ros::NodeHandle& to, const std::string& key, bool erase) {
  XmlRpc::XmlRpcValue value;
  if (!from.getParam(key, value)) return false;
  to.setParam(key, value);
  if (erase) from.deleteParam(key);
  return true;
}

std::string listText(const std::vector<LayerSpec>& layers) {
  std::ostringstream text;
  for (std::size_t k = 0; k < layers.size(); ++k) {
    text << (k ? ", " : "") << layers[k].name << " (" << layers[k].type << ")";
  }
  return text.str();
}

std::vector<LayerSpec> generate(ros::NodeHandle& pnh, std::vector<std::string>* warnings) {
  bool static_map = false;
  std::string map_type;
  pnh.getParam("static_map", static_map);
  pnh.getParam("map_type", map_type);
  const bool voxel = map_type == "voxel";
  const std::vector<LayerSpec> layers = preHydroLayers(static_map, voxel);
  std::string sources;
  pnh.getParam("observation_sources", sources);
  for (const LayerSpec& layer : layers) {
    ros::NodeHandle layer_nh(pnh, layer.name);
    std::vector<std::string> keys = preHydroKeys(layer.name, voxel);
    if (layer.name == "obstacle_layer") {
      std::istringstream names(sources);
      std::string source;
      while (names >> source) keys.push_back(source);
      keys.push_back("observation_sources");
    }
    for (const std::string& key : keys) moveKey(pnh, layer_nh, key, key != "track_unknown_space");
  }
  XmlRpc::XmlRpcValue list;
  list.setSize(static_cast<int>(layers.size()));
  for (std::size_t k = 0; k < layers.size(); ++k) {
    list[static_cast<int>(k)]["name"] = layers[k].name;
    list[static_cast<int>(k)]["type"] = layers[k].type;
  }
  pnh.setParam("plugins", list);
  warn(warnings, "no ~plugins: generated costmap_2d's pre-Hydro list from static_map / map_type (" +
                     listText(layers) + ") and moved the layer keys into it");
  return layers;
}

}  // namespace

std::string ourLayerType(const std::string& type, std::string* note) {
  if (note) note->clear();
  const auto known = costmap2dTypes().find(type);
  if (known != costmap2dTypes().end()) {
    if (note) {
      *note = std::string(type == kStvlType ? "spatio_temporal_voxel_layer" : "costmap_2d") +
              " type '" + type + "' runs as " + known->second;
    }
    return known->second;
  }
  if (type.rfind(kMoveBaseSpelling, 0) == 0) {
    const std::string ours = "downstream_perception/" + type.substr(sizeof(kMoveBaseSpelling) - 1);
    if (note) {
      *note = "'" + type + "' is the move_base (costmap_2d::Layer) spelling; in this host it is " +
              ours;
    }
    return ours;
  }
  return type;
}

const std::vector<std::string>& keysCopiedIntoLayer(const std::string& type) {
  static const std::map<std::string, std::vector<std::string>> keys{
      {"costmap_2d::StaticLayer",
       {"map_topic", "unknown_cost_value", "lethal_cost_threshold", "track_unknown_space"}},
      {"costmap_2d::VoxelLayer",
       {"origin_z", "z_resolution", "z_voxels", "mark_threshold", "unknown_threshold",
        "publish_voxel_map"}},
      {"costmap_2d::ObstacleLayer",
       {"max_obstacle_height", "raytrace_range", "obstacle_range", "track_unknown_space"}},
      {"costmap_2d::InflationLayer", {"cost_scaling_factor", "inflation_radius"}},
  };
  static const std::vector<std::string> none;
  const auto found = keys.find(type);
  return found == keys.end() ? none : found->second;
}

std::vector<LayerSpec> preHydroLayers(bool static_map, bool voxel) {
  std::vector<LayerSpec> layers;
  if (static_map) layers.push_back({"static_layer", "costmap_2d::StaticLayer"});
  layers.push_back(
      {"obstacle_layer", voxel ? "costmap_2d::VoxelLayer" : "costmap_2d::ObstacleLayer"});
  layers.push_back({"inflation_layer", "costmap_2d::InflationLayer"});
  return layers;
}

std::vector<std::string> preHydroKeys(const std::string& layer_name, bool voxel) {
  if (layer_name == "static_layer") {
    return {"map_topic", "unknown_cost_value", "lethal_cost_threshold", "track_unknown_space"};
  }
  if (layer_name == "inflation_layer") return {"cost_scaling_factor", "inflation_radius"};
  if (layer_name != "obstacle_layer") return {};
  std::vector<std::string> keys;
  if (voxel) {
    keys = {"origin_z",       "z_resolution",      "z_voxels",
            "mark_threshold", "unknown_threshold", "publish_voxel_map"};
  }
  for (const char* key :
       {"max_obstacle_height", "raytrace_range", "obstacle_range", "track_unknown_space"}) {
    keys.push_back(key);
  }
  return keys;
}

std::vector<LayerSpec> readLayerList(ros::NodeHandle& pnh, std::vector<std::string>* errors,
                                     std::vector<std::string>* warnings) {
  std::vector<LayerSpec> layers;
  XmlRpc::XmlRpcValue plugins;
  if (!pnh.getParam("plugins", plugins)) {
    layers = generate(pnh, warnings);
  } else {
    for (const char* key : {"static_map", "map_type"}) {
      if (pnh.hasParam(key)) {
        warn(warnings, std::string("pre-Hydro parameter ~") + key +
                           " is unused because ~plugins is given (as in costmap_2d)");
      }
    }
    if (plugins.getType() != XmlRpc::XmlRpcValue::TypeArray) {
      const std::string msg = "~plugins must be a list of {name, type}";
      ROS_ERROR("costmap: %s", msg.c_str());
      errors->push_back(msg);
      return layers;
    }
    for (int k = 0; k < plugins.size(); ++k) {
      XmlRpc::XmlRpcValue& entry = plugins[k];
      if (entry.getType() != XmlRpc::XmlRpcValue::TypeStruct || !entry.hasMember("name") ||
          !entry.hasMember("type") || entry["name"].getType() != XmlRpc::XmlRpcValue::TypeString ||
          entry["type"].getType() != XmlRpc::XmlRpcValue::TypeString) {
        const std::string msg =
            "~plugins[" + std::to_string(k) + "] needs string 'name' and 'type'";
        ROS_ERROR("costmap: %s", msg.c_str());
        errors->push_back(msg);
        continue;
      }
      layers.push_back(
          {static_cast<std::string>(entry["name"]), static_cast<std::string>(entry["type"])});
    }
  }
  for (const LayerSpec& layer : layers) {
    ros::NodeHandle layer_nh(pnh, layer.name);
    for (const std::string& key : keysCopiedIntoLayer(layer.type)) {
      XmlRpc::XmlRpcValue host_value;
      XmlRpc::XmlRpcValue own_value;
      if (!pnh.getParam(key, host_value)) continue;
      if (layer_nh.getParam(key, own_value) && own_value.toXml() != host_value.toXml()) {
        warn(warnings, "~" + key + " of the costmap overrides ~" + layer.name + "/" + key +
                           " (costmap_2d copies it into every " + layer.type + ")");
      }
      moveKey(pnh, layer_nh, key, false);
    }
  }
  return layers;
}

}  // namespace downstream_perception
