// Fusing depth images (projective) and point clouds (along each ray) into a TsdfMap.
#pragma once

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "downstream_perception/core/tsdf/tsdf_map.h"

namespace downstream_perception {

/// validate() bounds: the principal point lies at most this many image sizes outside the image
/// (cx in [-2 w, 3 w], cy in [-2 h, 3 h]), and every pixel ray at most atan(kMaxViewTangent)
/// (84 degrees) off the optical axis. Beyond them the view frustum, which carving fills with
/// blocks up to max_depth_m, grows without bound (cx = 1e7 px made one frame allocate 200,000
/// blocks).
constexpr double kMaxPrincipalPointOffset = 2.0;
constexpr double kMaxViewTangent = 10.0;

/// Pinhole intrinsics of a depth image in the ROS optical convention (z forward, x right,
/// y down; pixel (u, v) has its centre at integer coordinates, as in CameraInfo's K).
struct PinholeCamera {
  double fx = 0.0;  ///< focal length along x, px
  double fy = 0.0;  ///< focal length along y, px
  double cx = 0.0;  ///< principal point x, px (pixel centres at integers)
  double cy = 0.0;  ///< principal point y, px
  int width = 0;    ///< image width, px
  int height = 0;   ///< image height, px
  /// Empty if valid, else the reason.
  std::string validate() const;
};

struct TsdfIntegrationStats {
  std::size_t pixels_valid = 0;      ///< depths (or points) used
  std::size_t pixels_invalid = 0;    ///< NaN, 0, negative or outside [min_depth_m, max_depth_m]
  std::size_t pixels_no_return = 0;  ///< +Inf (REP-118: nothing within range)
  /// +Inf pixels ignored: carving, in a frame with too few valid depths
  /// (no_return_carve_min_valid_fraction); also counted in pixels_no_return.
  std::size_t pixels_no_return_ignored = 0;
  std::size_t blocks_touched = 0;    ///< blocks the frame's truncation band (or rays) reached
  std::size_t blocks_allocated = 0;  ///< of them new this frame
  std::size_t blocks_refused = 0;    ///< not allocated: max_blocks reached (>= 1 if so)
  std::size_t blocks_evicted = 0;    ///< farther than max_block_distance_m
  std::size_t voxels_updated = 0;    ///< voxels fused this frame
  /// Why the whole frame was refused (all its pixels or points counted invalid), or nullptr:
  /// invalid intrinsics, a pose or sensor origin not finite or beyond TsdfMap::inBounds.
  const char* refused = nullptr;
};

/// Integrates a depth image: `depth` holds width * height depths in metres along the optical
/// axis (row-major; NaN, 0 or negative = invalid, +Inf = no return). T_map_camera takes
/// optical-frame points into the map frame. Each voxel in the touched blocks is projected to its
/// nearest pixel centre (rounding, not truncation: no half-pixel bias) and updated with
/// sdf = (depth - z) * |(x/z, y/z, 1)|: the range difference along the ray through the voxel.
/// Allocates its per-pixel buffers per call; a stream of frames should use a DepthIntegrator.
TsdfIntegrationStats integrateDepth(TsdfMap* map, const float* depth, const PinholeCamera& camera,
                                    const Eigen::Isometry3d& T_map_camera);

/// Integrates depth images into a map. Keeps its per-pixel buffers (checked and inverse depths,
/// edge and interpolation masks, ray lengths per pixel) from frame to frame, so frames of one
/// size allocate nothing: hold one per stream. Not thread-safe; integrate() is as integrateDepth.
class DepthIntegrator {
 public:
  DepthIntegrator();
  ~DepthIntegrator();
  DepthIntegrator(DepthIntegrator&&) noexcept;
  DepthIntegrator& operator=(DepthIntegrator&&) noexcept;
  TsdfIntegrationStats integrate(TsdfMap* map, const float* depth, const PinholeCamera& camera,
                                 const Eigen::Isometry3d& T_map_camera);

 private:
  struct Buffers;
  std::unique_ptr<Buffers> buffers_;
};

/// 16UC1 depth (mm, 0 = invalid: REP-118) to metres (NaN where invalid), for integrateDepth.
void millimetresToMetres(const std::uint16_t* millimetres, std::size_t count, float* metres);

/// Integrates points (map frame) seen from `origin` (map frame): each voxel the ray crosses
/// within mu of its end point is updated with the signed distance along the ray.
TsdfIntegrationStats integratePoints(TsdfMap* map, const std::vector<Eigen::Vector3d>& points,
                                     const Eigen::Vector3d& origin);

}  // namespace downstream_perception
