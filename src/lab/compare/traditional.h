#pragma once
// The traditional empirical compensation: the stand-in for a factory's experience rule that the
// model-based compensation is compared against (the "传统的经验补偿法" of Li, Ma and Jiang).
//
// What it is. A shop without a model keeps, per machine, an experience table keyed by the screw's
// diameter class: "screws of about this diameter grow by about P um once the cut has warmed up",
// plus one ramp-in time T per machine: "the growth builds up over about T s". For every screw in a
// class it programs the same correction, one linear 840D segment and a hold:
//
//   c(t) = P_class * min(1, t / T)       um, t from the start of the cut
//
//   P_class = mean plateau elongation (max_elongation_um) of the past screws of that diameter class
//   T       = mean settle time (settle_time_s) of all past screws of the machine
//
// Diameter classes: the nominal diameters of ISO 3408-2 in the training range (50, 63, 80, 100 mm);
// a screw belongs to the nearest nominal diameter on a log scale (boundaries at the geometric
// means: 56.1, 71.0, 89.4 mm). A class without past screws falls back to the mean of all of them.
//
// Why it is a fair stand-in. (1) A constant offset does not change the lead (all metrics are
// offset-free), so "no transient, one fixed value" would be the same as no compensation; a real
// rule must ramp in, and one slope segment is the simplest thing an operator types into SD43900/
// SD43910/SD43920. (2) It is computed from the same history the model is trained on (the training
// table, i.e. what the shop measured on past screws), never from the truth of the screw being cut.
// (3) It is right on average for its class: it captures the dominant diameter effect and the mean
// time scale; what it cannot know is what the model adds: the effect of hardness, lead, raceway
// radius and cutting speed on the plateau and the settle time, and the curved (arctangent) rise.
// The history gives three baselines besides `none`, all from the same table:
//   ramp         the rule above (kept for continuity with earlier figures);
//   traditional  per class the mean past CURVE: class plateau P_class and class settle time
//                T_class (mean settle_time_s of the class) with the same arctangent shape the model
//                uses, planned like the model: the best experience rule a shop can keep without a
//                model. Fair: it uses only what the shop has measured and the curve shape anybody
//                can fit to one recorded curve; it lacks only the four inputs besides diameter.
//   regression   a least-squares log-linear model of each feature on the five inputs:
//                ln y = b0 + sum_i b_i ln x_i (6 coefficients per output), same history, same
//                curve and plan. Fair: the strongest cheap statistical baseline (power law, the
//                form the physics suggests: L ~ q / v_f, t_s ~ a / v_f^2); it is what a process
//                engineer with a spreadsheet would fit before training a network.
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "compare/history_rules.h"
#include "core/process.h"

namespace whirl::compare {

struct ExperienceRuleOptions {
  /// Nominal diameters of the classes, mm, strictly increasing (ISO 3408-2 series in the paper's
  /// training range 50-100 mm).
  std::vector<double> class_diameters_mm = {50, 63, 80, 100};
};

struct ExperienceClass {
  double nominal_diameter_mm = 0;
  double lower_mm = 0;    ///< class covers (lower_mm, upper_mm]; 0 for the first class
  double upper_mm = 0;    ///< 1e9 for the last class
  double plateau_um = 0;  ///< P_class, um
  double settle_time_s = 0;  ///< T_class: mean settle time of the class, s (traditional)
  int screws = 0;         ///< past screws behind P_class (0 = fell back to the machine mean)
};

/// ln y_k = coef_k(0) + sum_i coef_k(i + 1) ln x_i, k = max elongation, settle time.
struct LogLinearFeatures {
  std::array<std::array<double, ProcessInputs::kCount + 1>, 2> coef{};
  Features Predict(const ProcessInputs& inputs) const;
};

/// Least squares on the logs of a history table (InputError: fewer than 6 rows, a non-positive
/// input or target, or a singular design, e.g. a constant column).
LogLinearFeatures FitLogLinear(const ProcessTable& history);

/// The leave-one-out score (compare/history_rules.h) of the regression: each past screw predicted
/// by the fit of the others. NaN with fewer than 8 past screws (7 left for 6 coefficients).
double RegressionLeaveOneOutError(const ProcessTable& history);

struct ExperienceRule {
  std::vector<ExperienceClass> classes;
  double ramp_time_s = 0;         ///< T, s
  double machine_plateau_um = 0;  ///< mean plateau over all past screws, um
  std::string source;             ///< where the history came from (file name)
  /// The regression baseline from the same history; `has_regression` false when the history is
  /// too small for it (fewer than 6 rows).
  LogLinearFeatures regression;
  bool has_regression = false;
  std::string regression_error;  ///< why there is no regression baseline
  /// traditional: (P_class, T_class) of the screw's class.
  Features ClassFeatures(double diameter_mm) const;
  /// The other history rules (compare/history_rules.h) and the leave-one-out choice of the
  /// strongest one; `has_choice` false with fewer than 2 past screws (the class rule is used).
  ExperienceTable table;
  NearestScrews nearest;
  TraditionalChoice choice;
  bool has_choice = false;
  /// The same leave-one-out score (compare/history_rules.h) of the ramp rule and of the
  /// regression (refitted without each past screw): what the report's +-1 sd bands of ramp and
  /// regression are made from. NaN when it cannot be computed (ramp: fewer than 2 past screws;
  /// regression: no regression, or fewer than 8 past screws).
  double ramp_loo_relative_error = NAN;
  double regression_loo_relative_error = NAN;
  /// Features of one history rule for a screw.
  Features HistoryFeatures(HistoryRule r, const ProcessInputs& inputs) const;
  /// Features of the strongest history rule (choice.chosen): the headline "traditional".
  Features TraditionalFeatures(const ProcessInputs& inputs) const;

  /// The class of a screw of that diameter.
  const ExperienceClass& ClassFor(double diameter_mm) const;
  /// c(t) = P_class * min(1, t / T), um; 0 for t <= 0.
  double CompensationUm(double diameter_mm, double t_s) const;
};

/// Builds the rule from past screws (a process table with targets, e.g. the training table).
/// InputError: no targets, no rows, class diameters not strictly increasing or not positive.
ExperienceRule BuildExperienceRule(const ProcessTable& history,
                                   const ExperienceRuleOptions& options = {});

void to_json(nlohmann::json& j, const ExperienceRule& rule);

}  // namespace whirl::compare
