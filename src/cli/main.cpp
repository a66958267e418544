// whirl: predicts the thermal elongation of the unmachined section of a ball screw during hard
// whirling and turns it into SINUMERIK 840D temperature-compensation setting data.
#include "cli/commands.h"
#include "cli/common.h"

int main(int argc, char** argv) {
  CLI::App app{
      "whirl: thermal-elongation compensation for hard whirling of ball screws on SINUMERIK 840D.\n"
      "Train a Bayesian-regularized network on process tables (its size chosen from the data by\n"
      "the evidence: linear, or 4, 6 or 8 hidden neurons), predict the elongation curve of the\n"
      "unmachined section, plan 840D temperature-compensation setting data (SD43900/SD43910/\n"
      "SD43920) and compare the lead error against the traditional rules and a regression.\n"
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
