#pragma once
// The one Eigen-aware near-comparison for tests: prints both sides and the worst entry.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace whirl::test {

/// Succeeds when |a - b| <= abs_tol + rel_tol * max(|a|, |b|) entry-wise.
template <typename A, typename B>
::testing::AssertionResult AllNear(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b,
                                   double rel_tol, double abs_tol = 0.0) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) {
    return ::testing::AssertionFailure() << "shape " << a.rows() << "x" << a.cols() << " vs "
                                         << b.rows() << "x" << b.cols();
  }
  double worst = 0;
  Eigen::Index wr = 0, wc = 0;
  for (Eigen::Index r = 0; r < a.rows(); ++r)
    for (Eigen::Index c = 0; c < a.cols(); ++c) {
      const double x = a(r, c), y = b(r, c);
      const double excess = std::abs(x - y) / (abs_tol + rel_tol * std::max(std::abs(x), std::abs(y)) + 1e-300);
      if (!(excess <= worst)) { worst = excess; wr = r; wc = c; }
    }
  if (worst <= 1.0) return ::testing::AssertionSuccess();
  std::ostringstream ss;
  ss.precision(17);
  ss << "worst entry (" << wr << "," << wc << "): " << a(wr, wc) << " vs " << b(wr, wc)
     << " (rel_tol " << rel_tol << ", abs_tol " << abs_tol << ")\nleft:\n"
     << a << "\nright:\n" << b;
  return ::testing::AssertionFailure() << ss.str();
}

}  // namespace whirl::test
