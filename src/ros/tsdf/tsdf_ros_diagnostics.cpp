// TsdfRos's diagnostics: what it integrated and refused, its memory, the mesh, slice, OctoMap
// and ESDF figures, and its config errors.
#include "downstream_perception/ros/tsdf/tsdf_ros.h"

#include <sstream>

#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/timing_diagnostics.h"

namespace downstream_perception {

void TsdfRos::addSliceSizeLocked(diagnostic_updater::DiagnosticStatusWrapper& status) const {
  status.add("slice window (m)",
             slice_window_.side_m > 0.0 ? toText(slice_window_.side_m) : std::string("whole map"));
  status.add("slice max cells", slice_window_.max_cells);
  status.add("slices cut to slice_max_cells (total)", slices_capped_);
  status.add("slice: cells", slice_cells_);
  // The cells as SliceCell and as the message's data: a byte each.
  status.add("slice: bytes", 2 * slice_cells_);
  status.add("slice time last (ms)", slice_ms_);
  if (!slice_distance_publisher_) return;
  status.add("slice distance: columns computed (window and padding)",
             slice_distance_stats_.columns_computed);
  status.add("slice distance: bytes",
             slice_distance_stats_.columns_computed * EsdfBandStats::kBytesPerComputedCell +
                 slice_cells_ * sizeof(float));
  status.add("slice distance: known band voxels read", slice_distance_stats_.voxels_in_band);
  status.add("slice distance: padding (voxels)", slice_distance_stats_.padding_voxels);
  status.add("slice distance: padding narrowed to 2 x slice_max_cells (total)",
             clearance_padding_cuts_);
}

void TsdfRos::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::size_t rejected = rejected_.report(status);
  status.add("frames integrated", frames_integrated_);
  status.add("frames rejected", rejected);
  status.add("depth images waiting for their first CameraInfo", camera_infos_.waiting());
  status.add("clock jumps back (waiting messages and tf reset)", clock_jump_.jumps());
  status.add("integration time mean (ms)", integrate_ms_.mean());
  status.add("integration time max (ms)", integrate_ms_.max);
  addTimingHistogram(status, "integration time", "ms", integrate_ms_.histogram);
  status.add("last frame: valid pixels or points", last_.pixels_valid);
  status.add("last frame: voxels updated", last_.voxels_updated);
  status.add("invalid pixels or points (total)", pixels_invalid_);
  status.add("blocks", map_->blockCount());
  status.add("memory (MB)", static_cast<double>(map_->memoryBytes()) / 1e6);
  status.add("blocks refused at max_blocks (total)", blocks_refused_);
  status.add("blocks evicted by distance (total)", blocks_evicted_);
  status.add("blocks evicted to a lowered max_blocks (total)", map_->blocksEvictedToCap());
  status.add("no-return pixels not carved: too few valid depths in their frame (total)",
             pixels_no_return_ignored_);
  status.add("mesh triangles", mesh_triangles_);
  status.add("slice: occupied cells", slice_stats_.cells_occupied);
  status.add("slice band (m)", toText(slice_.min_z_m) + " .. " + toText(slice_.max_z_m));
  status.add("slice distance cap (m)",
             slice_distance_max_m_ > 0.0 ? toText(slice_distance_max_m_) : std::string("off"));
  status.add("max_weight", map_->config().max_weight);
  status.add("free-space carving", map_->config().carve_free_space ? "on" : "off");
  status.add("depth range (m)",
             toText(map_->config().min_depth_m) + " .. " + toText(map_->config().max_depth_m));
  if (octree_) {
    const OctreeWorker::Stats octree = octree_->stats();
    status.add("octomap: observations inserted", octree.inserted);
    status.add("octomap: observations dropped (queue full: insertion slower than the sensor)",
               octree.dropped);
    status.add("octomap: leaves", octree.leaves);
    status.add("octomap: nodes", octree.nodes);
    status.add("octomap: occupied leaves", octree_occupied_.load());
    status.add("octomap: memory (MB)", static_cast<double>(octree.memory_bytes) / 1e6);
    status.add("octomap: memory cap (MB)", static_cast<double>(octree_max_memory_bytes_) / 1e6);
    status.add("octomap: nodes evicted by distance (total)", octree.nodes_evicted_by_distance);
    status.add("octomap: nodes evicted at the memory cap (total)", octree.nodes_evicted_at_cap);
    status.add("octomap: maintenance time mean (ms)", octree.maintenance_ms.mean());
    status.add("octomap: maintenance time max (ms)", octree.maintenance_ms.max);
    status.add("octomap: insertion time mean (ms)", octree.insert_ms.mean());
    status.add("octomap: insertion time max (ms)", octree.insert_ms.max);
  }
  status.add("slice: free cells", slice_stats_.cells_free);
  status.add("slices refused (map extent beyond a grid)", slices_refused_);
  addSliceSizeLocked(status);
  if (esdf_) esdf_->diagnose(status);
  status.add("mesh update time mean (ms)", mesh_ms_.mean());
  if (!last_health_.isZero()) {
    status.add("health: zero crossings", health_.crossings);
    status.add("health: mean |grad(D mu)| (1 = true distances; oblique views read 1/cos)",
               health_.mean_gradient_ratio);
    status.add("health: double crossings within mu (drift or thin objects)",
               health_.double_crossings);
  }
  const std::size_t waiting = addTfWaits(status, "depth images: ", depth_filter_.waitingForTf()) +
                              addTfWaits(status, "point clouds: ", cloud_filter_.waitingForTf());
  if (config_errors_.report(status)) return;  // ERROR, with the first problem
  if (waiting > 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   std::to_string(waiting) + " frame(s) waiting for tf (see 'waiting for tf')");
  } else if (frames_integrated_ == 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no frame integrated yet");
  } else if (blocks_refused_ > 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   "max_blocks reached: parts of the scene are not mapped");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "fusing");
  }
}

}  // namespace downstream_perception
