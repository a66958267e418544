#pragma once
// The worst band width of a sampled curve over sliding windows of a given length: the accumulated
// error within any W millimetres (ISO 3408-3 v_300, the paper's error within any 1000 mm), used by
// the lead metrics and by the machine truth's magnitudes.
#include <vector>

namespace whirl {

/// Band width (max - min) of `values` over every window [x_i, x_i + window_mm]; returns the
/// worst. `x` strictly increasing, same size as `values`; 0 for empty or mismatched input. Every
/// sample starts one window; a window starting between samples holds a subset of the next one's.
double MaxWindowRange(const std::vector<double>& x, const std::vector<double>& values,
                      double window_mm);

}  // namespace whirl
