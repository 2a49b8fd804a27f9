// The costmap host's reading of costmap_2d's layer list, without a ROS master: type names, the
// pre-Hydro list costmap_2d generates, and the keys it moves and copies.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "downstream_perception/ros/costmap/costmap_plugin_list.h"

using namespace downstream_perception;  // NOLINT

namespace {
bool contains(const std::vector<std::string>& keys, const std::string& key) {
  return std::find(keys.begin(), keys.end(), key) != keys.end();
}
}  // namespace

TEST(OurLayerType, Costmap2dNamesMapToOurLayersAndSayHow) {
  std::string note;
  EXPECT_EQ(ourLayerType("costmap_2d::StaticLayer", &note), "downstream_perception/StaticLayer");
  EXPECT_NE(note.find("costmap_2d type 'costmap_2d::StaticLayer'"), std::string::npos) << note;
  EXPECT_EQ(ourLayerType("costmap_2d::ObstacleLayer"),
            "downstream_perception/LogOddsObstacleLayer");
  EXPECT_EQ(ourLayerType("costmap_2d::VoxelLayer"), "downstream_perception/VoxelObstacleLayer");
  EXPECT_EQ(ourLayerType("costmap_2d::InflationLayer"), "downstream_perception/InflationLayer");
}

TEST(OurLayerType, TheMoveBaseSpellingOfOursAndOtherTypes) {
  std::string note;
  EXPECT_EQ(ourLayerType("downstream_perception::TsdfLayer", &note),
            "downstream_perception/TsdfLayer");
  EXPECT_NE(note.find("move_base"), std::string::npos) << note;
  EXPECT_EQ(ourLayerType("downstream_perception/TsdfLayer", &note),
            "downstream_perception/TsdfLayer");
  EXPECT_EQ(note, "");
  // The spatio-temporal voxel layer runs as our 3-D voxel layer (its keys adopted by the host).
  EXPECT_EQ(ourLayerType("spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer", &note),
            "downstream_perception/VoxelObstacleLayer");
  EXPECT_NE(note.find("spatio_temporal_voxel_layer type"), std::string::npos) << note;
  // Not ours and not one we map: passed through (pluginlib then names the failure).
  EXPECT_EQ(ourLayerType("costmap_2d::RangeSensorLayer"), "costmap_2d::RangeSensorLayer");
}

TEST(PreHydroLayers, TheListCostmap2dGenerates) {
  const auto plain = preHydroLayers(false, false);
  ASSERT_EQ(plain.size(), 2u);
  EXPECT_EQ(plain[0].name, "obstacle_layer");
  EXPECT_EQ(plain[0].type, "costmap_2d::ObstacleLayer");
  EXPECT_EQ(plain[1].name, "inflation_layer");
  EXPECT_EQ(plain[1].type, "costmap_2d::InflationLayer");
  const auto full = preHydroLayers(true, true);
  ASSERT_EQ(full.size(), 3u);
  EXPECT_EQ(full[0].name, "static_layer");
  EXPECT_EQ(full[0].type, "costmap_2d::StaticLayer");
  EXPECT_EQ(full[1].type, "costmap_2d::VoxelLayer");
  EXPECT_EQ(full[2].type, "costmap_2d::InflationLayer");
}

TEST(PreHydroKeys, MovedIntoEachGeneratedLayer) {
  EXPECT_TRUE(contains(preHydroKeys("static_layer", false), "map_topic"));
  EXPECT_TRUE(contains(preHydroKeys("inflation_layer", false), "inflation_radius"));
  EXPECT_TRUE(contains(preHydroKeys("obstacle_layer", false), "obstacle_range"));
  EXPECT_FALSE(contains(preHydroKeys("obstacle_layer", false), "z_voxels"));
  EXPECT_TRUE(contains(preHydroKeys("obstacle_layer", true), "z_voxels"));
  EXPECT_TRUE(preHydroKeys("someone_else", true).empty());
}

TEST(KeysCopiedIntoLayer, OnlyForCostmap2dTypes) {
  EXPECT_TRUE(contains(keysCopiedIntoLayer("costmap_2d::InflationLayer"), "inflation_radius"));
  EXPECT_TRUE(contains(keysCopiedIntoLayer("costmap_2d::ObstacleLayer"), "track_unknown_space"));
  EXPECT_TRUE(contains(keysCopiedIntoLayer("costmap_2d::StaticLayer"), "lethal_cost_threshold"));
  EXPECT_TRUE(contains(keysCopiedIntoLayer("costmap_2d::VoxelLayer"), "origin_z"));
  // costmap_2d copies nothing into other types, ours included.
  EXPECT_TRUE(keysCopiedIntoLayer("downstream_perception/InflationLayer").empty());
  EXPECT_TRUE(keysCopiedIntoLayer("downstream_perception::InflationLayer").empty());
}
