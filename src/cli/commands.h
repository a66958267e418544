#pragma once
// One registration function per subcommand; each lives in its own cmd_<name>.cpp with its
// options struct, its setup (flags, validators, --help text) and its run function.
#include <CLI/CLI.hpp>

namespace whirl::cli {

void RegisterTrain(CLI::App& app);       // cmd_train.cpp
void RegisterPredict(CLI::App& app);     // cmd_predict.cpp
void RegisterDesign(CLI::App& app);      // cmd_design.cpp
void RegisterSimulate(CLI::App& app);    // cmd_simulate.cpp
void RegisterDataset(CLI::App& app);     // cmd_dataset.cpp
void RegisterCurve(CLI::App& app);       // cmd_curve.cpp
void RegisterFit(CLI::App& app);         // cmd_fit.cpp
void RegisterPlan(CLI::App& app);        // cmd_plan.cpp
void RegisterCompare(CLI::App& app);     // cmd_compare.cpp
void RegisterLeadReport(CLI::App& app);  // cmd_lead_report.cpp
void RegisterEvaluate(CLI::App& app);    // cmd_evaluate.cpp
void RegisterCrosscheck(CLI::App& app);  // cmd_crosscheck.cpp (in whirl-torch only)
void RegisterExport(CLI::App& app);      // cmd_export.cpp (in whirl-torch only)
/// In whirl: 'crosscheck' and 'export' hand their arguments to whirl-torch (torch_forward.cpp).
void RegisterTorchForwarders(CLI::App& app);
void RegisterDemo(CLI::App& app);        // cmd_demo.cpp
void RegisterBallbar(CLI::App& app);     // cmd_ballbar.cpp
void RegisterSurface(CLI::App& app);     // cmd_surface.cpp
void RegisterDrift(CLI::App& app);       // cmd_drift.cpp
void RegisterDriftNc(CLI::App* drift);   // cmd_drift_nc.cpp: whirl drift nc
void RegisterMachine(CLI::App& app);     // cmd_machine.cpp
void RegisterMachineTruth(CLI::App* machine);  // cmd_machine_truth.cpp: whirl machine truth
void RegisterMachineExport(CLI::App* machine);  // cmd_machine_export.cpp: whirl machine export
void RegisterMachineCeiling(CLI::App* machine);  // cmd_machine_ceiling.cpp: whirl machine ceiling

}  // namespace whirl::cli
