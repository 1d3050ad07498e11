#include "physics/solver/lcp.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace rigid_body_sim::physics {
namespace {

constexpr double kPivotTolerance = 1e-12;

// Refines a pivoting solution: with the active set S = {i : f_i > 0} fixed,
// solve A_SS f_S = -b_S directly. Kept only if it is at least as good.
void RefineActiveSet(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, LcpSolution* solution) {
  const int n = static_cast<int>(b.size());
  std::vector<int> active;
  for (int i = 0; i < n; ++i) {
    if (solution->f[i] > 0.0) active.push_back(i);
  }
  if (active.empty()) return;
  const int m = static_cast<int>(active.size());
  Eigen::MatrixXd a_active(m, m);
  Eigen::VectorXd b_active(m);
  for (int r = 0; r < m; ++r) {
    b_active[r] = b[active[r]];
    for (int c = 0; c < m; ++c) a_active(r, c) = a(active[r], active[c]);
  }
  const Eigen::VectorXd f_active = a_active.colPivHouseholderQr().solve(-b_active);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  for (int r = 0; r < m; ++r) f[active[r]] = std::max(0.0, f_active[r]);
  if (LcpViolation(a, b, f) <= LcpViolation(a, b, solution->f)) {
    solution->f = f;
    solution->w = a * f + b;
  }
}

}  // namespace

double LcpViolation(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, const Eigen::VectorXd& f) {
  const Eigen::VectorXd w = a * f + b;
  double violation = 0.0;
  for (int i = 0; i < f.size(); ++i) {
    violation = std::max({violation, -f[i], -w[i], std::abs(f[i] * w[i])});
  }
  return violation;
}

// Lemke's method (Cottle, Pang & Stone, "The Linear Complementarity Problem",
// 4.4). The tableau holds  I w - A f - d z0 = b  in the columns
// [w_0..w_{n-1}, f_0..f_{n-1}, z0]. Start with z0 = -min b, making w >= 0;
// then repeatedly bring in the complement of the variable that just left,
// choosing the leaving row by the minimum-ratio test, until z0 leaves.
Result<LcpSolution> SolveLcpLemke(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) {
  const int n = static_cast<int>(b.size());
  assert(a.rows() == n && a.cols() == n);
  LcpSolution solution;
  solution.f = Eigen::VectorXd::Zero(n);
  if (!a.allFinite() || !b.allFinite()) return Status::Error("LCP data is not finite");
  if (n == 0 || b.minCoeff() >= 0.0) {
    solution.w = b;
    return solution;
  }
  const int z0_column = 2 * n;
  Eigen::MatrixXd tableau(n, 2 * n + 1);
  tableau.leftCols(n).setIdentity();
  tableau.middleCols(n, n) = -a;
  tableau.col(z0_column).setConstant(-1.0);
  Eigen::VectorXd rhs = b;
  std::vector<int> basis(n);
  for (int i = 0; i < n; ++i) basis[i] = i;

  auto pivot = [&](int row, int column) {
    const double scale = 1.0 / tableau(row, column);
    tableau.row(row) *= scale;
    rhs[row] *= scale;
    for (int i = 0; i < n; ++i) {
      if (i == row) continue;
      const double factor = tableau(i, column);
      if (factor == 0.0) continue;
      tableau.row(i) -= factor * tableau.row(row);
      rhs[i] -= factor * rhs[row];
    }
    basis[row] = column;
  };

  int row;
  b.minCoeff(&row);
  int leaving = basis[row];
  pivot(row, z0_column);
  solution.pivots = 1;
  const int max_pivots = 50 * (n + 1);
  while (solution.pivots < max_pivots) {
    const int entering = leaving < n ? leaving + n : leaving - n;
    int best_row = -1;
    double best_ratio = std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) {
      const double coefficient = tableau(i, entering);
      if (coefficient <= kPivotTolerance) continue;
      const double ratio = rhs[i] / coefficient;
      // On a tie, let z0 leave: that ends the pivoting with a solution.
      const bool tie = std::abs(ratio - best_ratio) <= kPivotTolerance * (1.0 + std::abs(ratio));
      if (ratio < best_ratio && !tie) {
        best_ratio = ratio;
        best_row = i;
      } else if (tie && basis[i] == z0_column) {
        best_row = i;
      }
    }
    if (best_row < 0) {
      return Status::Error("LCP has no solution: Lemke's method ended on a secondary ray after " +
                           std::to_string(solution.pivots) + " pivots");
    }
    leaving = basis[best_row];
    pivot(best_row, entering);
    ++solution.pivots;
    if (leaving == z0_column) break;
  }
  if (solution.pivots >= max_pivots) {
    return Status::Error("LCP pivoting did not finish within " + std::to_string(max_pivots) +
                         " pivots");
  }
  for (int i = 0; i < n; ++i) {
    if (basis[i] >= n && basis[i] < 2 * n) solution.f[basis[i] - n] = std::max(0.0, rhs[i]);
  }
  solution.w = a * solution.f + b;
  RefineActiveSet(a, b, &solution);
  return solution;
}

int SolveLcpPgs(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, const PgsSettings& settings,
                Eigen::VectorXd* f) {
  const int n = static_cast<int>(b.size());
  assert(f != nullptr && f->size() == n);
  int sweep = 0;
  while (sweep < settings.max_iterations) {
    ++sweep;
    double largest_change = 0.0;
    for (int i = 0; i < n; ++i) {
      assert(a(i, i) > 0.0);
      const double residual = b[i] + a.row(i).dot(*f);
      const double updated = std::max(0.0, (*f)[i] - residual / a(i, i));
      largest_change = std::max(largest_change, std::abs(updated - (*f)[i]));
      (*f)[i] = updated;
    }
    if (largest_change <= settings.tolerance) break;
  }
  return sweep;
}

}  // namespace rigid_body_sim::physics
