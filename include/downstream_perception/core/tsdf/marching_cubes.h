// Marching cubes (Lorensen & Cline 1987) over the zero level set of a TsdfMap, per block, so
// only blocks changed since the last pass are re-extracted.
//
// The case table (256 sign patterns of a cube's corners -> triangles over its 12 edges) is
// derived at start-up rather than typed in: on each cube face the crossing edges are paired
// (on an ambiguous face, with two diagonal corners inside, the segments cut off the inside
// corners), the segments close into loops around the cube, and each loop becomes a triangle
// fan wound so its normal points toward positive distance (free space). The face rule depends
// only on the face's four corners, so neighbouring cubes agree and the surface has no cracks.
#pragma once

#include <tsl/robin_map.h>
#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "downstream_perception/core/tsdf/tsdf_map.h"

namespace downstream_perception {

/// Corner offsets of the unit cube in the usual order: 0 (0,0,0), 1 (1,0,0), 2 (1,1,0),
/// 3 (0,1,0), 4 (0,0,1), 5 (1,0,1), 6 (1,1,1), 7 (0,1,1).
extern const std::array<std::array<int, 3>, 8> kCubeCorners;
/// Edge e joins corners kCubeEdges[e][0] and kCubeEdges[e][1].
extern const std::array<std::array<int, 2>, 12> kCubeEdges;

/// Triangles (edge triples) for a sign pattern: bit c of `inside_mask` set when corner c has a
/// negative distance.
const std::vector<std::array<int, 3>>& marchingCubesCase(int inside_mask);

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;  ///< m, map frame
  std::vector<Eigen::Vector3f> normals;   ///< unit, toward free space (TSDF gradient)
  std::vector<std::uint32_t> triangles;   ///< 3 vertex indices per triangle
  std::size_t triangleCount() const { return triangles.size() / 3; }
  void append(const TriangleMesh& other);
  /// Binary little-endian PLY with vertex normals. Returns an empty string or the reason.
  std::string writePly(const std::string& path) const;
  /// The same PLY into a stream (a service writes it through an OutputDirectory).
  void writePly(std::ostream& out) const;
};

/// Mesh of the cubes whose lowest corner lies in `block` (corners need weight > min_weight).
TriangleMesh extractBlockMesh(const TsdfMap& map, const Eigen::Vector3i& block);

class TsdfMesher {
 public:
  using BlockMeshes = tsl::robin_map<Eigen::Vector3i, TriangleMesh, BlockIndexHash>;

  /// Re-extracts the blocks changed since the last call (and their neighbours, whose cubes and
  /// normals read the changed voxels), every block when a setting the mesh reads (min_weight,
  /// mesh_extrapolate_voxels) changed; drops meshes of blocks that no longer exist. Returns
  /// the number of blocks extracted.
  std::size_t update(const TsdfMap& map);
  /// Blocks extracted by the last update().
  const std::vector<Eigen::Vector3i>& lastUpdated() const { return last_updated_; }
  const BlockMeshes& blocks() const { return meshes_; }
  /// All blocks in one mesh, welded: one vertex per position (block seams included).
  TriangleMesh combined() const;
  void clear();

 private:
  BlockMeshes meshes_;
  std::uint64_t last_generation_ = 0;
  std::vector<Eigen::Vector3i> last_updated_;
  float voxel_size_ = 0.0f;  ///< of the map last meshed: where block faces lie in combined()
  /// The settings the meshes were extracted with (NaN: none yet).
  double meshed_min_weight_ = std::numeric_limits<double>::quiet_NaN();
  double meshed_extrapolate_voxels_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace downstream_perception
