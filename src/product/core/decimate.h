#pragma once
// The rows of a long table kept for a line plot, the data step before any plot of a long series
// (a year of a machine's log has millions of rows; a plot is a few thousand pixels wide): M4
// aggregation (Jugel, Hübner, Bradley and Markl, "M4: A Visualization-Oriented Time Series Data
// Aggregation", PVLDB 7(10), 2014). The x range is cut into `columns` equal pixel columns; in each
// the first and the last row and, for every series, the rows of its minimum and its maximum are
// kept (rows keep all their series, so a CSV of the kept rows plots every series). A line drawn
// through the kept rows covers the same pixels in each column as one through all rows, so the
// plot looks the same, while the kept rows are at most (2 + 2 x series) x columns whatever the
// row count. NaN values are skipped in the extremes.
#include <cstddef>
#include <vector>

namespace whirl {

/// Pixel columns of the decimation: above the width of whirl's plots (1000-1100 px).
inline constexpr int kPlotColumns = 1200;

/// M4 decimation of rows that arrive in order of x (a streamed log), x within [x0, x1].
class M4Decimator {
 public:
  /// `carried` more values per row ride along with the kept rows (a prediction's standard
  /// deviation beside its line) without choosing rows: the extremes are the `series`' only.
  M4Decimator(int series, double x0, double x1, int columns = kPlotColumns, int carried = 0);
  /// Row `row` (its index in the table) at x with `series` values, then the `carried` ones.
  void Add(long long row, double x, const double* values);
  /// Ends the last column; the kept rows' indices, in order.
  const std::vector<long long>& Finish();
  const std::vector<long long>& rows() const { return rows_; }
  /// The kept rows' values, row-major (series then carried values per kept row), and their x.
  const std::vector<double>& values() const { return values_; }
  const std::vector<double>& x() const { return xs_; }

 private:
  struct Candidate {
    long long row = -1;
    double x = 0;
    std::vector<double> values;
  };
  void Consider(Candidate* c, long long row, double x, const double* values);
  void Emit();

  int series_, width_;  // width_: series_ + carried values per row
  double x0_, x1_;
  int columns_;
  long long column_ = -1;
  Candidate first_, last_;
  std::vector<Candidate> min_, max_;
  std::vector<long long> rows_;
  std::vector<double> values_, xs_;
};

/// The rows of an in-memory table to keep (M4 above): `x` ascending, `series` the columns to
/// plot (each as long as x). Indices in ascending order.
std::vector<std::size_t> M4Rows(const std::vector<double>& x,
                                const std::vector<std::vector<double>>& series,
                                int columns = kPlotColumns);

}  // namespace whirl
