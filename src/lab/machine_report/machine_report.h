#pragma once
// The report of one screw cut on a drifting machine, the manual of the machine_report module
// (lab): written by the caller (`whirl machine evaluate --out-dir`, step 7 of `whirl demo`) from
// the screw an evaluation kept (machine_eval.h ReportScrew; the evaluation itself writes
// nothing). Its control log, the lead deviation per strategy, and the combined 840D programs
// (machine_nc.h) of the models a shop can train: the workpiece plan of the network's curve and
// the drift action of a shop-trainable machine model (the grey box of both_grey wherever it was
// fitted, else the sensor model of both_shop; ReportScrew::programs_strategy),
// trained from probe, laser and lead measurements only, never from the simulator's truth.
#include <string>

#include "interp/machine_profile.h"
#include "machine_eval/machine_eval.h"

namespace whirl::machine_report {

struct MachineReport {
  std::string index_html;  ///< the page written
  bool programs = false;   ///< the combined programs were written beside it
  /// Why the report holds no combined programs (no profile, or one that does not fit the
  /// machine), or "".
  std::string programs_note;
  /// Which machine model the programs apply and why (ReportScrew::programs_reason, or the
  /// fallback to both_shop when the grey box's programs cannot be written for the profile).
  std::string programs_reason;
  bool programs_grey = false;  ///< the programs apply the grey box (both_grey)
  /// grey_short_mix's drift action (machine_nc.h MixDriftProgramFiles) was written beside them:
  /// where its row was computed (the opt-in grey rows) and the programs are the grey box's; else
  /// mix_note says why not (empty where the row was not computed).
  bool mix_programs = false;
  std::string mix_note;
};

/// Report of one screw in `dir` (core/output_dir.h's rule: new, empty or a whirl output, never a
/// symbolic link; written all-or-nothing): sensors.csv/.png (the control's log of the screw's
/// day from power-on to the cut's end in the drift run format, the temperatures in panels of at
/// most 8 sensors, related ones together, each sensor in one colour in every panel, the sensor
/// model's sensors thick; degC over min since the day's 00:00), lead.csv/.png (lead deviation per
/// strategy, um over mm from the thread start to its end, each strategy in its core/plot_style.h
/// look with its +-1 sd band, ReportScrew::sd_um), index.html (core/report_render.h) with
/// the strategies' figures and the sensor model. Plots need gnuplot (skipped with a note
/// otherwise). With a `profile` that fits the machine, the screw's combined 840D programs are
/// written beside the figures and the page opens with the "load onto the control" box
/// (plan/load.h LoadBox, rendered by core/report_render.h): the plan's setting data, the five
/// files, the machine data both programs need (each datum once), the call order and what to run
/// after an abort; a profile that does not fit leaves them out with the note returned (the report
/// stands). Where grey_short_mix's row was computed (ReportScrew::mix_computed) and the programs
/// are the grey box's, its drift action is written too (machine_nc.h MixDriftProgramFiles: it
/// replaces WHIRL_DRIFT_COMP with the same plan) with a paragraph on the page; else mix_note.
/// InputError for a screw whose evaluation failed.
MachineReport WriteMachineScrewReport(const std::string& dir,
                                      const machine_eval::ReportScrew& screw,
                                      const interp::MachineProfile* profile);

}  // namespace whirl::machine_report
