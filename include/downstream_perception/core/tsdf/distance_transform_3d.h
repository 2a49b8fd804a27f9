// Exact 3-D Euclidean distance transform of a dense box, bounded to a radius, separable on
// integer squared distances (the 3-D form of the inflation layer's boundedSquaredDistances):
// along z by running counts, then along y and x by a brute-force window over the 2 r + 1
// neighbours of each voxel (in 16 bits, rows at a time, so it vectorises) for radii r up to 127
// voxels (16-bit results) or 64 (32-bit results), beyond by the lower envelope of parabolas of
// Felzenszwalb & Huttenlocher ("Distance Transforms of Sampled Functions", 2012). Exact either
// way: every result is the squared distance to the nearest seed voxel (no wavefront
// approximation), in integers.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace downstream_perception {

/// "No seed within the radius" in a squared-distance result.
constexpr std::int32_t kEdtFarSquared = 0x3fffffff;

/// "No seed within the radius" in a 16-bit squared-distance result.
constexpr std::int16_t kEdtFarSquared16 = 0x7fff;
/// Largest radius (voxels) of 16-bit results: a squared distance plus a window's k^2 fits.
constexpr int kEdtMaxRadius16 = 127;

/// Buffers boundedSquaredDistances3d keeps between calls (no allocation once grown): about a
/// plane, and for 32-bit results the window computes 2 bytes per voxel of the largest box.
struct EdtScratch {
  std::vector<std::int32_t> run;
  std::vector<std::int16_t> narrow, narrow_plane, narrow_row;
  std::size_t bytes() const;
};

/// Squared distances (voxels^2) from every voxel of a dense box of `size` voxels (x fastest,
/// then y, then z) to the nearest voxel whose label equals `seed_label`; distances above
/// `max_distance_voxels` (or no seed) come out as kEdtFarSquared. `out` is resized to the box;
/// `scratch` may be kept between calls. A negative radius counts as 0.
void boundedSquaredDistances3d(const std::uint8_t* labels, const Eigen::Vector3i& size,
                               std::uint8_t seed_label, int max_distance_voxels,
                               std::vector<std::int32_t>* out, EdtScratch* scratch);

/// The same in 16 bits (kEdtFarSquared16 for none within the radius), half the memory and no
/// copy: for radii up to kEdtMaxRadius16 (else std::invalid_argument).
void boundedSquaredDistances3d(const std::uint8_t* labels, const Eigen::Vector3i& size,
                               std::uint8_t seed_label, int max_distance_voxels,
                               std::vector<std::int16_t>* out, EdtScratch* scratch);

}  // namespace downstream_perception
