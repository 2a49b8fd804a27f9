// Helpers shared by the TSDF gtests: the lesson's configuration, voxel reads, synthetic fields,
// meshes and their edges, map comparison.
#pragma once

#include <Eigen/Geometry>

#include <cmath>
#include <functional>
#include <map>
#include <tuple>
#include <vector>

#include "downstream_perception/core/tsdf/marching_cubes.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "tsdf_test_scenes.h"

namespace downstream_perception {
namespace test {

inline TsdfConfig lessonConfig() {
  TsdfConfig c;
  c.voxel_size_m = 1.0;
  c.truncation_voxels = 4.0;  // mu = 4 m
  c.behind_surface_dropoff = false;
  c.max_weight = 0.0;
  c.max_depth_m = 100.0;
  return c;
}

inline float distanceAt(const TsdfMap& map, int x, int y = 0, int z = 0) {
  const TsdfVoxel* v = map.voxel({x, y, z});
  return v == nullptr ? std::nanf("") : v->distance;
}

// Writes D = value(voxel centre) with weight 1 into every voxel of [lo, hi] (inclusive; NaN
// skips the voxel), then marks every block as changed by one integration.
inline void fill(TsdfMap* map, const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
                 const std::function<double(const Eigen::Vector3d&)>& value) {
  for (int z = lo.z(); z <= hi.z(); ++z) {
    for (int y = lo.y(); y <= hi.y(); ++y) {
      for (int x = lo.x(); x <= hi.x(); ++x) {
        const Eigen::Vector3i v(x, y, z);
        const double d = value(map->voxelCenter(v));
        if (std::isnan(d)) continue;
        TsdfVoxel& voxel = map->allocate(TsdfMap::blockOf(v))->voxels[TsdfMap::localIndex(v)];
        voxel.distance = static_cast<float>(d);
        voxel.weight = 1.0f;
      }
    }
  }
  const std::uint64_t generation = map->beginIntegration();
  for (const auto& kv : map->blocks()) kv.second->updated_stamp = generation;
}

inline TriangleMesh meshOf(const TsdfMap& map) {
  TsdfMesher mesher;
  mesher.update(map);
  return mesher.combined();
}

// Mesh vertices merged by position (block seams duplicate them, bit-identically) and the count
// of each directed edge over the merged ids.
struct MeshEdges {
  std::vector<int> id;
  std::size_t vertices = 0;
  std::map<std::pair<int, int>, int> directed;
};
inline MeshEdges meshEdges(const TriangleMesh& mesh) {
  MeshEdges e;
  std::map<std::tuple<float, float, float>, int> id_of;
  for (const Eigen::Vector3f& p : mesh.vertices) {
    e.id.push_back(
        id_of.emplace(std::make_tuple(p.x(), p.y(), p.z()), static_cast<int>(id_of.size()))
            .first->second);
  }
  e.vertices = id_of.size();
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      ++e.directed[{e.id[mesh.triangles[3 * t + k]], e.id[mesh.triangles[3 * t + (k + 1) % 3]]}];
    }
  }
  return e;
}

/// Voxels (weight or distance) that differ between two maps, over the union of their blocks.
inline std::size_t differingVoxels(const TsdfMap& a, const TsdfMap& b) {
  std::size_t n = 0;
  const auto count = [&n](const TsdfMap& x, const TsdfMap& y, bool both_ways) {
    for (const auto& kv : x.blocks()) {
      const TsdfBlock* other = y.find(kv.first);
      if (other == nullptr) {
        n += kTsdfBlockVoxels;
        continue;
      }
      if (!both_ways) continue;
      for (int i = 0; i < kTsdfBlockVoxels; ++i) {
        n += kv.second->voxels[i].distance != other->voxels[i].distance ||
             kv.second->voxels[i].weight != other->voxels[i].weight;
      }
    }
  };
  count(a, b, true);
  count(b, a, false);
  return n;
}

}  // namespace test
}  // namespace downstream_perception
