#pragma once
// Every use a command makes of a loaded machine profile, with the smallest plan and drift models
// it could meet: the plan program (plain and combined), its reset program and PLC table, the
// drift program (both temperature references, with the slope model when the profile has the
// slope object), its reset program and PLC table. A profile that LoadMachineProfile accepts must
// pass all of them (one validation for every command): shared by the unit tests and the fuzz
// harness (tests/fuzz/fuzz_machine_profile.cpp). Throws whatever a use throws; no gtest here.
#include <Eigen/Dense>
#include <string>

#include "drift/model.h"
#include "interp/drift_action.h"
#include "interp/machine_profile.h"
#include "interp/sinumerik.h"

namespace whirl::interp::testing {

// A one-sensor static model (mlr) of `error_column` on `sensor`.
inline drift::DriftModel OneSensorModel(const std::string& sensor, const std::string& error_column) {
  drift::DriftModel m;
  m.kind = drift::ModelKind::kMlr;
  m.error_column = error_column;
  m.sensors = {sensor};
  m.reference_C = Eigen::VectorXd::Constant(1, 20.0);
  m.features.push_back({sensor, 0.0});
  m.feature_min = Eigen::VectorXd::Constant(1, -5.0);
  m.feature_max = Eigen::VectorXd::Constant(1, 5.0);
  m.linear.coefficients = Eigen::Vector2d(0.5, 2.0);
  m.linear.covariance = Eigen::MatrixXd::Identity(2, 2) * 0.01;
  m.Validate();
  return m;
}

// The smallest plan a profile meets: a flat curve, one segment.
inline CompensationPlan SmallestPlan(const PlanOptions& options) {
  return BuildPlan([](double) { return 0.0; }, 1.0, 100.0, options);
}

inline void PlanUses(const PlanOptions& options) {
  const CompensationPlan plan = SmallestPlan(options);
  (void)FormatNcProgram(plan);
  (void)FormatNcResetProgram(options);
  (void)FormatPlcCsv(plan);
}

inline void UseProfileEverywhere(const MachineProfile& profile) {
  PlanOptions plain;
  profile.ApplyTo(plain);
  PlanUses(plain);
  if (!profile.drift) return;
  DriftActionOptions d = profile.DriftOptions();
  if (d.workpiece_k0_param >= 0) {
    PlanOptions combined;
    profile.ApplyCombinedTo(combined);
    PlanUses(combined);
  }
  if (d.inputs.empty()) return;  // no analog input mapped: drift nc needs --input
  const std::string sensor = d.inputs.begin()->first;
  const drift::DriftModel m = OneSensorModel(sensor, "offset_um");
  const drift::DriftModel g = OneSensorModel(sensor, "zscrew_per_1000_um");
  for (DriftReference reference : {DriftReference::kModel, DriftReference::kStart}) {
    d.reference = reference;
    (void)FormatDriftNcProgram(m, d);
    (void)FormatDriftPlcCsv(m, d);
    if (d.has_slope) {
      (void)FormatDriftNcProgram(m, d, "", &g);
      (void)FormatDriftPlcCsv(m, d, &g);
    }
  }
  (void)FormatDriftNcResetProgram(d);
}

}  // namespace whirl::interp::testing
