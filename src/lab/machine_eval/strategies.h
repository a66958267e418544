#pragma once
// Causal application of a machine drift model, as the control runs it: the model is evaluated at
// every sample of the control's log (drift/joint.h JointEvaluator: sensors and duty signals of
// that sample only), and the compensation at time t is the value of the latest sample at or
// before t (zero-order hold): no interpolation towards a sample the control does not have yet.
// The tool position z(t) is the axis's own (known continuously: no look-ahead). The compensation
// line is the 840D form c_m(t) = K0_k + G_k (z_ref - z(t)) / 1000, k = the latest sample <= t.
#include <functional>
#include <vector>

#include "compare/cut.h"
#include "drift/grey_box.h"
#include "drift/joint.h"
#include "drift/run_file.h"

namespace whirl::machine_eval {

/// Values held from each sample time on (time_min ascending); before the first sample the first
/// value (the power-on state).
struct HeldSamples {
  std::vector<double> time_min, k0_um, slope_um_per_1000;
  /// The grey box's blank term g_b (B - 20) of each sample (drift/grey_box.h), latched at the
  /// cut start and added to the slope for the whole cut; empty: no blank term.
  std::vector<double> blank_slope_um_per_1000;
  /// Index of the latest sample with time <= t_min (0 before the first).
  std::size_t IndexAt(double t_min) const;
};

/// The model stepped through the log (the first row is the day's power-on).
HeldSamples RunCausally(const drift::JointDriftModel& model, const drift::Run& log);
/// The grey box stepped through the log, with its blank term per sample (latched at the cut
/// start by CausalMachineLine).
HeldSamples RunCausally(const drift::GreyBoxModel& model, const drift::Run& log);

/// `slope_model`'s samples (slope and blank term) with the offset K0 = (1 - share) x its own +
/// share x `offset_model`'s, sample by sample (share 1: offset_model's K0 exactly). Both must be
/// stepped through the same log (InputError when their sample times differ).
HeldSamples WithOffsetOf(HeldSamples slope_model, const HeldSamples& offset_model, double share);

/// The line w x `grey`'s + (1 - w) x `rule`'s, sample by sample: K0, slope and the blank term
/// (latched at the cut start; `rule` without one counts 0) each mixed, so each model's K0 and
/// slope stay together (w 1: `grey` exactly). Both must be stepped through the same log
/// (InputError when their sample times differ); w outside [0, 1] is an InputError.
HeldSamples MixedLines(HeldSamples grey, const HeldSamples& rule, double w);

/// c_m(t_s), t_s from the cut start, which is at log time `cut_start_min`; z_of_t(t_s) the tool
/// position [mm]; a blank term (grey box) is latched at the cut start's sample and added to the
/// slope for the whole cut. The samples are kept by the function.
compare::CompensationFunction CausalMachineLine(HeldSamples samples, double cut_start_min,
                                                double z_ref_mm,
                                                std::function<double(double)> z_of_t);

}  // namespace whirl::machine_eval
