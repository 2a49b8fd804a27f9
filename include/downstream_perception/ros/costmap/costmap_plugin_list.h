// The costmap host's layer list as costmap_2d reads it: costmap_2d's type names mapped to our
// layers, the list costmap_2d generates when ~plugins is absent (pre-Hydro static_map /
// map_type keys, moved into the generated layers' namespaces), and the host-level keys that
// costmap_2d copies into layers of its own types.
#pragma once

#include <ros/node_handle.h>

#include <string>
#include <vector>

namespace downstream_perception {

struct LayerSpec {
  std::string name;
  std::string type;
};

/// Our pluginlib name for `type`: costmap_2d::StaticLayer, ::ObstacleLayer, ::VoxelLayer and
/// ::InflationLayer map to our equivalents, the move_base spelling downstream_perception::X to
/// downstream_perception/X; anything else is returned unchanged. *note (if given) says what was
/// mapped and how, or stays empty.
std::string ourLayerType(const std::string& type, std::string* note = nullptr);

/// The host-level keys costmap_2d copies into a layer of costmap_2d type `type` (overwriting the
/// layer's own value) before it initialises it; empty for other types.
const std::vector<std::string>& keysCopiedIntoLayer(const std::string& type);

/// The plugin list costmap_2d builds without ~plugins: static_layer (if static_map), then
/// obstacle_layer (VoxelLayer if map_type is "voxel"), then inflation_layer.
std::vector<LayerSpec> preHydroLayers(bool static_map, bool voxel);

/// The keys costmap_2d moves from the host namespace into the generated layer `layer_name`
/// (observation_sources' own sub-namespaces are added by the caller).
std::vector<std::string> preHydroKeys(const std::string& layer_name, bool voxel);

/// For the host: reads ~plugins, or generates and stores it as costmap_2d does (moving the
/// pre-Hydro keys, WARN), or WARNs for static_map / map_type next to a ~plugins list. Then copies
/// the host-level keys into each costmap_2d-typed layer (WARN when that overrides a value the
/// layer set itself). Returns the list; malformed entries are reported into *errors and skipped.
std::vector<LayerSpec> readLayerList(ros::NodeHandle& pnh, std::vector<std::string>* errors,
                                     std::vector<std::string>* warnings);

}  // namespace downstream_perception
