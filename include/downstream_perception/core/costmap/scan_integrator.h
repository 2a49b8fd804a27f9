// Integration of range measurements into a LogOddsGrid.
//
// A measurement becomes a BeamUpdate (where to clear, whether and where to mark). A batch of
// beams from one scan is integrated in two passes, so that every cell gets at most one update per
// scan and a hit always wins over a pass-through from another beam of the same scan (as in
// OctoMap's insertPointCloud): beams that graze a wall at a shallow angle must not erode the cells
// that other beams of the same sweep just saw as occupied.
//   pass 1: each marking beam adds l_hit to its hit cell (once per cell)
//   pass 2: each clearing beam walks its cells (Amanatides-Woo) and adds l_miss to every cell not
//           yet updated in this scan; the cell containing a hit is never cleared by its own beam.
//
// Range semantics for a sensor_msgs/LaserScan (REP-117 and LaserScan.msg):
//   NaN                      invalid: ignored
//   -Inf                     "too close to measure": ignored (no free space can be inferred)
//   +Inf                     no return within range_max: if inf_is_valid, clears up to
//                            raytrace_max_range and marks nothing; else ignored
//   r < range_min            invalid per LaserScan.msg: ignored
//   r > range_max            invalid per LaserScan.msg: ignored
//   r == range_max           a return, unless range_max_is_no_return (drivers that report
//                            range_max for "nothing seen"): then treated as +Inf
//   otherwise                a return at r: marks the hit cell if r <= obstacle_max_range (and
//                            r >= obstacle_min_range); clears from raytrace_min_range to
//                            min(r, raytrace_max_range). A beam truncated by raytrace_max_range
//                            clears through its last cell, because that cell is a pass-through.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "downstream_perception/core/costmap/log_odds_grid.h"
#include "downstream_perception/core/costmap/walk_chooser.h"
#include "downstream_perception/core/grid/ray_traversal.h"
#include "downstream_perception/core/grid/se2.h"

namespace downstream_perception {

struct BeamUpdate {
  double start_x = 0.0;  ///< where clearing starts (world, m)
  double start_y = 0.0;
  double end_x = 0.0;  ///< where clearing ends (world, m); the hit point when mark is true
  double end_y = 0.0;
  bool clear = false;           ///< walk the cells from start to end adding l_miss
  bool clear_end_cell = false;  ///< include the cell containing the end point in the clearing
  bool mark = false;            ///< add l_hit to the cell containing (hit_x, hit_y)
  double hit_x = 0.0;
  double hit_y = 0.0;
};

struct IntegrationStats {
  std::size_t beams = 0;            ///< beams offered
  std::size_t beams_marked = 0;     ///< beams whose hit cell got (or shared) a hit update
  std::size_t beams_no_return = 0;  ///< +Inf (or range_max when treated so) beams that cleared
  std::size_t beams_invalid = 0;    ///< NaN, -Inf, outside [range_min, range_max]
  std::size_t beams_beyond_obstacle_range = 0;  ///< returns too far (or near) to mark
  std::size_t points_outside_height = 0;        ///< cloud points outside [min, max]_obstacle_height
  std::size_t points_merged = 0;  ///< cloud points sharing a merge cell with an earlier one
  /// Cells walked by clearing rays, per beam (a cell two beams cross counts twice, as in the
  /// lesson's "a 10 m beam clears ~200 cells"). Each cell still receives at most one miss
  /// update per scan, and none if it was hit in the same scan.
  std::size_t cells_cleared = 0;
  std::size_t cells_marked = 0;   ///< cells that received a hit update
  std::size_t cells_changed = 0;  ///< cells whose state (free/occupied/unknown) changed
  CellBounds touched;             ///< window of every updated cell
  CellBounds changed;             ///< window of the cells whose state changed

  /// Cells cleared per cell marked (the lesson's phantom-wall diagnostic; healthy >> 1).
  double clearMarkRatio() const {
    return cells_marked == 0 ? static_cast<double>(cells_cleared)
                             : static_cast<double>(cells_cleared) / cells_marked;
  }
  void accumulate(const IntegrationStats& o);
};

/// How pass 2 walks the clearing rays (src/core/costmap/scan_clearing.cpp). Both give the same
/// grid, statistics and flag order bit for bit; only the time differs.
enum class ClearingWalk {
  /// What the integrator runs: over space the grid has not seen, the first-visit or mark-sweep
  /// walk by rule; over seen space the walk (and thread count) timed fastest for this kind of
  /// scan (WalkChooser, walk_chooser.h; through an IntegrationScratch: without one, the rule's
  /// first guess: the reverse query / block walk for dense rays, else per ray).
  kAuto,
  /// Every cell of every ray is visited (the reference the block walk is tested against).
  kPerRay,
  /// The grid is cut into 32 x 32 blocks; a block whose every cell is already flagged in this
  /// scan or saturated free (so no ray of this scan can change it any more) is crossed in one
  /// exact integer jump instead of cell by cell. Near the sensor, where the beams of a dense
  /// scan overlap, most of every ray crosses such blocks.
  kBlockSkip,
  /// Mark, then sweep: the rays only mark the cells they cross in a byte map (a store per cell,
  /// no load, as costmap_2d's raytrace), then one pass over the rays' box gives every marked cell
  /// its one miss and clears the marks. Each crossed cell takes exactly one miss either way, so
  /// the grid and statistics are those of the per-ray walk. Pays on a dense scan over space the
  /// grid has not seen yet (first scan after start-up, a reset or a resize), where the per-ray
  /// walk's load and branch per cell cost ~3x costmap_2d's store; kAuto takes it there.
  kMarkSweep,
  /// The per-ray walk with its miss path made the fast one: a cell a miss saturates is left
  /// unflagged (skipped all the same) and changes are bounded per ray. For sparse scans over space
  /// the grid has hardly seen, where most visits update; kAuto takes it where less than a quarter
  /// of the box is saturated free and the mark-sweep does not pay.
  kFirstVisit,
  /// Reverse query (issue 20): the rays sharing one start point are sorted by direction;
  /// every cell of their box a miss could change (not flagged, not saturated free) asks the rays
  /// whose direction meets it whether their exact walk visits it before its end cell (an O(1)
  /// integer test, the walk's own order rule). Other rays (another start, lattice corners) are
  /// walked per ray first. Same grid and statistics as the per-ray walk; the flag order differs.
  kReverseQuery,
};

/// ClearingWalk::kAuto's choice, from the rays' cells (steps summed over the rays), the cells of
/// the box they touch and the share of a sample of that box already saturated free: the block
/// walk when the rays cross the box more than once over and at least a quarter of it is
/// saturated (else no block could be skipped: a first scan).
bool autoChoosesBlockWalk(std::size_t ray_cells, std::size_t box_cells,
                          double saturated_free_share);
/// ClearingWalk::kAuto's choice of the mark-sweep walk (when it does not take the block walk):
/// the rays cross at least half the box's cells and less than a quarter of it is saturated free.
bool autoChoosesMarkSweep(std::size_t ray_cells, std::size_t box_cells,
                          double saturated_free_share);

/// One clearing ray of a scan, set up before any is walked.
struct ClearingRay {
  RayWalk walk;
  bool clear_end_cell = false;  ///< also clear the end cell (asked for, or the end was clipped)
};

/// Buffers integrateBeams reuses between scans (optional: without one it allocates per scan).
struct IntegrationScratch {
  std::vector<ClearingRay> rays;            ///< this scan's clearing rays
  std::vector<std::uint32_t> flagged;       ///< cells flagged in this scan
  std::vector<std::int32_t> block_pending;  ///< per block: -1 unchecked, else cells left to clear
  std::vector<std::uint32_t> block_masks;   ///< per block: where those cells are
  std::vector<std::uint32_t> blocks_checked;
  std::vector<std::uint8_t> crossed;  ///< mark-sweep: 1 where a ray crossed (all 0 between scans)
  std::vector<std::uint8_t> row_changed;  ///< mark-sweep: per cell of a row, state class changed
  int blocks_x = 0;                       ///< block_pending's layout (blocks per row)
  int blocks_y = 0;
  /// The banded walk (see integrateBeams): each band's flags, blocks and results.
  struct Band {
    int first_row = 0;      ///< rows [first_row, next band's first_row)
    std::size_t parts = 0;  ///< ray parts walked in the band (a ray crossing k edges has k + 1)
    std::vector<std::uint32_t> flagged;
    std::vector<std::uint32_t> blocks_checked;
    IntegrationStats stats;
    std::size_t walked = 0;
  };
  std::vector<Band> bands;
  std::vector<ClearingRay> rays_serial;  ///< rays through lattice corners that cross a band edge
  std::vector<double> row_work;          ///< the rays' cells per row, to place the band edges
  /// Reverse query: per ray whether it starts at the scan's common start point (ray_origin, fixed
  /// point); the rays it queries, by direction.
  std::vector<std::uint8_t> same_origin;
  std::int64_t ray_origin[2] = {0, 0};
  struct DirectedRay {
    double key;      ///< pseudo-angle of the direction, [0, 4)
    double length2;  ///< squared length (fixed point)
    std::uint32_t ray;
    int min_x, min_y, max_x, max_y;  ///< the box of its start and end cells (its cells lie in it)
  };
  std::vector<DirectedRay> directed;
  std::vector<std::uint32_t> key_buckets;  ///< first ray of each key bucket
  std::vector<std::uint32_t> near_rays;    ///< the rays that may reach a run of cells
  struct QueryBlock {
    int x0, y0, x1, y1;        ///< the block's cells in the box: [x0, x1) x [y0, y1)
    std::uint32_t masks;       ///< its first row mask in query_masks
    std::uint32_t changeable;  ///< its cells a miss could change
    bool reached;              ///< some ray reaches as far as its changeable cells
    std::ptrdiff_t rays[4];    ///< the candidate rays of those cells (two ranges of directed)
  };
  /// Per block of the grid (kBlock cells square; the last column of blocks only if whole): 1 if
  /// all its cells are saturated free, as found by a reverse query and kept by every scan since
  /// (a hit clears its block's entry; misses cannot take a cell off the lower clamp). Valid while
  /// the grid's stamp is the one recorded after the last scan (stamp_id, stamp_version).
  std::vector<std::uint8_t> block_free;
  std::uint64_t stamp_id = 0;
  std::uint64_t stamp_version = 0;
  std::vector<QueryBlock> query_blocks;  ///< blocks with changeable cells
  std::vector<std::uint32_t> query_masks;
  std::vector<ClearingRay> rays_aside;  ///< rays the reverse query does not take (walked per ray)
  /// kAuto's timed choice between the steady scans' walks (walk_chooser.h).
  WalkChooser chooser;
};

/// The two-thread clearing walk starts at this many ray cells per scan: below it, waking the
/// helper and splitting the rays costs more than it saves (a 3600-beam scan on 1000^2 has
/// ~1.8 M ray cells, a 360-beam one ~0.1 M).
constexpr std::size_t kScanThreadMinCells = 200000;

/// Integrates one batch of beams (one scan) as described above. `scratch` (optional) is reused
/// between calls to avoid an allocation per scan. With threads >= 2 and at least
/// `thread_min_cells` ray cells, pass 2 is shared with a helper thread (runShared): the grid is
/// cut into bands of rows (at block boundaries) holding about equal shares of the rays' cells,
/// each band's cells are walked by whichever thread claims the band (a ray crossing a band edge is
/// split exactly where its own walk crosses it, by the band's own task), and rays through lattice
/// corners that cross an edge are walked before the bands, on the calling thread. Each cell still
/// gets at most one update per scan and the result does not depend on the order of the updates, so
/// the grid and the statistics are the same as one thread's bit for bit (only the internal order of
/// the flag list differs).
IntegrationStats integrateBeams(LogOddsGrid& grid, const std::vector<BeamUpdate>& beams,
                                IntegrationScratch* scratch = nullptr,
                                ClearingWalk walk = ClearingWalk::kAuto, int threads = 1,
                                std::size_t thread_min_cells = kScanThreadMinCells);

struct ScanIntegratorConfig {
  /// Largest accepted obstacle / raytrace range (m): 10 km, beyond any range sensor. A larger
  /// value is a typo, and ranges of ~1e15 m put beam ends where a double cannot place them.
  static constexpr double kMaxRangeM = 1e4;

  bool marking = true;                  ///< returns mark their cell
  bool clearing = true;                 ///< beams clear the cells they cross
  double obstacle_min_range = 0.0;      ///< m: returns nearer than this do not mark
  double obstacle_max_range = 2.5;      ///< m: returns farther than this do not mark
  double raytrace_min_range = 0.0;      ///< m: clearing starts this far from the sensor
  double raytrace_max_range = 3.0;      ///< m: clearing stops this far from the sensor
  bool inf_is_valid = true;             ///< +Inf means "no return": clear, do not mark
  bool range_max_is_no_return = false;  ///< treat r == range_max as +Inf

  /// Empty if 0 <= obstacle_min_range <= obstacle_max_range <= kMaxRangeM and the same for the
  /// raytrace ranges (all finite), else the reason.
  std::string validate() const;
};

/// A LaserScan without ROS: ranges[i] is at angle angle_min + i * angle_increment (sensor frame).
struct LaserScanView {
  const float* ranges = nullptr;
  std::size_t count = 0;
  double angle_min = 0.0;
  double angle_increment = 0.0;
  double range_min = 0.0;
  double range_max = 0.0;

  /// Empty if the header fields make sense (finite angles, increment != 0, 0 <= range_min <
  /// range_max, count > 0), else the reason.
  std::string validate() const;
};

class ScanIntegrator {
 public:
  explicit ScanIntegrator(const ScanIntegratorConfig& config = {});
  const ScanIntegratorConfig& config() const { return config_; }
  /// The clearing walk (kAuto unless set; the per-ray walk is the reference for tests and
  /// benchmarks). Every choice gives the same grid bit for bit.
  void setClearingWalk(ClearingWalk walk) { walk_ = walk; }
  ClearingWalk clearingWalk() const { return walk_; }
  /// Threads of the clearing walk (1 or 2; default 2 where the machine has two cores). Dense
  /// scans only (see integrateBeams); the grid is the same bit for bit.
  void setThreads(int threads) { threads_ = std::max(1, std::min(2, threads)); }
  int threads() const { return threads_; }
  /// kAuto's timed choice of the steady scans' walk (walk_chooser.h): which ran how often.
  const WalkChooser& walkChooser() const { return integration_scratch_.chooser; }

  /// REP-117 decisions for each beam (see the file comment), with the sensor at `sensor_pose`
  /// in the grid's frame. Appends to *beams; counts ignored beams into *stats.
  void beamsFromScan(const LaserScanView& scan, const Pose2D& sensor_pose,
                     std::vector<BeamUpdate>* beams, IntegrationStats* stats) const;
  /// Same for a scan taken while the sensor moved: beam k is cast from the pose interpolated
  /// (linear in x, y; shortest arc in yaw) between the pose at the first beam and the pose at the
  /// last beam. This is the per-beam time correction of a spinning lidar on a moving robot.
  void beamsFromMovingScan(const LaserScanView& scan, const Pose2D& first_beam_pose,
                           const Pose2D& last_beam_pose, std::vector<BeamUpdate>* beams,
                           IntegrationStats* stats) const;
  /// Same for one measurement with its own sensor origin and direction (point clouds,
  /// per-beam de-skewed scans): range may be NaN / +-Inf with the scan semantics.
  void beamFromRange(double origin_x, double origin_y, double direction_rad, double range,
                     double range_min, double range_max, std::vector<BeamUpdate>* beams,
                     IntegrationStats* stats) const;
  /// Same with the direction given as its unit vector (cos, sin).
  void beamFromDirection(double origin_x, double origin_y, double cos_dir, double sin_dir,
                         double range, double range_min, double range_max,
                         std::vector<BeamUpdate>* beams, IntegrationStats* stats) const;
  /// Same for a measured point (a cloud point, in the grid's frame): a return at its horizontal
  /// distance from the origin whose hit, and the end of its clearing ray, is the point itself, so
  /// the cell it marks is the cell containing it. A point at zero horizontal range (straight above
  /// or below the sensor) is a return at range 0: it marks the sensor's own cell (if range_min
  /// and obstacle_min_range are 0) and clears nothing, as costmap_2d marks it.
  void beamToPoint(double origin_x, double origin_y, double point_x, double point_y,
                   double range_min, double range_max, std::vector<BeamUpdate>* beams,
                   IntegrationStats* stats) const;

  /// integrateBeams over beams made by the beamsFrom* calls; the beam counts of `decisions`
  /// (filled by those calls) are carried into the result.
  IntegrationStats integrate(LogOddsGrid& grid, const std::vector<BeamUpdate>& beams,
                             const IntegrationStats& decisions);
  /// beamsFromScan + integrateBeams. Throws std::invalid_argument if scan.validate() fails.
  /// Not thread-safe (reuses a scratch buffer): one integrator per thread.
  IntegrationStats integrate(LogOddsGrid& grid, const LaserScanView& scan,
                             const Pose2D& sensor_pose);

 private:
  /// The REP-117 decisions of beamFromDirection; `point` (or nullptr) is the measured point at
  /// `range` along (c, s), used as the hit and the clearing end instead of recomputing it.
  void makeBeam(double origin_x, double origin_y, double c, double s, double range,
                double range_min, double range_max, const double* point,
                std::vector<BeamUpdate>* beams, IntegrationStats* stats) const;

  ScanIntegratorConfig config_;
  std::vector<BeamUpdate> scratch_;
  IntegrationScratch integration_scratch_;
  ClearingWalk walk_ = ClearingWalk::kAuto;
  int threads_ = std::thread::hardware_concurrency() >= 2 ? 2 : 1;
};

}  // namespace downstream_perception
