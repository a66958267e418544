// Development driver (not installed, not a test): fits the family choice or one candidate on a
// training table and predicts a test table, printing JSON for scripts/bench_peers.py.
//   family_bench --train T.csv --test X.csv [--candidates default|NAME,NAME...] [--no-cv]
//                [--joint] [--loo|--kfold] [--no-1se] [--leave-first-se Z] [--leave-first-se-large Z] [--leave-first-blocks M] [--leave-first-row-share S] [--lowest-gp|--no-lowest-gp] [--lowest-gp-per-scale|--no-lowest-gp-per-scale] [--lowest-gp-per-scale-large] [--equivalence-sd SD] [--gp-ftol F] [--gp-gtol G] [--gp-large-ftol F] [--gp-large-gtol G] [--calibration-folds K]
//                [--stack|--no-stack] [--stack-se START FULL] [--stack-se-large START FULL] [--stack-gate-se Z Z_LARGE] [--two-sd|--one-sd] [--seed N] [--folds K] [--gp-restarts R] [--gp-single-start-rows N] [--threads N]
//                [--few-rows N] [--refit-lowest-gp-rows N] [--refit-iterations N] [--refit-folds K]
//                [--refit-hyper-rows N] [--refit-ftol F] [--refit-gtol G]
//                [--gp-length-prior-sd SD] [--gp-max-rows N] [--gp-loo-penalty F]
//                [--gp-hyper-rows N] [--loo-calibration-rows N] [--gp-slot-large held-out|evidence|bic]
// Output: {"chosen", "cv_table", "fit_time_ms" (wall), "fit_cpu_ms" (process CPU), "predictions":
// [{"mean": [e, s], "sd": [e, s]}, ...]}. Bad arguments: message on stderr, exit 2.
#include <chrono>
#include <ctime>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "family/family.h"

namespace {

using whirl::family::Candidate;

struct Args {
  std::string train, test, candidates = "default";
  bool no_cv = false;
  whirl::family::ChoiceOptions choice;
};

Args Parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw whirl::InputError(k + ": needs a value");
      return argv[++i];
    };
    if (k == "--train")
      a.train = value();
    else if (k == "--test")
      a.test = value();
    else if (k == "--candidates")
      a.candidates = value();
    else if (k == "--no-cv")
      a.no_cv = true;
    else if (k == "--joint")
      a.choice.per_output = false;
    else if (k == "--loo")
      a.choice.closed_form_loo = true;
    else if (k == "--kfold")
      a.choice.closed_form_loo = false;
    else if (k == "--stack")
      a.choice.stack = true;
    else if (k == "--no-stack")
      a.choice.stack = false;
    else if (k == "--stack-se") {
      a.choice.stack_start_se = std::stod(value());
      a.choice.stack_full_se = std::stod(value());
    } else if (k == "--stack-gate-se") {
      a.choice.stack_gate_se = std::stod(value());
      a.choice.stack_gate_se_large = std::stod(value());
    } else if (k == "--stack-se-large") {
      a.choice.stack_start_se_large = std::stod(value());
      a.choice.stack_full_se_large = std::stod(value());
    }
    else if (k == "--stack-scale-single")
      a.choice.stack_scale_single = true;
    else if (k == "--no-stack-scale-single")
      a.choice.stack_scale_single = false;
    else if (k == "--network-max-rows")
      a.choice.network_max_rows = std::stoi(value());
    else if (k == "--stack-sd-two-share")
      a.choice.stack_sd_two_share = std::stod(value());
    else if (k == "--two-sd")
      a.choice.fit.calibrate_two_sd = true;
    else if (k == "--one-sd")
      a.choice.fit.calibrate_two_sd = false;
    else if (k == "--equivalence-sd")
      a.choice.equivalence_sd = std::stod(value());
    else if (k == "--leave-first-se")
      a.choice.leave_first_se = std::stod(value());
    else if (k == "--leave-first-se-large")
      a.choice.leave_first_se_large = std::stod(value());
    else if (k == "--leave-first-row-share")
      a.choice.leave_first_row_share = std::stod(value());
    else if (k == "--leave-first-blocks")
      a.choice.leave_first_blocks = std::stoi(value());
    else if (k == "--lowest-gp")
      a.choice.lowest_gp = true;
    else if (k == "--no-lowest-gp")
      a.choice.lowest_gp = false;
    else if (k == "--lowest-gp-per-scale")
      a.choice.lowest_gp_per_scale = true;
    else if (k == "--no-lowest-gp-per-scale")
      a.choice.lowest_gp_per_scale = false;
    else if (k == "--lowest-gp-per-scale-large")
      a.choice.lowest_gp_per_scale_large = true;
    else if (k == "--no-1se")
      a.choice.one_standard_error = false;
    else if (k == "--gp-ftol")
      a.choice.fit.gp.bfgs.function_tolerance = std::stod(value());
    else if (k == "--gp-gtol")
      a.choice.fit.gp.bfgs.gradient_tolerance = std::stod(value());
    else if (k == "--gp-large-ftol")
      a.choice.fit.gp.bfgs_large.function_tolerance = std::stod(value());
    else if (k == "--gp-large-gtol")
      a.choice.fit.gp.bfgs_large.gradient_tolerance = std::stod(value());
    else if (k == "--calibration-folds")
      a.choice.fit.calibration_folds = std::stoi(value());
    else if (k == "--seed")
      a.choice.fit.seed = std::stoull(value());
    else if (k == "--folds")
      a.choice.folds = std::stoi(value());
    else if (k == "--gp-max-rows")
      a.choice.fit.gp.max_rows = std::stoi(value());
    else if (k == "--gp-hyper-rows")
      a.choice.fit.gp.hyperparameter_rows = std::stoi(value());
    else if (k == "--loo-calibration-rows")
      a.choice.fit.loo_calibration_rows = std::stoi(value());
    else if (k == "--few-rows")
      a.choice.few_rows = std::stoi(value());
    else if (k == "--refit-lowest-gp-rows")
      a.choice.refit_lowest_gp_rows = std::stoi(value());
    else if (k == "--refit-iterations")
      a.choice.refit_iterations = std::stoi(value());
    else if (k == "--refit-ftol")
      a.choice.refit_function_tolerance = std::stod(value());
    else if (k == "--refit-gtol")
      a.choice.refit_gradient_tolerance = std::stod(value());
    else if (k == "--refit-hyper-rows")
      a.choice.refit_hyperparameter_rows = std::stoi(value());
    else if (k == "--refit-folds")
      a.choice.refit_folds = std::stoi(value());
    else if (k == "--gp-loo-penalty")
      a.choice.gp_loo_hyperparameter_penalty = std::stod(value());
    else if (k == "--gp-slot-large") {
      const std::string v = value();
      using whirl::family::GpSlot;
      if (v != "held-out" && v != "evidence" && v != "bic")
        throw std::invalid_argument("--gp-slot-large " + v + ": must be held-out, evidence or bic");
      a.choice.gp_slot_large = v == "evidence" ? GpSlot::kEvidence
                               : v == "bic"    ? GpSlot::kBic
                                               : GpSlot::kHeldOut;
    } else if (k == "--gp-length-prior-sd")
      a.choice.fit.gp.length_prior_sd = std::stod(value());
    else if (k == "--gp-restarts")
      a.choice.fit.gp.restarts = std::stoi(value());
    else if (k == "--gp-single-start-rows")
      a.choice.fit.gp.single_start_rows = std::stoi(value());
    else if (k == "--threads")
      a.choice.fit.threads = std::stoi(value());
    else
      throw whirl::InputError("unknown argument " + k);
  }
  if (a.train.empty() || a.test.empty()) throw whirl::InputError("--train and --test are required");
  if (a.candidates != "default") {
    a.choice.candidates.clear();
    std::stringstream ss(a.candidates);
    for (std::string n; std::getline(ss, n, ',');)
      a.choice.candidates.push_back(whirl::family::ParseCandidate(n));
  }
  return a;
}

nlohmann::json Run(const Args& a) {
  const whirl::ProcessTable train = whirl::ReadProcessTable(a.train, true);
  const whirl::ProcessTable test = whirl::ReadProcessTable(a.test, false);
  const auto wall0 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  whirl::family::Choice c;
  if (a.no_cv) {
    c.models = {whirl::family::FitCandidate(train, a.choice.candidates.front(), a.choice.fit)};
    c.table.push_back({a.choice.candidates.front(), {}, 0, 0});
  } else {
    c = whirl::family::ChooseFamily(train, a.choice);
  }
  const double cpu_ms = 1000.0 * static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  const double wall_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count();
  nlohmann::json out = {{"chosen", c.Describe()},
                        {"cv_table", c.table},
                        {"fit_time_ms", wall_ms},
                        {"fit_cpu_ms", cpu_ms},
                        {"calibration", c.models.front().calibration}};
  out["predictions"] = nlohmann::json::array();
  for (const auto& p : whirl::family::PredictChoice(c, test.inputs))
    out["predictions"].push_back({{"mean", {p.mean.max_elongation_um, p.mean.settle_time_s}},
                                  {"sd", {p.stddev.max_elongation_um, p.stddev.settle_time_s}}});
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::cout << Run(Parse(argc, argv)).dump() << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "family_bench: " << e.what() << "\n";
    return 2;
  }
}
