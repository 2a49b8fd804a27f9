// Which exact clearing walk runs a steady scan, chosen by timing them (issue 20).
//
// The clearing walks of scan_clearing.cpp give the same grid and statistics bit for bit, and which
// one is fastest depends on the scan, the map and the machine: a sweep over maps of 200^2-1000^2,
// 360-3600 beams and four sensor positions (docs/benchmarks.md) found the fixed rule
// (ClearingWalk::kAuto's thresholds, measured on one room) more than 1.15x slower than the best
// walk in 10 of 60 cases, up to 1.59x. Since the choice cannot change the result, it can be
// measured instead: the chooser keeps, per kind of scan (a context: the rays' cells and their box,
// in octaves), the time per ray cell of each walk, runs the fastest, and tries each other walk
// again after a number of scans that doubles while it keeps losing (16 to 256 scans), so a walk
// that became faster (the robot drove into a larger room) is found again while a walk that stays
// slower costs at most one scan in 256. Dense scans also choose between one and two threads (the
// shared walks). A trial's sample replaces the walk's old figure (the scene may have changed
// since); the running walk's figure is a moving average, with samples capped at 3x it so one
// preempted scan does not make it look slow.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace downstream_perception {

class WalkChooser {
 public:
  /// The walks it chooses between over seen space (ClearingWalk's per-ray, block, reverse-query
  /// and first-visit walks; the first-visit walk's loop measured faster than the per-ray one on
  /// some steady sparse scans), the *Shared ones on two threads (integrateBeams' bands: they pay
  /// on large maps and cost ~0.1 ms where the box is small or the second core busy). Scans over
  /// unseen space keep kAuto's fixed rule (first-visit or mark-sweep: there they win by far).
  enum Walk : int {
    kPerRay = 0,
    kBlocks = 1,
    kReverseQuery = 2,
    kFirstVisit = 3,
    kPerRayShared = 4,
    kBlocksShared = 5,
    kFirstVisitShared = 6
  };
  static constexpr int kWalks = 7;
  static constexpr std::uint32_t kOneThreadWalks = 0xF;  ///< available without a second thread
  static constexpr std::uint32_t kAllWalks = 0x7F;
  /// Whether a walk runs on two threads, and the same walk on one.
  static bool shared(Walk w) { return w >= kPerRayShared; }
  static Walk oneThread(Walk w) {
    return w == kPerRayShared       ? kPerRay
           : w == kBlocksShared     ? kBlocks
           : w == kFirstVisitShared ? kFirstVisit
                                    : w;
  }
  static constexpr int kContexts = 8;
  static constexpr int kFirstRetryScans = 16;
  static constexpr int kMaxRetryScans = 256;
  static constexpr double kAverageWeight = 0.25;
  static constexpr double kSpikeCap = 3.0;

  /// The context of a scan: its rays' cells and the cells of their box, in octaves, and the walks
  /// available to it (a bit per Walk).
  static std::uint32_t contextOf(std::size_t ray_cells, std::size_t box_cells,
                                 std::uint32_t available = kAllWalks);

  /// The walk to run for a scan of this context, one of `available` (a bit per Walk); `prior`
  /// (kAuto's fixed rule, available) is tried first in a context not seen before. Call report()
  /// after the walk.
  Walk choose(std::uint32_t context, Walk prior, std::uint32_t available = kAllWalks);
  /// The walk chose() returned took this long per ray cell (ns; any positive figure works).
  void report(double ns_per_cell);

  /// Scans run with each walk since construction (all contexts).
  const std::array<std::uint64_t, kWalks>& runs() const { return runs_; }
  /// The current figure of a walk in a context (ns per ray cell), negative if never measured.
  double figure(std::uint32_t context, Walk walk) const;

 private:
  struct Measure {
    double ns_per_cell = -1.0;  ///< < 0: not measured yet
    int samples = 0;
    int retry_scans = kFirstRetryScans;
    std::uint64_t retry_at = 0;  ///< the context's scan count at which it is tried again
  };
  struct Context {
    std::uint32_t key = 0;
    bool used = false;
    std::uint64_t scans = 0;              ///< scans run in this context
    std::uint64_t last_used = 0;          ///< the chooser's scan count when last chosen (LRU)
    std::uint32_t available = kAllWalks;  ///< the walks of its last choose()
    std::array<Measure, kWalks> measures;
  };
  Context& contextFor(std::uint32_t key);
  static Walk fastest(const Context& c, std::uint32_t available);

  std::array<Context, kContexts> contexts_{};
  std::array<std::uint64_t, kWalks> runs_{};
  std::uint64_t scans_ = 0;
  Context* pending_context_ = nullptr;  ///< the context and walk of the last choose()
  Walk pending_walk_ = kPerRay;
  bool pending_trial_ = false;  ///< the walk ran as a trial (not the fastest known)
};

}  // namespace downstream_perception
