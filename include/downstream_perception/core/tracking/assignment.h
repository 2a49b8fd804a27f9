// Global assignment (rectangular linear assignment, the Hungarian method with potentials and
// shortest augmenting paths, O(n^2 m)), with gating: forbidden pairs are never assigned.
#pragma once

#include <Eigen/Core>

#include <limits>
#include <vector>

namespace downstream_perception {

/// Pairs with cost >= kForbidden (or non-finite) may not be assigned.
constexpr double kForbidden = std::numeric_limits<double>::infinity();

/// Minimum-cost assignment of rows to columns of `cost` (rows x cols, any shape). Returns, per
/// row, the assigned column or -1.
///
/// `unmatched_pair_cost` is what leaving a row and a column unassigned costs, against taking
/// their pair. Infinite (the default): among all assignments the solver first maximises the
/// number of allowed pairs, then minimises their total cost. Finite (L): it minimises the sum of
/// (cost - L) over the pairs it takes, so a pair is taken only where it beats leaving both
/// unassigned and pairs costing L or more never are (lap.lapjv with cost_limit L, as ByteTrack
/// calls it): one good pair is not traded for two poor ones.
std::vector<int> solveAssignment(const Eigen::MatrixXd& cost,
                                 double unmatched_pair_cost = kForbidden);

/// An allowed pair of a sparse cost matrix.
struct CostEntry {
  int row = 0;
  int col = 0;
  double cost = 0.0;
};

/// The same for a sparse matrix: only the listed pairs are allowed (each pair at most once).
/// Work grows with the pairs and the size of the groups they link, not with rows x cols.
std::vector<int> solveAssignment(int rows, int cols, const std::vector<CostEntry>& entries,
                                 double unmatched_pair_cost = kForbidden);

}  // namespace downstream_perception
