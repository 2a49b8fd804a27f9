// Global assignment (rectangular linear assignment, the Hungarian method with potentials and
// shortest augmenting paths, O(n^2 m)), with gating: forbidden pairs are never assigned.
#pragma once

#include <Eigen/Core>

#include <limits>
#include <vector>

namespace downstream_perception {

/// Pairs with cost >= kForbidden (or non-finite) may not be assigned.
constexpr double kForbidden = std::numeric_limits<double>::infinity();

/// Minimum-cost assignment of rows to columns of `cost` (rows x cols, any shape). Among all
/// assignments it first maximises the number of allowed pairs, then minimises their total cost.
/// Returns, per row, the assigned column or -1.
std::vector<int> solveAssignment(const Eigen::MatrixXd& cost);

/// An allowed pair of a sparse cost matrix.
struct CostEntry {
  int row = 0;
  int col = 0;
  double cost = 0.0;
};

/// The same for a sparse matrix: only the listed pairs are allowed (each pair at most once).
/// Work grows with the pairs and the size of the groups they link, not with rows x cols.
std::vector<int> solveAssignment(int rows, int cols, const std::vector<CostEntry>& entries);

}  // namespace downstream_perception
