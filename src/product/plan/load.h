#pragma once
// What a process engineer takes to the SINUMERIK 840D for one screw, as data ("load onto the
// control"; LoadBox makes it a box of a report document, core/report_render.h renders it): the
// setting data the plan writes (SD43900 K0, SD43910 slope, SD43920 reference position, one row
// per segment, written when the axis passes the row's trigger position), the files in the order
// of loading, the machine data the programs need (each datum once, with the threshold the
// programs need together: interp/control_requirements.h, built from the plan and the drift
// action's data, not read back from the programs' text), what the machine profile states about
// the control, the call order and what to run after an aborted cut.
#include <string>
#include <utility>
#include <vector>

#include "core/report_document.h"
#include "interp/control_requirements.h"
#include "interp/machine_profile.h"
#include "interp/sinumerik.h"

namespace whirl::plan {

struct ControlLoad {
  std::string heading;            ///< e.g. the screw's name
  interp::CompensationPlan plan;  ///< its setting data
  /// Whether the plan's positions (trigger positions, SD43920) are machine coordinates (MCS: the
  /// plan options or a machine profile placed the thread on the axis); false: millimetres from
  /// the thread start (a plan made without a machine profile, as `compare` makes it).
  bool machine_coordinates = true;
  /// Extra words under the setting-data table (e.g. "handed to the drift action via $AC_PARAM").
  std::string plan_note;
  /// (href relative to the report page, what it is), in the order of loading; empty: `no_files`.
  std::vector<std::pair<std::string, std::string>> files;
  /// Why there are no files and which command writes them (shown when `files` is empty).
  std::string no_files;
  /// The machine data the programs need, each datum once (interp::MergeRequirements).
  std::vector<interp::ControlRequirement> requirements;
  /// What the machine profile states about the control (ProfileNote), or "".
  std::string profile_note;
  std::string call_order;   ///< which program to call when, e.g. "call X before the cutting block"
  std::string after_abort;  ///< what to run after an aborted cut
};

/// The requirements with the profile's values of the data it states (MD10300, MD28250, MD28254
/// from its "control" section when stated; MD32760 on the profile's axis).
std::vector<interp::ControlRequirement> WithProfileValues(
    std::vector<interp::ControlRequirement> requirements, const interp::MachineProfile& profile);

/// One sentence on what the profile states about the control (MD10300, MD28250, MD28254,
/// MD32760, the axis) and what to do if the control differs; "" when the profile states no
/// control section.
std::string ProfileNote(const interp::MachineProfile& profile);

/// The entry for one plan's files as `whirl plan` and `whirl demo` write them: the NC program
/// `<program>.SPF`, its reset `<program>_RESET.SPF`, the PLC table `plc_csv` and the plan
/// document `plan_json`, each linked as `prefix` + name (the path from the report page to the
/// files, e.g. "../"); the requirements of the plan's program (interp::PlanRequirements) with
/// the profile's values (`profile` may be null); the call order and what to run after an abort.
/// The heading is left for the caller.
ControlLoad PlanFilesLoad(const std::string& prefix, const std::string& program,
                          const std::string& plc_csv, const std::string& plan_json,
                          const interp::CompensationPlan& plan,
                          const interp::MachineProfile* profile);

/// The "load onto the control" box that opens the workpiece and the machine report (id "load"):
/// per load its heading, the files (links), the call order, the setting data the plan writes
/// (one row per segment and the restoring row; positions "[mm, MCS]" or "[mm from the thread
/// start]" per ControlLoad::machine_coordinates), the machine data the programs need and what to
/// run after an abort. Plain text throughout: the renderer escapes it.
report::Box LoadBox(const std::vector<ControlLoad>& loads);

}  // namespace whirl::plan
