#include "downstream_perception/core/tracking/assignment.h"

#include <algorithm>
#include <cmath>

namespace downstream_perception {

namespace {

// Square-free Hungarian (Kuhn-Munkres with potentials) for n <= m: a[1..n][1..m], returns for
// each row its column. Classic shortest-augmenting-path form (one Dijkstra-like pass per row).
std::vector<int> hungarian(const std::vector<std::vector<double>>& a, int n, int m) {
  const double inf = std::numeric_limits<double>::max();
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0), minv(m + 1);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);
  std::vector<char> used(m + 1);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::fill(minv.begin(), minv.end(), inf);
    std::fill(used.begin(), used.end(), 0);
    do {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double cur = a[i0][j] - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> row_to_col(n, -1);
  for (int j = 1; j <= m; ++j) {
    if (p[j] != 0) row_to_col[p[j] - 1] = j - 1;
  }
  return row_to_col;
}

}  // namespace

namespace {
std::vector<int> solveDense(const Eigen::MatrixXd& cost, double unmatched_pair_cost);

// A pair the solver may take: finite, and cheaper than leaving its row and column unassigned.
bool allowed(double cost, double unmatched_pair_cost) {
  return std::isfinite(cost) && cost < unmatched_pair_cost;
}

int findRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}
}  // namespace

std::vector<int> solveAssignment(const Eigen::MatrixXd& cost, double unmatched_pair_cost) {
  std::vector<CostEntry> entries;
  for (int r = 0; r < cost.rows(); ++r) {
    for (int c = 0; c < cost.cols(); ++c) {
      if (std::isfinite(cost(r, c))) entries.push_back({r, c, cost(r, c)});
    }
  }
  return solveAssignment(static_cast<int>(cost.rows()), static_cast<int>(cost.cols()), entries,
                         unmatched_pair_cost);
}

std::vector<int> solveAssignment(int rows, int cols, const std::vector<CostEntry>& entries,
                                 double unmatched_pair_cost) {
  // Gating leaves the matrix sparse: rows and columns linked by allowed pairs form independent
  // groups (objects far apart never compete), and each is solved on its own.
  std::vector<int> result(rows, -1);
  std::vector<int> parent(rows + cols);
  for (int i = 0; i < rows + cols; ++i) parent[i] = i;
  for (const CostEntry& e : entries) {
    if (e.row < 0 || e.row >= rows || e.col < 0 || e.col >= cols ||
        !allowed(e.cost, unmatched_pair_cost)) {
      continue;
    }
    const int a = findRoot(parent, e.row);
    const int b = findRoot(parent, rows + e.col);
    if (a != b) parent[a] = b;
  }
  // Group members in index order, and each group's pairs.
  std::vector<int> group_of(rows + cols);
  std::vector<int> local(rows + cols, -1);
  std::vector<int> group_rows_count(rows + cols, 0), group_cols_count(rows + cols, 0);
  for (int i = 0; i < rows + cols; ++i) {
    group_of[i] = findRoot(parent, i);
    if (i < rows) {
      local[i] = group_rows_count[group_of[i]]++;
    } else {
      local[i] = group_cols_count[group_of[i]]++;
    }
  }
  std::vector<std::vector<CostEntry>> group_entries(rows + cols);
  for (const CostEntry& e : entries) {
    if (e.row < 0 || e.row >= rows || e.col < 0 || e.col >= cols ||
        !allowed(e.cost, unmatched_pair_cost)) {
      continue;
    }
    group_entries[group_of[e.row]].push_back({local[e.row], local[rows + e.col], e.cost});
  }
  std::vector<std::vector<int>> members_rows(rows + cols), members_cols(rows + cols);
  for (int r = 0; r < rows; ++r) members_rows[group_of[r]].push_back(r);
  for (int c = 0; c < cols; ++c) members_cols[group_of[rows + c]].push_back(c);
  for (int g = 0; g < rows + cols; ++g) {
    const auto& gr = members_rows[g];
    const auto& gc = members_cols[g];
    if (gr.empty() || gc.empty()) continue;
    if (gr.size() == 1 && gc.size() == 1) {
      result[gr[0]] = gc[0];  // linked, hence allowed
      continue;
    }
    Eigen::MatrixXd sub = Eigen::MatrixXd::Constant(
        static_cast<Eigen::Index>(gr.size()), static_cast<Eigen::Index>(gc.size()), kForbidden);
    for (const CostEntry& e : group_entries[g]) sub(e.row, e.col) = e.cost;
    const std::vector<int> match = solveDense(sub, unmatched_pair_cost);
    for (std::size_t i = 0; i < gr.size(); ++i) {
      if (match[i] >= 0) result[gr[i]] = gc[match[i]];
    }
  }
  return result;
}

namespace {

std::vector<int> solveDense(const Eigen::MatrixXd& cost, double unmatched_pair_cost) {
  const int rows = static_cast<int>(cost.rows());
  const int cols = static_cast<int>(cost.cols());
  std::vector<int> result(rows, -1);
  if (rows == 0 || cols == 0) return result;
  const bool limited = std::isfinite(unmatched_pair_cost);
  // Limited: an allowed pair costs (cost - limit) < 0 and a forbidden one 0, as much as leaving
  // its row and column unassigned; the solver's complete assignment minus its forbidden pairs
  // is then the best set of allowed pairs, however many. Unlimited: a forbidden pair costs more
  // than any set of allowed pairs together, so the optimum uses as few of them as possible
  // (maximum cardinality first). Forbidden pairs are dropped afterwards either way.
  double max_allowed = 0.0;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double x = cost(r, c);
      if (std::isfinite(x)) max_allowed = std::max(max_allowed, std::abs(x));
    }
  }
  const double big = (max_allowed + 1.0) * (std::min(rows, cols) + 1) * 2.0;
  const bool transpose = rows > cols;  // the solver wants n <= m
  const int n = transpose ? cols : rows;
  const int m = transpose ? rows : cols;
  std::vector<std::vector<double>> a(n + 1, std::vector<double>(m + 1, 0.0));
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      const double x = transpose ? cost(j, i) : cost(i, j);
      if (limited) {
        a[i + 1][j + 1] = allowed(x, unmatched_pair_cost) ? x - unmatched_pair_cost : 0.0;
      } else {
        a[i + 1][j + 1] = std::isfinite(x) ? x : big;
      }
    }
  }
  const std::vector<int> match = hungarian(a, n, m);
  for (int i = 0; i < n; ++i) {
    const int j = match[i];
    if (j < 0) continue;
    const double x = transpose ? cost(j, i) : cost(i, j);
    if (!allowed(x, unmatched_pair_cost)) continue;
    if (transpose) {
      result[j] = i;
    } else {
      result[i] = j;
    }
  }
  return result;
}

}  // namespace

}  // namespace downstream_perception
