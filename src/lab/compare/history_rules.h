#pragma once
// Experience rules a shop keeps from its past screws, beside the diameter-class mean of
// compare/traditional.h: each maps a new screw's five process inputs to the features (plateau
// elongation, settle time) that the arctangent curve and the 840D plan are built from, exactly as
// the network's features are. All are computed from the history table alone (the measured targets
// of past screws), never from the screw being cut.
//
//   class    the diameter-class means (traditional.h, ExperienceRule::ClassFeatures).
//   table    an experience table keyed on ball size (raceway radius), cutting speed and lead:
//            3 classes each, split at the geometric thirds of the training ranges (raceway radius
//            3-10 mm: 4.48 / 6.69 mm; cutting speed 150-210 m/min: 167.8 / 187.7 m/min; lead
//            6-16 mm: 8.32 / 11.54 mm), 27 cells; a cell's value is the mean of its past screws;
//            an empty cell takes the mean of the non-empty cells at the smallest Chebyshev
//            distance in cell indices. A class upper edge belongs to the lower class.
//   nearest  the mean features of the k = 3 past screws nearest in the five inputs, each input
//            scaled by its range over the history (Euclidean; ties by table order).
// The strongest of them ("traditional" in headlines) is chosen on the history by leave-one-out:
// each past screw predicted by the rule built without it, scored by the mean relative error of
// both features, (|P - P_r| / P_r + |T - T_r| / T_r) / 2, averaged over the screws; the lowest
// wins (ties: class, then table, then nearest). The test screws never enter the choice.
#include <array>
#include <string>
#include <vector>

#include "core/process.h"

namespace whirl::compare {

enum class HistoryRule { kClass, kTable, kNearest };
inline constexpr std::size_t kHistoryRuleCount = 3;
std::string ToString(HistoryRule r);  ///< "class", "table", "nearest"

struct ExperienceTableOptions {
  std::array<double, 2> raceway_edges_mm = {4.48, 6.69};
  std::array<double, 2> speed_edges_m_min = {167.8, 187.7};
  std::array<double, 2> lead_edges_mm = {8.32, 11.54};
};

struct ExperienceTable {
  ExperienceTableOptions options;
  /// Per cell (index 9 radius + 3 speed + lead class): sum of the features and the count.
  std::array<Features, 27> sum{};
  std::array<int, 27> count{};
  /// Cell index of a screw's inputs (0..26).
  int CellOf(const ProcessInputs& inputs) const;
  /// The cell's mean, or the mean of the nearest non-empty cells' means (see the header comment).
  Features Predict(const ProcessInputs& inputs) const;
};

/// InputError: no rows, no targets, or edges not increasing.
ExperienceTable BuildExperienceTable(const ProcessTable& history,
                                     const ExperienceTableOptions& options = {});

struct NearestScrews {
  std::vector<ProcessInputs> inputs;
  std::vector<Features> targets;
  std::array<double, ProcessInputs::kCount> scale{};  ///< range of each input (1 when constant)
  /// Mean features of the k nearest past screws (k clamped to the history size); `skip` (>= 0)
  /// leaves that history row out (leave-one-out).
  Features Predict(const ProcessInputs& q, int k = 3, int skip = -1) const;
};

/// InputError: no rows or no targets.
NearestScrews BuildNearestScrews(const ProcessTable& history);

/// The leave-one-out score of one prediction (header comment): the mean relative error of both
/// features, (|P - P_r| / P_r + |T - T_r| / T_r) / 2, against the measured `truth`.
double LeaveOneOutRelativeError(const Features& predicted, const Features& truth);

struct TraditionalChoice {
  HistoryRule chosen = HistoryRule::kClass;
  std::array<double, kHistoryRuleCount> loo_relative_error{};  ///< HistoryRule order
};

struct ExperienceRule;
/// The leave-one-out choice (header comment) among the class rule, the table and the nearest
/// screws, all built from `history`. InputError with fewer than 2 past screws.
TraditionalChoice ChooseTraditional(const ProcessTable& history, const ExperienceRule& class_rule,
                                    const ExperienceTable& table, const NearestScrews& nearest);

/// The same leave-one-out score of the ramp rule (compare/traditional.h: the class plateau
/// without the screw, the machine's mean settle time without it as the ramp time). InputError
/// with fewer than 2 past screws.
double RampLeaveOneOutError(const ProcessTable& history, const ExperienceRule& class_rule);

}  // namespace whirl::compare
