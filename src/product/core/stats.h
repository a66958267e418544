#pragma once
// Small statistics shared by the modules.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace whirl {

/// Median of `v` (the mean of the two middle values for an even count). `v` must not be empty.
inline double Median(std::vector<double> v) {
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  double m = v[mid];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + mid));
  return m;
}

}  // namespace whirl
