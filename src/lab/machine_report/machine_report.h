#pragma once
// Report of one screw cut on a drifting machine (the first screw of machine_eval.h's
// EvaluateWithMachines with a report folder): its sensor log, the lead deviation per strategy and
// its combined 840D programs.
#include <string>
#include <vector>

#include "machine_eval/machine_eval.h"
#include "machine_eval/machine_nc.h"

namespace whirl::machine_eval {

/// Report of one screw in `dir` (core/output_dir.h's rule: new, empty or a whirl output, never a
/// symbolic link; written all-or-nothing): sensors.csv/.png (the screw's sensor log, degC over
/// min, in panels of at most 8 sensors, related ones together, the models' sensors thick),
/// lead.csv/.png (lead deviation per strategy, um over mm from the thread start to its end, each
/// strategy in its core/plot_style.h look), index.html (core/html_page.h) with the strategies'
/// figures and the chosen sensors. Plots need gnuplot (skipped with a note otherwise).
/// Returns the index path.
/// `programs` (optional): the screw's combined 840D programs, written beside the figures
/// (machine_eval/machine_nc.h CombinedProgramFiles); the page then opens with the "load onto the
/// control" box (compare/control_box.h): the plan's setting data, the five files, the programs'
/// prerequisites, the call order and what to run after an abort.
std::string WriteMachineScrewReport(const std::string& dir, const MachineEvalScrew& screw,
                                    const MachineScrewDetail& detail,
                                    const std::vector<std::string>& sensors_cutting,
                                    const std::vector<std::string>& sensors_idle,
                                    const CombinedPrograms* programs = nullptr,
                                    const std::string& programs_note = "");

}  // namespace whirl::machine_eval
