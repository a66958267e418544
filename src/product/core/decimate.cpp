#include "core/decimate.h"

#include <algorithm>
#include <cmath>

namespace whirl {

M4Decimator::M4Decimator(int series, double x0, double x1, int columns, int carried)
    : series_(std::max(0, series)), width_(series_ + std::max(0, carried)), x0_(x0), x1_(x1), columns_(std::max(1, columns)),
      min_(static_cast<std::size_t>(series_)), max_(static_cast<std::size_t>(series_)) {}

void M4Decimator::Consider(Candidate* c, long long row, double x, const double* values) {
  c->row = row;
  c->x = x;
  c->values.assign(values, values + width_);
}

void M4Decimator::Add(long long row, double x, const double* values) {
  const double span = x1_ - x0_;
  long long column = 0;
  if (span > 0 && std::isfinite(x))
    column = std::clamp(static_cast<long long>((x - x0_) / span * columns_), 0LL,
                        static_cast<long long>(columns_) - 1);
  if (column != column_) {
    Emit();
    column_ = column;
    Consider(&first_, row, x, values);
  }
  Consider(&last_, row, x, values);
  for (int s = 0; s < series_; ++s) {
    const double v = values[s];
    if (std::isnan(v)) continue;
    Candidate& lo = min_[static_cast<std::size_t>(s)];
    Candidate& hi = max_[static_cast<std::size_t>(s)];
    if (lo.row < 0 || v < lo.values[static_cast<std::size_t>(s)]) Consider(&lo, row, x, values);
    if (hi.row < 0 || v > hi.values[static_cast<std::size_t>(s)]) Consider(&hi, row, x, values);
  }
}

void M4Decimator::Emit() {
  if (first_.row < 0) return;
  std::vector<const Candidate*> kept{&first_, &last_};
  for (int s = 0; s < series_; ++s) {
    if (min_[static_cast<std::size_t>(s)].row >= 0) kept.push_back(&min_[static_cast<std::size_t>(s)]);
    if (max_[static_cast<std::size_t>(s)].row >= 0) kept.push_back(&max_[static_cast<std::size_t>(s)]);
  }
  std::sort(kept.begin(), kept.end(),
            [](const Candidate* a, const Candidate* b) { return a->row < b->row; });
  long long previous = -1;
  for (const Candidate* c : kept) {
    if (c->row == previous) continue;
    previous = c->row;
    rows_.push_back(c->row);
    xs_.push_back(c->x);
    values_.insert(values_.end(), c->values.begin(), c->values.end());
  }
  first_.row = last_.row = -1;
  for (auto& c : min_) c.row = -1;
  for (auto& c : max_) c.row = -1;
}

const std::vector<long long>& M4Decimator::Finish() {
  Emit();
  column_ = -1;
  return rows_;
}

std::vector<std::size_t> M4Rows(const std::vector<double>& x,
                                const std::vector<std::vector<double>>& series, int columns) {
  if (x.empty()) return {};
  M4Decimator d(static_cast<int>(series.size()), x.front(), x.back(), columns);
  std::vector<double> row(series.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (std::size_t s = 0; s < series.size(); ++s) row[s] = series[s][i];
    d.Add(static_cast<long long>(i), x[i], row.data());
  }
  std::vector<std::size_t> out;
  for (long long r : d.Finish()) out.push_back(static_cast<std::size_t>(r));
  return out;
}

}  // namespace whirl
