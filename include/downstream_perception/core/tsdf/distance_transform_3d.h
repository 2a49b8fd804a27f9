// Exact 3-D Euclidean distance transform of a dense box, bounded to a radius: the separable
// lower-envelope transform of Felzenszwalb & Huttenlocher ("Distance Transforms of Sampled
// Functions", 2012) on integer squared distances, the 3-D form of the inflation layer's
// boundedSquaredDistances. Exact: every result is the squared distance to the nearest seed
// voxel (no wavefront approximation), in integers.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace downstream_perception {

/// "No seed within the radius" in a squared-distance result.
constexpr std::int32_t kEdtFarSquared = 0x3fffffff;

/// Squared distances (voxels^2) from every voxel of a dense box of `size` voxels (x fastest,
/// then y, then z) to the nearest voxel whose label equals `seed_label`; distances above
/// `max_distance_voxels` (or no seed) come out as kEdtFarSquared. `out` is resized to the box;
/// `scratch` is a buffer the caller may keep between calls (no allocation once grown).
void boundedSquaredDistances3d(const std::uint8_t* labels, const Eigen::Vector3i& size,
                               std::uint8_t seed_label, int max_distance_voxels,
                               std::vector<std::int32_t>* out, std::vector<std::int32_t>* scratch);

}  // namespace downstream_perception
