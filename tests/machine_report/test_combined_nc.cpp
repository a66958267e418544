// The combined 840D programs of a screw on a simulated drifting machine,
// replayed as the control runs them (tests/interp/nc_replay.h) with the screw's own virtual
// sensor log on the analog inputs: at every cycle of the cut the control applies the workpiece
// plan plus the machine's offset and Z-screw line, i.e. what the evaluation's "both" strategy
// applies (machine_eval/machine_eval.h: K(t) + G(t) (z_fixed - z(t)) / 1000, K and G the drift
// models on the log, linear between samples); the drift action is the only writer of SD43900-43920
// and the reset programs leave the control as found.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "drift/fit.h"
#include "drift/model.h"
#include "interp/nc_replay.h"
#include "machine_eval/machine_nc.h"
#include "screw/screw.h"

namespace whirl::machine_eval {
namespace {

std::string ProfilePath() {
  return std::string(WHIRL_SOURCE_DIR) + "/datasets/machines/whirling_840d.json";
}

// Linear interpolation of a column of samples taken every step_min, held after the last.
double Interp(const Eigen::VectorXd& v, double step_min, double t_s) {
  const double u = t_s / 60.0 / step_min;
  const auto k = static_cast<Eigen::Index>(std::floor(u));
  if (k + 1 >= v.size()) return v(v.size() - 1);
  const double f = u - static_cast<double>(k);
  return (1 - f) * v(k) + f * v(k + 1);
}

// The shipped profile (direction -1), or the same machine seen from an axis that runs +Z towards
// the chuck (direction +1: program coordinate -z, the fixed bearing at offset - z_fixed).
interp::MachineProfile Profile(int direction, interp::ControlDk control_dk) {
  interp::MachineProfile p = interp::LoadMachineProfile(ProfilePath());
  p.control_dk = control_dk;
  if (direction == 1) {
    p.direction = 1;
    p.drift->error_direction = 1;
    p.drift->slope_growth_direction = 1;
    p.drift->slope_fixed_end_mm =
        p.machine_offset_mm - machine::DefaultMachine().z_screw.fixed_end_mm;
  }
  return p;
}

void ReplayOneCut(int direction, interp::ControlDk control_dk) {
  SCOPED_TRACE("direction " + std::to_string(direction) + ", control_dk " +
               interp::ToString(control_dk));
  const machine::MachineConfig config = machine::DefaultMachine();
  const std::uint64_t machine_seed = 5;
  const MachineModels models = FitMachineModels(config, machine_seed, 2, drift::FitOptions{});
  const machine::MachineDay day = machine::MachineDay::Draw(config, machine_seed, 991);
  screw::Screw screw = screw::ReferenceScrew();
  screw.thread_length_mm = 1500;  // 37 min of cutting keeps the test short
  const screw::Kinematics kin = screw::ComputeKinematics(screw);
  const double feed = kin.axial_feed_mm_s, t_cut = kin.cutting_time_s;
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures({14.0, 900.0}, 4.0, 0.9);
  const interp::MachineProfile profile = Profile(direction, control_dk);
  interp::PlanOptions po;
  po.tolerance_um = 0.5;
  const CombinedPrograms p = BuildCombinedPrograms(curve, kin, screw.thread_length_mm, po, models,
                                                   day.config, profile, "test curve");

  machine::RunSpec spec;
  spec.duration_min = t_cut / 60.0 + 2 * config.sample_min;
  spec.cutting_speed_m_min = screw.process.cutting_speed_m_min;
  const drift::Run log = machine::SimulateRun(day, spec);
  const Eigen::VectorXd k_um = drift::PredictRun(models.offset_cutting, log).predicted_um;
  const Eigen::VectorXd g_um = drift::PredictRun(models.slope_cutting, log).predicted_um;

  interp::replay::Replay r;
  r.control.abs_value_mm = -0.0013;  // what the control holds before
  r.control.slope = 7e-6;
  r.control.ref_position_mm = 100.0;
  auto set_inputs = [&](double t_s) {
    for (std::size_t s = 0; s < log.sensor_names.size(); ++s) {
      const auto it = p.drift.inputs.find(log.sensor_names[s]);
      ASSERT_NE(it, p.drift.inputs.end()) << log.sensor_names[s];
      const Eigen::VectorXd col = log.temperature_C.col(static_cast<Eigen::Index>(s));
      r.control.ain[it->second.index] =
          (Interp(col, config.sample_min, t_s) - it->second.offset) / it->second.scale;
    }
  };
  set_inputs(0.0);
  ASSERT_TRUE(r.RunProgram(p.drift_nc));
  const double s = interp::SignFactor(p.plan.options.sign);
  const double z0 = kin.thread_start_position_mm, z_fixed = config.z_screw.fixed_end_mm;
  // While the plan's part program runs the axis stands 5 mm before the thread start (z0 + 5 mm:
  // the cut runs towards the chuck); every state it passes through applies the machine line
  // alone (nothing of the plan before the thread start), never a slope about a stale reference.
  const double park = interp::AxisPositionMm(p.plan.options, kin.axial_feed_mm_s, -5.0 / feed);
  const double machine0_um = k_um(0) + g_um(0) * (z_fixed - (z0 + 5.0)) / 1e3;
  double worst_start_um = 0;
  r.axis_mm = park;
  r.between_blocks = [&] {
    r.Cycle(park);
    worst_start_um =
        std::max(worst_start_um, std::abs(r.control.DkMm(park) * 1000.0 / s - machine0_um));
  };
  ASSERT_TRUE(r.RunProgram(p.plan_nc));
  r.between_blocks = nullptr;
  EXPECT_LT(worst_start_um, 1e-3);
  double worst_um = 0, largest_machine_um = 0;
  // One cycle per second: the default machine models are MLR without lags, so the cycle length
  // does not enter (lags are replayed per cycle in tests/interp/test_drift_action.cpp).
  for (double t = 0; t < t_cut; t += 1.0) {
    const double pos = interp::AxisPositionMm(p.plan.options, feed, t);
    set_inputs(t);
    r.Cycle(pos);
    const double machine_um =
        Interp(k_um, config.sample_min, t) +
        Interp(g_um, config.sample_min, t) * (z_fixed - (z0 - feed * t)) / 1e3;
    const double expected = interp::AppliedCompensationUm(p.plan, pos) + machine_um;
    worst_um = std::max(worst_um, std::abs(r.control.DkMm(pos) * 1000.0 / s - expected));
    largest_machine_um = std::max(largest_machine_um, std::abs(machine_um));
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_LT(worst_um, 1e-3);
  EXPECT_GT(largest_machine_um, 5.0);  // the machine part is not trivially zero
  // The plan never writes a setting datum itself; after the cut and both resets the control
  // holds what it held before.
  EXPECT_EQ(p.plan_nc.find("SA_TEMP_COMP"), std::string::npos);
  r.Cycle(interp::AxisPositionMm(p.plan.options, feed, t_cut) - 1.0);
  r.EndProgram();
  ASSERT_TRUE(r.RunProgram(p.plan_reset_nc));
  ASSERT_TRUE(r.RunProgram(p.drift_reset_nc));
  EXPECT_TRUE(r.actions.empty());
  EXPECT_EQ(r.control.abs_value_mm, -0.0013);
  EXPECT_EQ(r.control.slope, 7e-6);
  EXPECT_EQ(r.control.ref_position_mm, 100.0);
}

TEST(CombinedPrograms, ReplayAppliesPlanPlusMachineLineEverySecondOfTheCut) {
  for (int direction : {-1, 1})
    for (auto control_dk : {interp::ControlDk::kAdded, interp::ControlDk::kSubtracted})
      ReplayOneCut(direction, control_dk);
}

TEST(CombinedPrograms, ProfileThatDisagreesWithTheMachineIsRefused) {
  const machine::MachineConfig config = machine::DefaultMachine();
  const MachineModels models = FitMachineModels(config, 2, 1, drift::FitOptions{});
  const screw::Screw screw = screw::ReferenceScrew();
  const screw::Kinematics kin = screw::ComputeKinematics(screw);
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures({14.0, 900.0}, 4.0, 0.9);
  interp::MachineProfile profile = interp::LoadMachineProfile(ProfilePath());
  auto build = [&] {
    return BuildCombinedPrograms(curve, kin, screw.thread_length_mm, interp::PlanOptions{}, models,
                                 config, profile, "");
  };
  EXPECT_NO_THROW(build());
  profile.drift->slope_fixed_end_mm += 10.0;  // the bearing is not where the machine has it
  EXPECT_THROW(build(), InputError);
  profile = interp::LoadMachineProfile(ProfilePath());
  profile.drift->slope_growth_direction = 1;
  EXPECT_THROW(build(), InputError);
  profile = interp::LoadMachineProfile(ProfilePath());
  profile.drift->workpiece_slope_param = -1;  // the plan would keep SD43910: two writers
  EXPECT_THROW(build(), InputError);
  MachineModels none;
  EXPECT_THROW(BuildCombinedPrograms(curve, kin, screw.thread_length_mm, interp::PlanOptions{},
                                     none, config, interp::LoadMachineProfile(ProfilePath()), ""),
               InputError);
}

}  // namespace
}  // namespace whirl::machine_eval
