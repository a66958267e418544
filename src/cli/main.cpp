// whirl: predicts the thermal elongation of the unmachined section of a ball screw during hard
// whirling and turns it into SINUMERIK 840D temperature-compensation setting data.
#include "cli/commands.h"
#include "cli/common.h"

namespace {

// One line per command in 'whirl --help' and in a group's --help.
const whirl::cli::CommandSummaries kSummaries = {
    {"demo", "the whole workflow on the shipped files: model, 840D plans, comparison, report"},
    {"dataset", "simulate a process table (training rows) over the paper's ranges"},
    {"simulate", "simulate one screw's elongation [um] over time [s] and its two features"},
    {"train", "train a workpiece model on a process table (family chosen by default) and write it"},
    {"predict", "max elongation [um] and settle time [s] of screws, with their sd"},
    {"design", "which screws to measure: first design, next screws, stop rule"},
    {"curve", "the arctangent elongation curve of a screw [um over s]"},
    {"fit", "fit curve models to a measured or simulated elongation curve"},
    {"plan", "SD43900/43910/43920 and the 840D programs for one screw"},
    {"compare", "cut one screw in the simulator with each strategy; lead errors and report"},
    {"lead-report", "ISO 3408-3 figures of a measured lead-deviation curve"},
    {"evaluate", "the strategies on many screws and truth scenarios"},
    {"ballbar", "ball-bar measurements"},
    {"ballbar drift", "spindle thermal drift [um] from ball-bar readings to three pivots"},
    {"ballbar circle", "circle-test diagnostics of a ball-bar trace"},
    {"ballbar simulate", "write a documented simulated ball-bar measurement"},
    {"surface", "thermal-error surface of the table"},
    {"surface synth", "write a synthetic thermal-error field as points [um at mm]"},
    {"surface fit", "fit a surface (cubic or B-spline) to the points of one moment"},
    {"surface predict", "thermal error [um] at table positions [mm] from a surface file"},
    {"surface compare", "cubic or B-spline: leave-one-out error of both"},
    {"surface line", "the linear 840D compensation per axis from a surface"},
    {"surface points", "per-point drift models, then a surface at one time"},
    {"drift", "machine thermal drift from temperature sensors"},
    {"drift select", "temperature-sensitive points: the sensors that explain an error"},
    {"drift fit", "fit a drift model of one error channel [um] and write it"},
    {"drift fit-grey", "fit the grey-box machine estimator from a shop's measurement records"},
    {"drift predict", "evaluate a drift model on a run sample by sample"},
    {"drift crossval", "cross-run evaluation of the drift models"},
    {"drift holdout", "chronological hold-out on one long log"},
    {"drift split", "cut one long log into run files at every machine start"},
    {"drift report", "HTML report: fit on training runs, evaluate on the others"},
    {"drift nc", "the live drift compensation on an 840D: NC program and PLC table"},
    {"drift monitor", "replay the on-line check-bar monitoring on a logged run"},
    {"machine", "simulated machine with its own thermal drift"},
    {"machine sensors", "write day logs of a simulated field machine (drift run files)"},
    {"machine evaluate", "workpiece plan and shop-trained drift models on drifting machines"},
    {"machine truth", "uncompensated machine error per test-day cut, split by source"},
    {"crosscheck", "check the network against LibTorch (runs whirl-torch)"},
    {"export", "export a model as TorchScript (runs whirl-torch)"},
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "whirl: thermal-elongation compensation for hard whirling of ball screws on SINUMERIK 840D.\n"
      "Predict the elongation curve of the unmachined section with a workpiece model (power law,\n"
      "linear fit, Gaussian process or Bayesian-regularized network, chosen on held-out error),\n"
      "plan the 840D temperature-compensation setting data (SD43900/SD43910/SD43920) and its NC\n"
      "programs, and compare the lead error against the alternatives.\n"
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
  RegisterDesign(app);
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
  return RunApp(app, argc, argv, kSummaries);
}
