// Our Layer plugins running inside costmap_2d (move_base): a costmap_2d::Layer that owns one of
// our layers and a "shadow" LayeredCostmap mirroring costmap_2d's master (size, resolution,
// origin, footprint, frame). Built only when costmap_2d is found at build time.
//
// Per update: the master's geometry is mirrored (a rolling-window origin change becomes a
// whole-cell shift of the layer's data, anything else a resize), updateBounds() runs on our
// layer, and updateCosts() copies the master's window into the shadow, lets our layer draw into
// it and copies the window back (one memcpy per row each way; the layers themselves are the same
// code as in our own costmap). Parameters live where costmap_2d plugins keep them:
// ~/<costmap name>/<layer name>/..., with the same keys as in our costmap, and the layer's
// dynamic_reconfigure server and diagnostics come along.
#pragma once

#include <costmap_2d/costmap_2d.h>
#include <costmap_2d/layer.h>
#include <diagnostic_updater/diagnostic_updater.h>

#include <memory>

#include "downstream_perception/ros/costmap/layer.h"
#include "downstream_perception/ros/costmap/layered_costmap.h"

namespace downstream_perception {

class Costmap2dLayerAdapter : public costmap_2d::Layer {
 public:
  explicit Costmap2dLayerAdapter(std::shared_ptr<downstream_perception::Layer> impl);
  ~Costmap2dLayerAdapter() override;

  void updateBounds(double robot_x, double robot_y, double robot_yaw, double* min_x, double* min_y,
                    double* max_x, double* max_y) override;
  void updateCosts(costmap_2d::Costmap2D& master, int min_i, int min_j, int max_i,
                   int max_j) override;
  void matchSize() override;
  void reset() override;
  void activate() override;
  void deactivate() override;
  void onFootprintChanged() override;

 protected:
  void onInitialize() override;

 private:
  /// Mirrors the master's geometry into the shadow; true if the whole map must be redrawn.
  bool syncGeometry();

  std::shared_ptr<downstream_perception::Layer> impl_;
  std::unique_ptr<LayeredCostmap> shadow_;
  std::unique_ptr<diagnostic_updater::Updater> diagnostics_;
  bool impl_enabled_ = true;  ///< our layer's "enabled" (costmap_2d's enabled_ stays true)
};

}  // namespace downstream_perception
