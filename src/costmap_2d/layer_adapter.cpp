#include "downstream_perception/costmap_2d/layer_adapter.h"

#include <costmap_2d/layered_costmap.h>
#include <pluginlib/class_list_macros.hpp>

#include <cmath>
#include <cstring>

#include "downstream_perception/layers/inflation_layer.h"
#include "downstream_perception/layers/log_odds_obstacle_layer.h"
#include "downstream_perception/layers/static_layer.h"
#include "downstream_perception/layers/tracked_obstacle_layer.h"
#include "downstream_perception/layers/tsdf_layer.h"
#include "downstream_perception/layers/voxel_obstacle_layer.h"

namespace downstream_perception {

namespace {

GridGeometry geometryOf(const costmap_2d::Costmap2D& m) {
  return GridGeometry(static_cast<int>(m.getSizeInCellsX()), static_cast<int>(m.getSizeInCellsY()),
                      m.getResolution(), m.getOriginX(), m.getOriginY());
}

bool hasCells(const costmap_2d::Costmap2D& m) {
  return m.getSizeInCellsX() > 0 && m.getSizeInCellsY() > 0 && m.getResolution() > 0.0;
}

}  // namespace

Costmap2dLayerAdapter::Costmap2dLayerAdapter(std::shared_ptr<downstream_perception::Layer> impl)
    : impl_(std::move(impl)) {}

Costmap2dLayerAdapter::~Costmap2dLayerAdapter() {
  diagnostics_.reset();
  impl_.reset();  // its subscriptions call back into it: gone before the shadow
  shadow_.reset();
}

void Costmap2dLayerAdapter::onInitialize() {
  shadow_ = std::make_unique<LayeredCostmap>(layered_costmap_->getGlobalFrameID(),
                                             layered_costmap_->isTrackingUnknown());
  const costmap_2d::Costmap2D& master = *layered_costmap_->getCostmap();
  if (hasCells(master)) shadow_->resizeMap(geometryOf(master));
  shadow_->setRollingWindow(layered_costmap_->isRolling());
  // A static map sizes costmap_2d's master (not only the shadow), locked against reconfigure as
  // costmap_2d's StaticLayer does; every costmap_2d layer's matchSize() follows, ours included
  // (which mirrors the new geometry into the shadow). Master lock first, then the shadow's: the
  // order of costmap_2d's update thread.
  shadow_->setSizeLockHandler([this](const GridGeometry& g) {
    costmap_2d::Costmap2D* master_grid = layered_costmap_->getCostmap();
    boost::unique_lock<costmap_2d::Costmap2D::mutex_t> lock(*master_grid->getMutex());
    if (hasCells(*master_grid) && geometryOf(*master_grid) == g) return;
    ROS_INFO("layer '%s': resizing the costmap to %d x %d cells at %.3f m", name_.c_str(),
             g.sizeX(), g.sizeY(), g.resolution());
    layered_costmap_->resizeMap(static_cast<unsigned int>(g.sizeX()),
                                static_cast<unsigned int>(g.sizeY()), g.resolution(), g.originX(),
                                g.originY(), true /* size_locked */);
  });
  shadow_->addPlugin(impl_);
  onFootprintChanged();
  ros::NodeHandle private_nh("~");  // costmap_2d plugins read ~/<costmap>/<layer>/...
  impl_->initialize(shadow_.get(), name_, tf_, private_nh);
  impl_->matchSize();
  diagnostics_ = std::make_unique<diagnostic_updater::Updater>(
      ros::NodeHandle(), ros::NodeHandle(private_nh, name_),
      private_nh.getNamespace() + "/" + name_);
  diagnostics_->setHardwareID("costmap_2d layer " + name_);
  diagnostics_->add("layer " + name_,
                    [this](diagnostic_updater::DiagnosticStatusWrapper& s) { impl_->diagnose(s); });
  enabled_ = true;
  impl_enabled_ = impl_->isEnabled();
  current_ = impl_->isCurrent();
}

bool Costmap2dLayerAdapter::syncGeometry() {
  const costmap_2d::Costmap2D& master = *layered_costmap_->getCostmap();
  if (!hasCells(master)) return false;
  const GridGeometry target = geometryOf(master);
  const GridGeometry& current = shadow_->costmap().geometry();
  if (target == current) return false;
  const double res = target.resolution();
  const double dxf = (target.originX() - current.originX()) / res;
  const double dyf = (target.originY() - current.originY()) / res;
  const bool whole_cells =
      std::abs(dxf - std::round(dxf)) < 1e-6 && std::abs(dyf - std::round(dyf)) < 1e-6;
  if (target.sizeX() == current.sizeX() && target.sizeY() == current.sizeY() &&
      res == current.resolution() && whole_cells) {
    // costmap_2d's rolling window moved the origin by whole cells: keep what stays in view.
    const int dx = static_cast<int>(std::lround(dxf));
    const int dy = static_cast<int>(std::lround(dyf));
    shadow_->costmap().shift(dx, dy);
    impl_->shiftOrigin(dx, dy);
  } else {
    shadow_->resizeMap(target);  // calls impl_->matchSize()
  }
  return true;
}

void Costmap2dLayerAdapter::updateBounds(double robot_x, double robot_y, double robot_yaw,
                                         double* min_x, double* min_y, double* max_x,
                                         double* max_y) {
  if (diagnostics_) diagnostics_->update();
  std::lock_guard<std::recursive_mutex> lock(shadow_->mutex());
  // costmap_2d stops calling a layer whose enabled_ is false, so that flag stays true and our
  // layer's own switch (dynamic_reconfigure "enabled") is followed here instead.
  const bool was_enabled = impl_enabled_;
  impl_enabled_ = impl_->isEnabled();
  // A layer switched on or off appears or vanishes everywhere.
  bool redraw_all = shadow_->takeFullRedrawRequest() || was_enabled != impl_enabled_;
  if (impl_enabled_) {
    redraw_all = syncGeometry() || redraw_all;
    shadow_->setHaveRobotPose(true);  // costmap_2d only updates with a known robot pose
    impl_->updateBounds(robot_x, robot_y, robot_yaw, min_x, min_y, max_x, max_y);
    redraw_all = shadow_->takeFullRedrawRequest() || redraw_all;
    current_ = impl_->isCurrent();
  }
  const costmap_2d::Costmap2D& master = *layered_costmap_->getCostmap();
  if (redraw_all && hasCells(master)) {
    const GridGeometry g = geometryOf(master);
    CellBounds all;
    all.expand(0, 0);
    all.expand(g.sizeX() - 1, g.sizeY() - 1);
    g.expandWorldBox(all, min_x, min_y, max_x, max_y);
  }
}

void Costmap2dLayerAdapter::updateCosts(costmap_2d::Costmap2D& master, int min_i, int min_j,
                                        int max_i, int max_j) {
  if (!impl_enabled_ || min_i >= max_i || min_j >= max_j) return;
  std::lock_guard<std::recursive_mutex> lock(shadow_->mutex());
  Costmap& shadow = shadow_->costmap();
  if (geometryOf(master) != shadow.geometry()) return;  // mirrored at the next updateBounds
  const std::size_t stride = master.getSizeInCellsX();
  const std::size_t width = static_cast<std::size_t>(max_i - min_i);
  unsigned char* cells = master.getCharMap();
  for (int y = min_j; y < max_j; ++y) {
    std::memcpy(shadow.data() + y * stride + min_i, cells + y * stride + min_i, width);
  }
  impl_->updateCosts(shadow, min_i, min_j, max_i, max_j);
  for (int y = min_j; y < max_j; ++y) {
    std::memcpy(cells + y * stride + min_i, shadow.data() + y * stride + min_i, width);
  }
}

void Costmap2dLayerAdapter::matchSize() {
  if (!shadow_) return;
  std::lock_guard<std::recursive_mutex> lock(shadow_->mutex());
  syncGeometry();
}

void Costmap2dLayerAdapter::reset() {
  if (!shadow_) return;
  std::lock_guard<std::recursive_mutex> lock(shadow_->mutex());
  impl_->reset();
  shadow_->requestFullRedraw();
}

void Costmap2dLayerAdapter::activate() {
  impl_->activate();
}

void Costmap2dLayerAdapter::deactivate() {
  impl_->deactivate();
}

void Costmap2dLayerAdapter::onFootprintChanged() {
  if (!shadow_) return;
  Footprint footprint;
  for (const geometry_msgs::Point& p : layered_costmap_->getFootprint()) {
    footprint.push_back({p.x, p.y});
  }
  // costmap_2d's footprint is already padded; ours would pad again: hand it over as it is.
  if (validateFootprint(footprint).empty()) shadow_->setFootprint(footprint);
}

/// downstream_perception::StaticLayer (map_server's map) for costmap_2d / move_base.
class Costmap2dStaticLayer : public Costmap2dLayerAdapter {
 public:
  Costmap2dStaticLayer() : Costmap2dLayerAdapter(std::make_shared<StaticLayer>()) {}
};

/// downstream_perception::LogOddsObstacleLayer for costmap_2d / move_base.
class Costmap2dLogOddsObstacleLayer : public Costmap2dLayerAdapter {
 public:
  Costmap2dLogOddsObstacleLayer()
      : Costmap2dLayerAdapter(std::make_shared<LogOddsObstacleLayer>()) {}
};

/// downstream_perception::InflationLayer for costmap_2d / move_base.
class Costmap2dInflationLayer : public Costmap2dLayerAdapter {
 public:
  Costmap2dInflationLayer() : Costmap2dLayerAdapter(std::make_shared<InflationLayer>()) {}
};

/// downstream_perception::TsdfLayer (the TSDF nodelet's slice) for costmap_2d / move_base.
class Costmap2dTsdfLayer : public Costmap2dLayerAdapter {
 public:
  Costmap2dTsdfLayer() : Costmap2dLayerAdapter(std::make_shared<TsdfLayer>()) {}
};

/// downstream_perception::TrackedObstacleLayer for costmap_2d / move_base.
class Costmap2dTrackedObstacleLayer : public Costmap2dLayerAdapter {
 public:
  Costmap2dTrackedObstacleLayer()
      : Costmap2dLayerAdapter(std::make_shared<TrackedObstacleLayer>()) {}
};

/// downstream_perception::VoxelObstacleLayer (3-D voxels, costmap_2d VoxelLayer's keys) for
/// costmap_2d / move_base.
class Costmap2dVoxelObstacleLayer : public Costmap2dLayerAdapter {
 public:
  Costmap2dVoxelObstacleLayer() : Costmap2dLayerAdapter(std::make_shared<VoxelObstacleLayer>()) {}
};

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::Costmap2dStaticLayer, costmap_2d::Layer)
PLUGINLIB_EXPORT_CLASS(downstream_perception::Costmap2dLogOddsObstacleLayer, costmap_2d::Layer)
PLUGINLIB_EXPORT_CLASS(downstream_perception::Costmap2dInflationLayer, costmap_2d::Layer)
PLUGINLIB_EXPORT_CLASS(downstream_perception::Costmap2dTsdfLayer, costmap_2d::Layer)
PLUGINLIB_EXPORT_CLASS(downstream_perception::Costmap2dTrackedObstacleLayer, costmap_2d::Layer)
PLUGINLIB_EXPORT_CLASS(downstream_perception::Costmap2dVoxelObstacleLayer, costmap_2d::Layer)
