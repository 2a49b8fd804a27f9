#include "downstream_perception/ros/tsdf/tsdf_mesh_markers.h"

#include <vector>

namespace downstream_perception {

int TsdfMeshMarkers::idOf(const Eigen::Vector3i& block) {
  auto it = ids_.find(block);
  if (it != ids_.end()) return it->second;
  ids_.emplace(block, next_id_);
  return next_id_++;
}

visualization_msgs::MarkerArray TsdfMeshMarkers::changed(const TsdfMesher& mesher,
                                                         const std_msgs::Header& header) {
  visualization_msgs::MarkerArray out;
  const auto base = [&](int id, int action) {
    visualization_msgs::Marker m;
    m.header = header;
    m.ns = "tsdf_mesh";
    m.id = id;
    m.action = action;
    m.type = visualization_msgs::Marker::TRIANGLE_LIST;
    m.pose.orientation.w = 1.0;
    m.scale.x = m.scale.y = m.scale.z = 1.0;
    return m;
  };
  for (const Eigen::Vector3i& key : mesher.lastUpdated()) {
    const auto it = mesher.blocks().find(key);
    const bool empty = it == mesher.blocks().end() || it->second.triangles.empty();
    if (empty) {
      const auto known = ids_.find(key);
      if (known != ids_.end())
        out.markers.push_back(base(known->second, visualization_msgs::Marker::DELETE));
      continue;
    }
    const TriangleMesh& mesh = it->second;
    visualization_msgs::Marker m = base(idOf(key), visualization_msgs::Marker::ADD);
    m.color.a = 1.0f;
    m.points.reserve(mesh.triangles.size());
    m.colors.reserve(mesh.triangles.size());
    for (const std::uint32_t i : mesh.triangles) {
      geometry_msgs::Point p;
      p.x = mesh.vertices[i].x();
      p.y = mesh.vertices[i].y();
      p.z = mesh.vertices[i].z();
      m.points.push_back(p);
      std_msgs::ColorRGBA c;
      c.r = 0.5f * (mesh.normals[i].x() + 1.0f);
      c.g = 0.5f * (mesh.normals[i].y() + 1.0f);
      c.b = 0.5f * (mesh.normals[i].z() + 1.0f);
      c.a = 1.0f;
      m.colors.push_back(c);
    }
    out.markers.push_back(std::move(m));
  }
  // Blocks evicted or cleared since the last call.
  std::vector<Eigen::Vector3i> gone;
  for (const auto& [key, id] : ids_) {
    if (mesher.blocks().find(key) == mesher.blocks().end()) gone.push_back(key);
  }
  for (const Eigen::Vector3i& key : gone) {
    out.markers.push_back(base(ids_.at(key), visualization_msgs::Marker::DELETE));
    ids_.erase(key);
  }
  return out;
}

visualization_msgs::MarkerArray TsdfMeshMarkers::clearAll(const std_msgs::Header& header) {
  visualization_msgs::MarkerArray out;
  visualization_msgs::Marker m;
  m.header = header;
  m.ns = "tsdf_mesh";
  m.action = visualization_msgs::Marker::DELETEALL;
  out.markers.push_back(m);
  ids_.clear();
  return out;
}

}  // namespace downstream_perception
