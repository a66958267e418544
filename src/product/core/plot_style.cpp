#include "core/plot_style.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <stdexcept>

namespace whirl {

const std::vector<SeriesStyle>& SeriesStyles() {
  // Every strategy of the workpiece and the machine comparison has a colour of its own (Tableau
  // 10 for the workpiece comparison, Tableau 20b's dark tones for the rows only the machine
  // evaluation has); the drift methods and monitor rules reuse those colours with dash patterns
  // no strategy has, distinct within their own report. "both_shop" is drawn thicker than its
  // monitored variant, which carries open circles, so the two stay apart where they coincide.
  // One entry a line (clang-format off keeps it so, and a new strategy a one-line change).
  // clang-format off
  static const std::vector<SeriesStyle> kStyles = {
      {"measured",     "#000000", 1, 2.0},
      {"prediction",   "#1f77b4", 3, 1.5},
      {"residual",     "#d62728", 1, 1.5},
      // The strategies of the workpiece comparison (compare::kStrategies).
      {"none",         "#7f7f7f", 1, 2.0},
      {"ramp",         "#8c564b", 4, 2.0},
      {"traditional",  "#ff7f0e", 2, 2.0},
      {"regression",   "#9467bd", 5, 1.5, 4},
      {"model",        "#1f77b4", 1, 2.5},
      {"class",        "#bcbd22", 4, 1.5},
      {"table",        "#17becf", 1, 1.5},
      {"nearest",      "#e377c2", 2, 1.5},
      // The rows only the machine evaluation has (machine_eval::MachineStrategies()).
      {"workpiece",    "#393b79", 2, 2.0},
      {"warmup",       "#b8860b", 2, 1.5},
      {"schedule",     "#7b4173", 4, 1.5},
      {"lead_slope",   "#637939", 5, 1.5},
      {"machine_shop", "#843c39", 1, 1.5},
      {"both_shop",    "#2ca02c", 1, 3.5},
      {"both_shop_monitor", "#d62728", 2, 1.0, 6},
      {"both_grey",    "#e6550d", 1, 2.5},
      // The drift hold-out's methods (drift::HoldoutMethods(); "none" as above).
      {"fit",          "#1f77b4", 2, 2.0},
      {"time",         "#ff7f0e", 5, 1.5},
      {"mlr_all",      "#9467bd", 1, 1.5},
      {"mlr",          "#17becf", 2, 1.5},
      {"dynamic",      "#2ca02c", 4, 1.5},
      {"network",      "#e377c2", 1, 1.5},
      {"dynamic_extra", "#8c564b", 2, 1.5},
      // The drift monitor's update rules (drift::UpdateRule).
      {"static",       "#7f7f7f", 2, 1.5},
      {"patent",       "#ff7f0e", 1, 1.5},
      {"bayes",        "#2ca02c", 2, 1.5},
      {"offset",       "#9467bd", 4, 1.5}};
  // clang-format on
  return kStyles;
}

const SeriesStyle* FindSeriesStyle(std::string_view name) {
  for (const SeriesStyle& s : SeriesStyles())
    if (s.name == name) return &s;
  return nullptr;
}

std::string GnuplotWith(std::string_view name) {
  const SeriesStyle* s = FindSeriesStyle(name);
  const SeriesStyle fallback{name, "#aaaaaa", 3, 1.5};
  if (!s) s = &fallback;
  char buf[128];
  std::snprintf(buf, sizeof buf, "with %s lc rgb '%.*s' lw %g dt %d",
                s->point ? "linespoints" : "lines", static_cast<int>(s->colour.size()),
                s->colour.data(), s->width, s->dash);
  std::string with = buf;
  if (s->point) with += " pt " + std::to_string(s->point) + " ps 0.9 pn 40";
  return with;
}

const std::vector<std::string_view>& SeriesPalette() {
  static const std::vector<std::string_view> kPalette = {
      "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
      "#bcbd22", "#17becf", "#393b79", "#637939", "#8c6d31", "#843c39", "#7b4173", "#3182bd"};
  return kPalette;
}

std::string_view PaletteColour(std::size_t index) {
  return SeriesPalette()[index % SeriesPalette().size()];
}

std::vector<std::vector<std::size_t>> GroupSeries(const std::vector<std::string>& names,
                                                  std::size_t max_per_plot) {
  if (max_per_plot == 0) throw std::invalid_argument("GroupSeries: max_per_plot must be >= 1");
  // Groups by prefix, in order of first appearance.
  std::vector<std::vector<std::size_t>> groups;
  std::map<std::string, std::size_t> group_of;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string prefix = names[i].substr(0, names[i].find('_'));
    const auto [it, added] = group_of.emplace(prefix, groups.size());
    if (added) groups.emplace_back();
    groups[it->second].push_back(i);
  }
  std::vector<std::vector<std::size_t>> plots;
  for (const auto& group : groups) {
    for (std::size_t begin = 0; begin < group.size(); begin += max_per_plot) {
      const std::size_t end = std::min(group.size(), begin + max_per_plot);
      const std::size_t n = end - begin;
      if (plots.empty() || plots.back().size() + n > max_per_plot) plots.emplace_back();
      plots.back().insert(plots.back().end(), group.begin() + static_cast<std::ptrdiff_t>(begin),
                          group.begin() + static_cast<std::ptrdiff_t>(end));
    }
  }
  return plots;
}

}  // namespace whirl
