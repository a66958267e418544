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
/// symbolic link; written all-or-nothing): sensors.csv/.png (the screw's sensor log,
/// degC over min), lead.csv/.png (lead deviation per strategy, um over mm), index.html with the
/// chosen sensors and the screw's figures. Plots need gnuplot (skipped with a note otherwise).
/// Returns the index path.
/// `programs` (optional): the screw's combined 840D programs, written beside the figures
/// (machine_eval/machine_nc.h CombinedProgramFiles) and shown in index.html.
std::string WriteMachineScrewReport(const std::string& dir, const MachineEvalScrew& screw,
                                    const MachineScrewDetail& detail,
                                    const std::vector<std::string>& sensors_cutting,
                                    const std::vector<std::string>& sensors_idle,
                                    const CombinedPrograms* programs = nullptr,
                                    const std::string& programs_note = "");

}  // namespace whirl::machine_eval
