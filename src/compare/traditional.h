#pragma once
// The traditional empirical compensation: the stand-in for a factory's experience rule that the
// model-based compensation is compared against (the paper's "传统的经验补偿法", REFERENCE.md 1).
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
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

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
  int screws = 0;         ///< past screws behind P_class (0 = fell back to the machine mean)
};

struct ExperienceRule {
  std::vector<ExperienceClass> classes;
  double ramp_time_s = 0;         ///< T, s
  double machine_plateau_um = 0;  ///< mean plateau over all past screws, um
  std::string source;             ///< where the history came from (file name)

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
