// Cost values shared by every layer, identical to costmap_2d's cost_values.h so that
// grids, planners and rviz colour schemes built for costmap_2d read ours unchanged.
#pragma once

#include <array>
#include <cstdint>

namespace downstream_perception {
namespace cost {

constexpr std::uint8_t kFreeSpace = 0;
constexpr std::uint8_t kInscribedInflatedObstacle = 253;
constexpr std::uint8_t kLethalObstacle = 254;
constexpr std::uint8_t kNoInformation = 255;

/// costmap_2d's translation from a cost (0..255) to a nav_msgs/OccupancyGrid value (-1..100):
/// 0 -> 0, 1..252 -> 1 + 97 (c - 1) / 251, 253 -> 99, 254 -> 100, 255 -> -1.
constexpr std::int8_t toOccupancyValue(std::uint8_t c) {
  if (c == kFreeSpace) return 0;
  if (c == kInscribedInflatedObstacle) return 99;
  if (c == kLethalObstacle) return 100;
  if (c == kNoInformation) return -1;
  return static_cast<std::int8_t>(1 + (97 * (c - 1)) / 251);
}

/// The whole table, built once at compile time (publishing is a lookup per cell).
constexpr std::array<std::int8_t, 256> occupancyTable() {
  std::array<std::int8_t, 256> table{};
  for (int c = 0; c < 256; ++c) table[c] = toOccupancyValue(static_cast<std::uint8_t>(c));
  return table;
}

}  // namespace cost
}  // namespace downstream_perception
