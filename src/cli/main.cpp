// whirl: predicts the thermal elongation of the unmachined section of a ball screw during hard
// whirling and turns it into SINUMERIK 840D temperature-compensation setting data.
#include "cli/commands.h"
#include "cli/common.h"

int main(int argc, char** argv) {
  CLI::App app{
      "whirl: thermal-elongation compensation for hard whirling of ball screws on SINUMERIK 840D.\n"
      "Train a Bayesian-regularized 5-6-2 network on process tables, predict the elongation curve\n"
      "of the unmachined section, plan 840D temperature-compensation setting data (SD43900/\n"
      "SD43910/SD43920) and compare the lead error against traditional compensation.\n"
      "Run 'whirl <command> --help' for each command. Exit code 0 only on success; 1 on bad\n"
      "input or failure; 2 when a check ran and failed."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "whirl 0.1.0");
  using namespace whirl::cli;
  RegisterDemo(app);
  RegisterDataset(app);
  RegisterSimulate(app);
  RegisterTrain(app);
  RegisterPredict(app);
  RegisterCurve(app);
  RegisterFit(app);
  RegisterPlan(app);
  RegisterCompare(app);
  RegisterLeadReport(app);
  RegisterEvaluate(app);
  RegisterBallbar(app);
  RegisterSurface(app);
  RegisterDrift(app);
  RegisterMachine(app);
  RegisterTorchForwarders(app);
  return RunApp(app, argc, argv);
}
