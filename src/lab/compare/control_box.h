#pragma once
// The "load onto the control" box that opens the workpiece and the machine report: what a process
// engineer takes to the SINUMERIK 840D, in the order of doing it. Per screw: the setting data the
// plan writes (SD43900 K0, SD43910 slope, SD43920 reference position, one row per segment, written
// when the axis passes the row's trigger position), links to the NC programs (.SPF) and the PLC
// table (.csv) relative to the report, the machine-data prerequisites (the programs' own
// "; requires" and "; uses" header lines, and the machine profile's "control" section), and what
// to run after an aborted cut. Every text reaches the page through HtmlEscape.
#include <string>
#include <utility>
#include <vector>

#include "interp/machine_profile.h"
#include "interp/sinumerik.h"

namespace whirl::compare {

struct ControlLoad {
  std::string heading;                             ///< e.g. the screw's name
  const interp::CompensationPlan* plan = nullptr;  ///< its setting data (required)
  /// Extra words under the setting-data table (e.g. "handed to the drift action via $AC_PARAM").
  std::string plan_note;
  /// (href relative to the report page, what it is), in the order of loading; empty: `no_files`.
  std::vector<std::pair<std::string, std::string>> files;
  /// Why there are no files and which command writes them (shown when `files` is empty).
  std::string no_files;
  /// Prerequisites, one sentence each (NcPrerequisites, ProfilePrerequisites).
  std::vector<std::string> prerequisites;
  std::string call_order;   ///< which program to call when, e.g. "call X before the cutting block"
  std::string after_abort;  ///< what to run after an aborted cut
};

/// The header lines of an NC program that state what the control must provide (those starting
/// "; requires" or "; uses"), without the leading "; ", in order.
std::vector<std::string> NcPrerequisites(const std::string& nc_program);

/// What the machine profile states about the control (its "control" section: MD10300, MD28250,
/// MD28254; MD32760; the axis); empty when the profile states no control section.
std::vector<std::string> ProfilePrerequisites(const interp::MachineProfile& profile);

/// The entry for one plan's files as `whirl demo` writes them: the NC program `<program>.SPF`, its
/// reset `<program>_RESET.SPF`, the PLC table `plc_csv` and the plan document `plan_json`, each
/// linked as `prefix` + name (the path from the report page to the files, e.g. "../"); the
/// prerequisites from the program's header `nc_program` and from `profile` (may be null); the
/// call order and what to run after an abort, as the program's header states them. Heading and
/// plan are left for the caller.
ControlLoad PlanFilesLoad(const std::string& prefix, const std::string& program,
                          const std::string& plc_csv, const std::string& plan_json,
                          const std::string& nc_program, const interp::MachineProfile* profile);

/// The box (a <section class='control'>) for one or more screws.
std::string ControlBoxHtml(const std::vector<ControlLoad>& loads);

}  // namespace whirl::compare
