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

}  // namespace downstream_perception
