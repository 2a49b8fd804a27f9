#include "downstream_perception/core/costmap/walk_chooser.h"

#include <algorithm>
#include <cmath>

namespace downstream_perception {

namespace {
// 0 for 0, else the number of bits of n.
std::uint32_t octave(std::size_t n) {
  std::uint32_t bits = 0;
  for (; n != 0; n >>= 1) ++bits;
  return bits;
}
}  // namespace

std::uint32_t WalkChooser::contextOf(std::size_t ray_cells, std::size_t box_cells,
                                     std::uint32_t available) {
  return octave(ray_cells) | (octave(box_cells) << 8) | ((available & kAllWalks) << 16);
}

WalkChooser::Context& WalkChooser::contextFor(std::uint32_t key) {
  Context* oldest = &contexts_[0];
  for (Context& c : contexts_) {
    if (c.used && c.key == key) return c;
    if (!c.used) {
      oldest = &c;
      break;
    }
    if (c.last_used < oldest->last_used) oldest = &c;
  }
  *oldest = Context{};
  oldest->key = key;
  oldest->used = true;
  return *oldest;
}

WalkChooser::Walk WalkChooser::fastest(const Context& c, std::uint32_t available) {
  int best = -1;
  for (int k = 0; k < kWalks; ++k) {
    const Measure& m = c.measures[k];
    if (m.samples == 0 || !(available >> k & 1u)) continue;
    if (best < 0 || m.ns_per_cell < c.measures[best].ns_per_cell) best = k;
  }
  return static_cast<Walk>(std::max(best, 0));
}

WalkChooser::Walk WalkChooser::choose(std::uint32_t context, Walk prior, std::uint32_t available) {
  ++scans_;
  available |= 1u << prior;
  Context& c = contextFor(context);
  c.available = available;
  c.last_used = scans_;
  ++c.scans;
  Walk walk = prior;
  bool trial = false;
  // Each walk is measured twice before any is preferred, the prior first; the second sample
  // replaces the first, which may have run cold (the reverse query's block memory still empty).
  if (c.measures[prior].samples >= 2) {
    int unmeasured = -1;
    for (int k = 0; k < kWalks && unmeasured < 0; ++k) {
      if ((available >> k & 1u) && c.measures[k].samples < 2) unmeasured = k;
    }
    if (unmeasured >= 0) {
      walk = static_cast<Walk>(unmeasured);
    } else {
      walk = fastest(c, available);
      for (int k = 0; k < kWalks; ++k) {
        if (k != walk && (available >> k & 1u) && c.scans >= c.measures[k].retry_at) {
          walk = static_cast<Walk>(k);
          trial = true;
          break;
        }
      }
    }
  }
  pending_context_ = &c;
  pending_walk_ = walk;
  pending_trial_ = trial;
  ++runs_[walk];
  return walk;
}

void WalkChooser::report(double ns_per_cell) {
  if (pending_context_ == nullptr) return;
  Context& c = *pending_context_;
  pending_context_ = nullptr;
  // A scan below the clock's resolution still counts as fast.
  const double sample = std::isfinite(ns_per_cell) && ns_per_cell > 0.0 ? ns_per_cell : 1e-3;
  Measure& m = c.measures[pending_walk_];
  const Walk before = fastest(c, c.available);
  if (m.samples < 2 || pending_trial_) {
    m.ns_per_cell = sample;
  } else {
    m.ns_per_cell += kAverageWeight * (std::min(sample, kSpikeCap * m.ns_per_cell) - m.ns_per_cell);
  }
  ++m.samples;
  if (pending_trial_) {
    if (fastest(c, c.available) == pending_walk_) {
      // It won: the walk it replaces is tried again soon, in case the trial was lucky.
      m.retry_scans = kFirstRetryScans;
      Measure& former = c.measures[before];
      former.retry_scans = kFirstRetryScans;
      former.retry_at = c.scans + kFirstRetryScans;
    } else {
      m.retry_scans = std::min(2 * m.retry_scans, kMaxRetryScans);
      m.retry_at = c.scans + m.retry_scans;
    }
  } else {
    // Exploring, or the fastest running: should it lose that place, it is retried after the
    // first interval (not at once on a stale schedule).
    m.retry_scans = kFirstRetryScans;
    m.retry_at = c.scans + kFirstRetryScans;
  }
}

double WalkChooser::figure(std::uint32_t context, Walk walk) const {
  for (const Context& c : contexts_) {
    if (c.used && c.key == context) {
      return c.measures[walk].samples > 0 ? c.measures[walk].ns_per_cell : -1.0;
    }
  }
  return -1.0;
}

}  // namespace downstream_perception
