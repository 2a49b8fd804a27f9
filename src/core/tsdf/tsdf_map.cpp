#include "downstream_perception/core/tsdf/tsdf_map.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace downstream_perception {

std::string TsdfConfig::inertSettings() const {
  const TsdfConfig defaults;
  std::ostringstream why;
  // Only these two estimate the pixels' incidences, which say how deep along the normal a voxel
  // lies (confirm_depth_voxels) and which the incidence window refines.
  const bool estimates_incidences =
      (edge_guard_rule == EdgeGuardRule::kRimDistance && edge_guard_rad > 0.0) ||
      grazing_reach_voxels > 0.0;
  const char* no_incidences =
      " has no effect without incidence estimates (edge_guard_rule rim_distance with "
      "edge_guard_rad > 0, or grazing_reach_voxels > 0)";
  // The confirm rule's own settings (the first one changed) do nothing while the rule is off
  // or has no incidences to read.
  const char* confirm_setting = nullptr;
  double confirm_value = 0.0;
  if (confirm_depth_max_m != defaults.confirm_depth_max_m) {
    confirm_setting = "confirm_depth_max_m";
    confirm_value = confirm_depth_max_m;
  } else if (unconfirmed_update_weight != defaults.unconfirmed_update_weight) {
    confirm_setting = "unconfirmed_update_weight";
    confirm_value = unconfirmed_update_weight;
  } else if (far_free_guess_weight != defaults.far_free_guess_weight) {
    confirm_setting = "far_free_guess_weight";
    confirm_value = far_free_guess_weight;
  }
  const char* confirm_inert =
      !(confirm_depth_voxels > 0.0)
          ? " has no effect with confirm_depth_voxels 0 (every update confirms)"
          : (estimates_incidences ? nullptr : no_incidences);
  if (edge_guard_rule == EdgeGuardRule::kRimDistance &&
      edge_guard_grazing_voxels != defaults.edge_guard_grazing_voxels) {
    why << "edge_guard_grazing_voxels " << edge_guard_grazing_voxels
        << " has no effect with edge_guard_rule rim_distance (the rim distance sets every "
           "pixel's depth); it applies with fixed_radius";
  } else if (edge_guard_rule == EdgeGuardRule::kFixedRadius &&
             edge_guard_rim_scale != defaults.edge_guard_rim_scale) {
    why << "edge_guard_rim_scale " << edge_guard_rim_scale
        << " has no effect with edge_guard_rule fixed_radius; it applies with rim_distance";
  } else if (confirm_depth_voxels != defaults.confirm_depth_voxels && confirm_depth_voxels > 0.0 &&
             !estimates_incidences) {
    why << "confirm_depth_voxels " << confirm_depth_voxels << no_incidences;
  } else if (confirm_setting != nullptr && confirm_inert != nullptr) {
    why << confirm_setting << " " << confirm_value << confirm_inert;
  } else if (incidence_window_radius_px != defaults.incidence_window_radius_px &&
             incidence_window_radius_px > 0 && !estimates_incidences) {
    why << "incidence_window_radius_px " << incidence_window_radius_px << no_incidences;
  } else if (mesh_extrapolate_voxels != defaults.mesh_extrapolate_voxels &&
             mesh_extrapolate_voxels > truncation_voxels) {
    why << "mesh_extrapolate_voxels " << mesh_extrapolate_voxels << " acts as truncation_voxels "
        << truncation_voxels << " (no voxel lies farther from the surface)";
  }
  return why.str();
}

double TsdfConfig::confirmDepth() const {
  const double depth = confirm_depth_voxels * voxel_size_m;
  if (!(confirm_depth_max_m > 0.0)) return depth;
  return std::min(depth, std::max(confirm_depth_max_m, kConfirmDepthFloorVoxels * voxel_size_m));
}

std::string TsdfConfig::validate() const {
  std::ostringstream why;
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(voxel_size_m) || voxel_size_m < 1e-3 || voxel_size_m > 10.0) {
    why << "voxel_size_m must be in [0.001, 10] m, got " << voxel_size_m;
  } else if (!(truncation_voxels >= 1.0 && truncation_voxels <= 64.0)) {
    why << "truncation_voxels must be in [1, 64], got " << truncation_voxels;
  } else if (!(std::isfinite(max_weight) && max_weight >= 0.0)) {
    why << "max_weight must be finite and >= 0 (0 = no cap), got " << max_weight;
  } else if (!(positive(min_depth_m) && max_depth_m > min_depth_m && max_depth_m <= 1000.0)) {
    why << "need 0 < min_depth_m < max_depth_m <= 1000 m, got " << min_depth_m << " and "
        << max_depth_m;
  } else if (!(no_return_carve_min_valid_fraction >= 0.0 &&
               no_return_carve_min_valid_fraction <= 1.0)) {
    why << "no_return_carve_min_valid_fraction must be in [0, 1], got "
        << no_return_carve_min_valid_fraction;
  } else if (!(std::isfinite(min_weight) && min_weight >= 0.0)) {
    why << "min_weight must be finite and >= 0, got " << min_weight;
  } else if (!(std::isfinite(edge_guard_rad) && edge_guard_rad >= 0.0 && edge_guard_rad < 0.2)) {
    why << "edge_guard_rad must be in [0, 0.2) rad, got " << edge_guard_rad;
  } else if (!(edge_guard_rim_scale > 0.0 && edge_guard_rim_scale <= 100.0)) {
    why << "edge_guard_rim_scale must be in (0, 100], got " << edge_guard_rim_scale;
  } else if (!(grazing_reach_voxels >= 0.0 && grazing_reach_voxels <= 64.0)) {
    why << "grazing_reach_voxels must be in [0, 64], got " << grazing_reach_voxels;
  } else if (!(grazing_reach_max_voxels >= 1.0 && grazing_reach_max_voxels <= 256.0)) {
    why << "grazing_reach_max_voxels must be in [1, 256], got " << grazing_reach_max_voxels;
  } else if (edge_guard_rule != EdgeGuardRule::kRimDistance &&
             edge_guard_rule != EdgeGuardRule::kFixedRadius) {
    why << "edge_guard_rule must be rim_distance or fixed_radius";
  } else if (!(edge_guard_grazing_voxels >= 1.0 && edge_guard_grazing_voxels <= 1000.0)) {
    why << "edge_guard_grazing_voxels must be in [1, 1000], got " << edge_guard_grazing_voxels;
  } else if (!(std::isfinite(behind_surface_dropoff_start_voxels) &&
               behind_surface_dropoff_start_voxels >= 0.0)) {
    why << "behind_surface_dropoff_start_voxels must be finite and >= 0 (>= truncation_voxels = "
           "no ramp), got "
        << behind_surface_dropoff_start_voxels;
  } else if (!(confirm_depth_voxels >= 0.0 && confirm_depth_voxels <= 64.0)) {
    why << "confirm_depth_voxels must be in [0, 64] (0 = off), got " << confirm_depth_voxels;
  } else if (!(confirm_depth_max_m >= 0.0 && confirm_depth_max_m <= 100.0)) {
    why << "confirm_depth_max_m must be in [0, 100] m (0 = no cap), got " << confirm_depth_max_m;
  } else if (!(unconfirmed_update_weight > 0.0 && unconfirmed_update_weight <= 1.0)) {
    why << "unconfirmed_update_weight must be in (0, 1] (1 = as a confirming update), got "
        << unconfirmed_update_weight;
  } else if (!(far_free_guess_weight > 0.0 && far_free_guess_weight <= 1.0)) {
    why << "far_free_guess_weight must be in (0, 1] (1 = off), got " << far_free_guess_weight;
  } else if (!(incidence_window_radius_px >= 0 && incidence_window_radius_px <= 64)) {
    why << "incidence_window_radius_px must be in [0, 64] (0 = off), got "
        << incidence_window_radius_px;
  } else if (!(mesh_extrapolate_voxels >= 0.0 && mesh_extrapolate_voxels <= 64.0)) {
    // Not bounded by truncation_voxels: the default (2) must not refuse a map truncated at 1.5.
    why << "mesh_extrapolate_voxels must be in [0, 64] (0 = off), got " << mesh_extrapolate_voxels;
  } else if (max_blocks < 1) {
    why << "max_blocks must be >= 1";
  } else if (!(std::isfinite(max_block_distance_m) && max_block_distance_m >= 0.0)) {
    why << "max_block_distance_m must be finite and >= 0 (0 = never evict), got "
        << max_block_distance_m;
  }
  return why.str();
}

namespace {
/// The cap fuse() applies: max_weight, or none (+Inf) for 0.
float weightCapOf(const TsdfConfig& c) {
  return c.max_weight > 0.0 ? static_cast<float>(c.max_weight)
                            : std::numeric_limits<float>::infinity();
}
}  // namespace

TsdfMap::TsdfMap(const TsdfConfig& config) : config_(config), weight_cap_(weightCapOf(config)) {
  const std::string why = config.validate();
  if (!why.empty()) throw std::invalid_argument("tsdf: " + why);
}

std::string TsdfMap::setConfig(const TsdfConfig& config) {
  std::string why = config.validate();
  if (!why.empty()) return why;
  if (config.voxel_size_m != config_.voxel_size_m ||
      config.truncation_voxels != config_.truncation_voxels) {
    return "voxel_size_m and truncation_voxels are fixed for the map's life (the stored distances "
           "are in their units); restart the node to change them";
  }
  config_ = config;
  weight_cap_ = weightCapOf(config);
  evictToCap();
  return {};
}

namespace {
/// floor(a / b) for b > 0, without overflow for any int a (-a overflows at INT_MIN).
int floorDiv(int a, int b) {
  return a >= 0 ? a / b : -1 - (-(a + 1)) / b;
}

/// round(x) as an int, clamped to +-TsdfMap::kMaxVoxelIndex (NaN: 0): no float-to-int overflow.
int clampedRound(double x) {
  constexpr double kMax = TsdfMap::kMaxVoxelIndex;
  if (!(std::abs(x) <= kMax)) return std::isnan(x) ? 0 : (x > 0.0 ? kMax : -kMax);
  return static_cast<int>(std::lround(x));
}
}  // namespace

bool TsdfMap::inBounds(const Eigen::Vector3d& p) const {
  const double limit = 0.5 * kMaxVoxelIndex * config_.voxel_size_m;
  return std::abs(p.x()) <= limit && std::abs(p.y()) <= limit && std::abs(p.z()) <= limit;
}

Eigen::Vector3i TsdfMap::blockOf(const Eigen::Vector3i& v) {
  return {floorDiv(v.x(), kTsdfBlockSide), floorDiv(v.y(), kTsdfBlockSide),
          floorDiv(v.z(), kTsdfBlockSide)};
}

int TsdfMap::localIndex(const Eigen::Vector3i& v) {
  const auto local = [](int a) { return a - floorDiv(a, kTsdfBlockSide) * kTsdfBlockSide; };
  return TsdfBlock::linear(local(v.x()), local(v.y()), local(v.z()));
}

Eigen::Vector3i TsdfMap::voxelAt(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d s = p / config_.voxel_size_m;
  return {clampedRound(s.x()), clampedRound(s.y()), clampedRound(s.z())};
}

TsdfBlock* TsdfMap::allocate(const Eigen::Vector3i& block, bool* created) {
  if (created != nullptr) *created = false;
  auto it = blocks_.find(block);
  if (it != blocks_.end()) return it->second.get();
  if (blocks_.size() >= config_.max_blocks) return nullptr;
  if (created != nullptr) *created = true;
  return blocks_.emplace(block, pool_->acquire()).first->second.get();
}

TsdfBlock* TsdfMap::find(const Eigen::Vector3i& block) {
  auto it = blocks_.find(block);
  return it == blocks_.end() ? nullptr : it->second.get();
}

const TsdfBlock* TsdfMap::find(const Eigen::Vector3i& block) const {
  auto it = blocks_.find(block);
  return it == blocks_.end() ? nullptr : it->second.get();
}

const TsdfVoxel* TsdfMap::voxel(const Eigen::Vector3i& v) const {
  const TsdfBlock* b = find(blockOf(v));
  return b == nullptr ? nullptr : &b->voxels[localIndex(v)];
}

const TsdfVoxel* TsdfMap::voxelNear(const Eigen::Vector3d& p) const {
  return inBounds(p) ? voxel(voxelAt(p)) : nullptr;
}

std::size_t TsdfMap::evictFartherThan(const Eigen::Vector3d& center, double distance_m) {
  const double block_m = kTsdfBlockSide * config_.voxel_size_m;
  const double limit2 = distance_m * distance_m;
  std::size_t removed = 0;
  for (auto it = blocks_.begin(); it != blocks_.end();) {
    const Eigen::Vector3d c =
        (it->first.cast<double>() + Eigen::Vector3d::Constant(0.5)) * block_m -
        Eigen::Vector3d::Constant(0.5 * config_.voxel_size_m);
    if ((c - center).squaredNorm() > limit2) {
      it = blocks_.erase(it);
      ++removed;
    } else {
      ++it;
    }
  }
  return removed;
}

std::size_t TsdfMap::evictToCap() {
  if (blocks_.size() <= config_.max_blocks) return 0;
  struct Candidate {
    std::uint64_t stamp;
    double distance2;
    Eigen::Vector3i key;
  };
  const double block_m = kTsdfBlockSide * config_.voxel_size_m;
  std::vector<Candidate> candidates;
  candidates.reserve(blocks_.size());
  for (const auto& kv : blocks_) {
    const Eigen::Vector3d c = (kv.first.cast<double>() + Eigen::Vector3d::Constant(0.5)) * block_m;
    candidates.push_back({kv.second->updated_stamp, (c - sensor_origin_).squaredNorm(), kv.first});
  }
  // The first `excess` in this order go: oldest update first, then farthest, then by index (so
  // the choice does not depend on the hash table's order).
  const auto first_out = [](const Candidate& a, const Candidate& b) {
    if (a.stamp != b.stamp) return a.stamp < b.stamp;
    if (a.distance2 != b.distance2) return a.distance2 > b.distance2;
    return std::lexicographical_compare(a.key.data(), a.key.data() + 3, b.key.data(),
                                        b.key.data() + 3);
  };
  const std::size_t excess = blocks_.size() - config_.max_blocks;
  std::nth_element(candidates.begin(), candidates.begin() + (excess - 1), candidates.end(),
                   first_out);
  for (std::size_t i = 0; i < excess; ++i) blocks_.erase(candidates[i].key);
  evicted_to_cap_ += excess;
  return excess;
}

void TsdfMap::clear() {
  blocks_.clear();
  pool_->trim();
  ++generation_;
}

std::size_t TsdfMap::memoryBytes() const {
  return pool_->bytesReserved() +
         blocks_.bucket_count() * (sizeof(Eigen::Vector3i) + sizeof(void*) + sizeof(std::int32_t));
}

}  // namespace downstream_perception
