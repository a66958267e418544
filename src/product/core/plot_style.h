#pragma once
// How every whirl plot draws a series: one colour, one dash pattern and one line width per
// compensation strategy, drift method and monitor rule (and for the measured truth, the
// prediction and the residual), the same in the workpiece report, the machine report, the drift
// reports and the monitor report, so a dashed orange line always means "traditional" and a solid
// blue one always "model". The table is the only place a series' look is defined; tests/core
// checks that no two entries look alike; tests/machine_report checks that every name of every
// evaluation's list (compare::kStrategies, machine_eval::MachineStrategies(),
// drift::HoldoutMethods(), drift::UpdateRule) has an entry and that no two strategies of the
// workpiece and machine comparisons, and no two names of one list, share a colour.
// Colours: the Tableau 10 palette (as in matplotlib's "tab10") and the dark tones of Tableau 20b,
// black for measurements.
// Dash types are gnuplot's (1 solid, 2 dashed, 3 dotted, 4 dash-dot, 5 dash-dot-dot); point types
// gnuplot's too (4 open square, 6 open circle).
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace whirl {

struct SeriesStyle {
  std::string_view name;    ///< the series' name as the reports and CSV columns spell it
  std::string_view colour;  ///< "#rrggbb"
  int dash = 1;             ///< gnuplot dash type, 1..5
  double width = 2;         ///< line width, gnuplot units
  /// gnuplot point type marked at 40 places along the line (0: none): how a series that often
  /// coincides with a thicker one (both_shop_monitor with both_shop, regression with model) stays
  /// visible (a dash pattern vanishes on a line of many short segments).
  int point = 0;
};

/// The table: measured (truth), prediction, residual, then the strategies none, ramp,
/// traditional, regression, model, class, table, nearest (the workpiece comparison), the machine
/// evaluation's own rows workpiece, warmup, schedule, lead_slope, machine_shop, both_shop,
/// both_shop_monitor, the drift hold-out's methods fit, time, mlr_all, mlr, dynamic, network,
/// dynamic_extra and the monitor's rules static, patent, bayes, offset.
const std::vector<SeriesStyle>& SeriesStyles();

/// The entry named `name`, or nullptr when the table has none.
const SeriesStyle* FindSeriesStyle(std::string_view name);

/// The gnuplot plot style of `name`: "with lines lc rgb '#1f77b4' lw 2.5 dt 1", or with a point
/// type "with linespoints lc rgb '#d62728' lw 1 dt 1 pt 6 ps 0.9 pn 40" (pn: gnuplot >= 5.4). A
/// name without an entry gets thin grey dots (visible, and obviously not one of the table's looks).
std::string GnuplotWith(std::string_view name);

/// Sixteen well-separated colours for plots of many unnamed series (sensors), in order: Tableau
/// 10, then six dark tones of Tableau 20b/c.
const std::vector<std::string_view>& SeriesPalette();

/// The colour of the `index`-th of a set of unnamed series (a sensor's column in its log): the
/// palette's colour `index` (repeating only past its size), so one sensor has one colour in
/// every panel and figure of a report.
std::string_view PaletteColour(std::size_t index);

/// Splits `names` into plots of at most `max_per_plot` series (>= 1), keeping related series
/// together: names sharing the text before their first '_' ("bed_headstock_C", "bed_middle_C")
/// form a group, groups keep the order of their first appearance, and a plot takes whole groups
/// while they fit; a group larger than `max_per_plot` is split into runs of `max_per_plot`.
/// Returns the indices into `names` per plot; every index appears exactly once.
std::vector<std::vector<std::size_t>> GroupSeries(const std::vector<std::string>& names,
                                                  std::size_t max_per_plot);

}  // namespace whirl
