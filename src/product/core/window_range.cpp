#include "core/window_range.h"

#include <algorithm>
#include <cmath>
#include <deque>

namespace whirl {

double MaxWindowRange(const std::vector<double>& x, const std::vector<double>& values,
                      double window_mm) {
  if (x.size() != values.size() || x.empty()) return 0.0;
  // Tolerance so that a window of exactly W between two grid samples holds both ends.
  const double slack = 1e-9 * std::max(window_mm, std::abs(x.back()));
  // Sliding window [x_i, x_i + W] with monotonic deques of indices for max and min.
  std::deque<std::size_t> max_q, min_q;
  std::size_t j = 0;  // next index to push
  double worst = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    while (j < x.size() && x[j] <= x[i] + window_mm + slack) {
      while (!max_q.empty() && values[max_q.back()] <= values[j]) max_q.pop_back();
      max_q.push_back(j);
      while (!min_q.empty() && values[min_q.back()] >= values[j]) min_q.pop_back();
      min_q.push_back(j);
      ++j;
    }
    while (max_q.front() < i) max_q.pop_front();
    while (min_q.front() < i) min_q.pop_front();
    worst = std::max(worst, values[max_q.front()] - values[min_q.front()]);
    if (j == x.size()) break;  // later windows hold subsets of this one
  }
  return worst;
}

}  // namespace whirl
