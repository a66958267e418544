// whirl train: fit the workpiece model (src/product/workpiece/model.h) to a process table: by default the
// family choice by cross-validated error (src/product/family/family.h), or the Bayesian-regularized network
// (src/product/nn/trainbr.h); or sweep the network's hidden size with k-fold cross-validation
// (src/product/nn/selection.h).
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>
#include <thread>

#include "cli/commands.h"
#include "cli/common.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/process.h"
#include "family/transform.h"
#include "nn/model.h"
#include "nn/selection.h"
#include "workpiece/model.h"

namespace whirl::cli {
namespace {

struct TrainCliOptions {
  std::string data_path;
  std::string out_path;
  std::string hidden = "evidence";
  std::uint64_t seed = 1;
  int restarts = 1;
  int epochs = nn::TrainOptions{}.epochs;
  std::string hidden_sweep;  // "A..B"
  int folds = 5;
  bool trainbr_matlab = false;
  bool ard = false;
  bool stop_by_cv = false;
  double change = -1;  // < 0: the default of the chosen setting
  int noise_folds = 5;
  int threads = 0;
  bool json = false;
  std::string family;     // empty: not given
  std::string transform;  // empty: not given
  std::string choice = "stack";  // --choice: stack (ChoiceOptions::stack) or hard
  std::string network_flags;  // the network-only flags given, " --hidden --ard"
};

constexpr int kMaxHidden = 200;  // neurons in the hidden layer (--hidden, --hidden-sweep)

std::pair<int, int> ParseSweep(const std::string& s) {
  const auto dots = s.find("..");
  const auto whole = [](const std::string& t, long* v) {
    char* end = nullptr;
    errno = 0;
    *v = std::strtol(t.c_str(), &end, 10);
    return !t.empty() && errno == 0 && *end == '\0';
  };
  long a = 0, b = 0;
  if (dots == std::string::npos || !whole(s.substr(0, dots), &a) || !whole(s.substr(dots + 2), &b))
    throw InputError("--hidden-sweep '" + s + "': expected A..B with integers, e.g. 4..10");
  if (a < 1 || b < a || b > kMaxHidden)
    throw InputError("--hidden-sweep '" + s + "': need 1 <= A <= B <= " +
                     std::to_string(kMaxHidden) + " (hidden neurons, as --hidden)");
  return {static_cast<int>(a), static_cast<int>(b)};
}

int ParseHidden(const std::string& s) {
  int h = 0;
  char tail = 0;
  if (std::sscanf(s.c_str(), "%d%c", &h, &tail) != 1 || h < 0 || h > 200)
    throw InputError("--hidden '" + s + "': expected 'evidence', 'auto' or an integer in [0, 200]");
  return h;
}

void RunSweep(const TrainCliOptions& o, const ProcessTable& table) {
  nn::SweepOptions s;
  std::tie(s.hidden_min, s.hidden_max) = ParseSweep(o.hidden_sweep);
  s.folds = o.folds;
  s.seed = o.seed;
  s.restarts = o.restarts;
  s.train.epochs = o.epochs;
  s.train.ard = o.ard;
  s.threads = o.threads;
  s.Validate(static_cast<int>(table.inputs.size()));
  Progress progress("hidden sweep",
                    static_cast<std::size_t>((s.hidden_max - s.hidden_min + 1) * (s.folds + 1)));
  const auto rows = nn::HiddenSweep(table, s, [&](int done, int total) {
    progress.Update(static_cast<std::size_t>(done),
                    std::to_string(done) + "/" + std::to_string(total) + " fits");
  });
  progress.Finish();
  if (o.json) {
    PrintJson({{"data", o.data_path},
               {"samples", table.inputs.size()},
               {"folds", s.folds},
               {"seed", s.seed},
               {"restarts", s.restarts},
               {"error_space", "normalized"},
               {"rows", rows}});
    return;
  }
  std::cout << "hidden-size sweep on " << o.data_path << " (" << table.inputs.size() << " rows, "
            << s.folds << "-fold CV, seed " << s.seed << ", " << s.restarts
            << " restart(s) per fit)\n";
  std::cout << "hidden  N   gamma   train_rms_um  train_rms_s  cv_rms_um  cv_rms_s  "
               "cv_rms_norm  log_evidence\n";
  for (const auto& r : rows) {
    char line[256];
    std::snprintf(line, sizeof line, "%6d %3d %7.2f %13.4g %12.4g %10.4g %9.4g %12.4g %13.5g\n",
                  r.hidden, r.parameter_count, r.gamma, r.train_rms(0), r.train_rms(1), r.cv_rms(0),
                  r.cv_rms(1), r.cv_rms_normalized, r.log_evidence);
    std::cout << line;
  }
  std::cout << "Pick the smallest size after which cv_rms_norm stops improving (the paper grew\n"
               "the hidden layer from 4 until the error stopped improving), then run 'whirl\n"
               "train --hidden N --out MODEL.json'.\n";
}

// The library's training options for the command's flags (the default training, or MATLAB's
// trainbr with --trainbr-matlab); flags that exclude each other are refused.
nn::ModelTrainOptions ModelOptions(const TrainCliOptions& o) {
  if (o.trainbr_matlab && o.change >= 0)
    throw InputError("train: --trainbr-matlab is MATLAB's trainbr as it is; it excludes --change");
  nn::ModelTrainOptions opt =
      o.trainbr_matlab ? nn::ModelTrainOptions{} : nn::DefaultTrainingOptions();
  if (o.hidden == "auto" && !o.trainbr_matlab) {
    opt.hidden_candidates = {4, 6, 8, 10, 12};
    opt.hidden_by_evidence = false;
  } else if (o.hidden != "evidence" && o.hidden != "auto") {
    opt.hidden_candidates.clear();
    opt.hidden_sizes = nn::HiddenLayers(ParseHidden(o.hidden));
  }
  if (o.change >= 0) opt.train.change = o.change;
  opt.seed = o.seed;
  opt.restarts = o.restarts;
  opt.train.epochs = o.epochs;
  opt.threads = o.threads;
  if (o.stop_by_cv) opt.stopping = nn::Stopping::kCrossValidated;
  opt.noise_folds = o.noise_folds;
  if (o.trainbr_matlab && o.stop_by_cv)
    throw InputError("train: --trainbr-matlab and --stop-by-cv exclude each other");
  if (o.trainbr_matlab && o.ard)
    throw InputError("train: --trainbr-matlab is MATLAB's trainbr as it is; it excludes --ard");
  opt.train.ard = o.ard;
  return opt;
}

// The human summary on stdout: the network, the training summary, the choices and, with ARD or
// restarts, their figures.
void PrintModelSummary(const TrainCliOptions& o, const nn::Model& model, std::size_t rows,
                       double fit_ms) {
  const auto& s = model.training_summary;
  std::string sizes;
  for (int n : model.network.layer_sizes) sizes += (sizes.empty() ? "" : "-") + std::to_string(n);
  std::cout << "model " << o.out_path << ": network " << sizes << " ("
            << (model.network.LayerCount() == 1 ? "no hidden layer, linear; " : "")
            << "N = " << s.parameter_count << " weights and biases), " << rows << " samples from "
            << o.data_path << "\n";
  std::cout << "  " << s.BriefReport() << "\n";
  std::cout << "  hidden layer: " << model.hidden_selection << "\n";
  std::cout << "  stopping: " << model.stopping << "\n";
  std::cout << "  fit time " << FormatSignificant(fit_ms, 4)
            << " ms (hidden-size choice, training, noise calibration)\n";
  std::cout << "  RMS training error: max_elongation " << FormatSignificant(s.rms_error(0), 4)
            << " um, settle_time " << FormatSignificant(s.rms_error(1), 4) << " s (normalized ssE "
            << FormatSignificant(s.sse, 4) << ")\n";
  std::cout << "  gamma " << FormatSignificant(s.gamma, 4) << " of " << s.parameter_count
            << ", alpha " << FormatSignificant(s.alpha, 4) << ", beta "
            << FormatSignificant(s.beta, 4) << ", sum of squared weights "
            << FormatSignificant(s.sum_squared_weights, 4) << ", log evidence "
            << FormatSignificant(s.log_evidence, 6) << "\n";
  if (s.ard_alpha.size() == ProcessInputs::kCount + 1) {
    std::cout << "  ARD alpha per input (larger = less relevant; normalized units):";
    for (int i = 0; i < ProcessInputs::kCount; ++i)
      std::cout << (i ? ", " : " ") << kInputColumns[i] << " "
                << FormatSignificant(s.ard_alpha(i), 4);
    std::cout << "; other weights " << FormatSignificant(s.ard_alpha(ProcessInputs::kCount), 4)
              << "\n";
  }
  if (model.restarts > 1) {
    std::cout << "  restarts (best log evidence kept):\n";
    for (const auto& r : model.restart_runs)
      std::cout << "    seed " << r.seed << ": log evidence "
                << FormatSignificant(r.log_evidence, 6) << ", ssE " << FormatSignificant(r.sse, 4)
                << ", gamma " << FormatSignificant(r.gamma, 4) << ", " << r.epochs << " epochs, "
                << nn::ToString(r.termination) << (r.seed == model.init_seed ? "  <- kept" : "")
                << "\n";
  }
}

// --family and --transform with the network-only flags: a network flag without --family means
// --family network; with another family it is refused; --transform defaults to identity for a
// network (the network of earlier versions), auto otherwise.
workpiece::TrainOptions WorkpieceOptions(const TrainCliOptions& o) {
  workpiece::TrainOptions w;
  w.family = o.family.empty() ? (o.network_flags.empty() ? workpiece::FamilyFlag::kAuto
                                                         : workpiece::FamilyFlag::kNetwork)
                              : workpiece::ParseFamilyFlag(o.family);
  const bool network = w.family == workpiece::FamilyFlag::kNetwork;
  if (!network && !o.network_flags.empty())
    throw InputError("train:" + o.network_flags + ": options of the network; they need --family " +
                     "network (got --family " + o.family + ")");
  w.transform = o.transform.empty() ? (network ? workpiece::TransformFlag::kIdentity
                                               : workpiece::TransformFlag::kAuto)
                                    : workpiece::ParseTransformFlag(o.transform);
  if (!o.network_flags.empty() && w.transform != workpiece::TransformFlag::kIdentity)
    throw InputError("train:" + o.network_flags + ": options of the network on raw columns; " +
                     "they exclude --transform " + o.transform +
                     " (a network on log columns is a family candidate with its defaults)");
  if (network) w.network = ModelOptions(o);
  w.choice.stack = o.choice == "stack";
  w.choice.fit.seed = o.seed;
  w.choice.fit.threads = o.threads;
  return w;
}

// Progress of a family choice on stderr, only for a fit that takes longer than kQuiet: from then
// on a line every kQuiet (a watcher thread, so that one long step still gets its lines): steps
// done, elapsed seconds and the step last finished.
class SlowFitProgress {
 public:
  static constexpr std::chrono::seconds kQuiet{2};
  SlowFitProgress() : start_(std::chrono::steady_clock::now()), watcher_([this] { Watch(); }) {}
  ~SlowFitProgress() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    watcher_.join();
  }
  void Update(int done, int total, const std::string& step) {
    const std::lock_guard<std::mutex> lock(mutex_);
    done_ = done;
    total_ = total;
    step_ = step;
  }

 private:
  void Watch() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!wake_.wait_for(lock, kQuiet, [this] { return stop_; })) {
      const double s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
      std::fprintf(stderr, "train: %d/%d steps in %.0f s%s%s\n", done_, total_, s,
                   step_.empty() ? "" : ", last: ", step_.c_str());
      std::fflush(stderr);
    }
  }
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  int done_ = 0, total_ = 0;
  std::string step_;
  std::thread watcher_;  // last: starts after the fields above exist
};

// A family choice: train, save and print what was chosen with the CV table.
// How the one GP that takes part is chosen (ChoiceOptions::gp_slot_large), for the table's
// summary line; empty where the held-out errors choose it.
std::string GpSlotNote(const family::ChoiceOptions& c, bool few) {
  if (few || !c.lowest_gp || c.gp_slot_large == family::GpSlot::kHeldOut) return "";
  return std::string("; of the GPs only the one of highest ") +
         (c.gp_slot_large == family::GpSlot::kBic ? "BIC" : "log marginal likelihood") +
         " (as a density of the output in its units) takes part";
}

void RunFamily(const TrainCliOptions& o, const ProcessTable& table, workpiece::TrainOptions w) {
  const auto start = std::chrono::steady_clock::now();
  workpiece::WorkpieceModel model;
  {
    SlowFitProgress progress;
    w.choice.progress = [&progress](int done, int total, const std::string& step) {
      progress.Update(done, total, step);
    };
    model = workpiece::TrainWorkpieceModel(table, w,
                                           std::filesystem::path(o.data_path).filename().string());
  }
  const double fit_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  for (const std::string& warning : model.choice.warnings) Warn(warning);
  workpiece::SaveWorkpieceModel(o.out_path, model);
  const family::ChoiceOptions& c = w.choice;
  if (o.json) {
    PrintJson({{"model", o.out_path},
               {"kind", "family"},
               {"chosen", model.Describe()},
               {"folds", c.folds},
               {"cv_table", workpiece::ChoiceTableJson(model.choice)},
               {"notes", model.choice.notes},
               {"rows_note", model.choice.rows_note},
               {"warnings", model.choice.warnings},
               {"calibration", model.choice.models.front().calibration},
               {"sd_scale", {{"max_elongation_um", model.choice.sd_scale[0]},
                             {"settle_time_s", model.choice.sd_scale[1]}}},
               {"fit_time_ms", fit_ms}});
    return;
  }
  std::cout << "model " << o.out_path << ": " << model.Describe() << "; " << table.inputs.size()
            << " samples from " << o.data_path << "\n";
  const bool few = static_cast<int>(table.inputs.size()) < c.few_rows;
  std::cout << "  chosen per output by held-out error ("
            << (c.closed_form_loo
                    ? std::string("closed-form leave-one-out for linear fits, ") +
                          (few ? std::to_string(c.folds) + "-fold refits for GPs and networks"
                               : "closed-form leave-one-out for GPs, " +
                                     std::to_string(c.folds) + "-fold refits for networks")
                    : std::to_string(c.folds) + "-fold refits")
            << ")" << GpSlotNote(c, few)
            << (c.stack ? ", combined with weights shrunk toward the power law"
                : c.one_standard_error ? ", the simplest within one standard error"
                                       : "")
            << "; held-out RMSE in um and s, score = sum of MSE / variance:\n"
            << workpiece::FormatChoiceTable(model.choice);
  std::cout << "  sd: " << model.choice.models.front().calibration << "\n";
  const auto& scale = model.choice.sd_scale;
  if (scale[0] != 1.0 || scale[1] != 1.0)
    std::cout << "  sd then narrowed per output (max_elongation_um x" << FormatSignificant(scale[0], 3)
              << ", settle_time_s x" << FormatSignificant(scale[1], 3)
              << "): the smallest factor, at most 1, at which +-1 sd covers 68.27 % of the held-out "
                 "residuals"
              << (c.stack_sd_two_share > 0
                      ? " while +-2 sd still covers " +
                            FormatSignificant(100 * c.stack_sd_two_share, 3) + " %"
                      : std::string())
              << "\n";
  std::cout << "  fit time " << FormatSignificant(fit_ms, 4) << " ms (choice, refits, calibration)\n";
}

// Refuses a table whose rows are all one screw type (every input equal in every row): no model
// can learn how the inputs act from it, and a fit would claim certainty it does not have.
void RequireVaryingInputs(const ProcessTable& table) {
  family::TableTransform used;
  if (family::LeaveOutConstantInputs(table, &used).size() < ProcessInputs::kCount) return;
  throw InputError(table.source + ": every input is the same in every row (" +
                   std::to_string(table.inputs.size()) +
                   " rows of one screw type): a workpiece model learns how the five inputs act "
                   "from screws that differ in them; add measured screws of other types "
                   "('whirl design' says which)");
}

void Run(const TrainCliOptions& o) {
  CheckOutputs({{"--data", o.data_path}}, {{"--out", o.out_path}});
  const ProcessTable table = ReadProcessTable(o.data_path, /*require_targets=*/true);
  RequireVaryingInputs(table);
  if (!o.hidden_sweep.empty()) {
    RunSweep(o, table);
    return;
  }
  if (o.out_path.empty())
    throw InputError("train: --out MODEL.json is required (or use --hidden-sweep)");
  const workpiece::TrainOptions w = WorkpieceOptions(o);
  if (w.family != workpiece::FamilyFlag::kNetwork ||
      w.transform != workpiece::TransformFlag::kIdentity) {
    RunFamily(o, table, w);
    return;
  }
  const nn::ModelTrainOptions& opt = w.network;
  const auto start = std::chrono::steady_clock::now();
  // At most epochs per stage and restart (ARD adds a second stage). Restarts run in parallel and
  // report out of order (one at a time: TrainBrRestarts serializes the callback), so the bar
  // shows the epochs finished over all restarts.
  const std::size_t total = static_cast<std::size_t>(o.restarts) *
                            static_cast<std::size_t>(std::max(o.epochs, 1)) * (o.ard ? 2 : 1);
  Progress progress("train", total);
  std::size_t epochs_done = 0;
  const nn::Model model = nn::TrainModel(  // = workpiece::TrainWorkpieceModel for a network
      table, opt, std::filesystem::path(o.data_path).filename().string(),
      [&](int restart, const nn::EpochInfo& info) {
        progress.Update(++epochs_done, "restart " + std::to_string(restart + 1) + "/" +
                                           std::to_string(o.restarts) +
                                           (info.ard_stage ? " ARD epoch " : " epoch ") +
                                           std::to_string(info.epoch) + " F " +
                                           FormatSignificant(info.objective, 4) + " gamma " +
                                           FormatSignificant(info.gamma, 4));
      });
  progress.Finish();
  const double fit_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  nn::SaveModel(o.out_path, model);
  const auto& s = model.training_summary;
  const std::vector<nn::FlatOutput> flat = nn::FlatOutputs(model, table);
  const std::string flat_warning = flat.empty() ? "" : nn::DescribeFlatOutputs(model, flat);
  if (!flat.empty()) Warn(flat_warning);
  if (o.json) {
    PrintJson({{"model", o.out_path},
               {"layer_sizes", model.network.layer_sizes},
               {"seed", model.seed},
               {"init_seed", model.init_seed},
               {"restarts", model.restarts},
               {"restart_runs", model.restart_runs},
               {"stopping", model.stopping},
               {"hidden_selection", model.hidden_selection},
               {"fit_time_ms", fit_ms},
               {"warnings",
                flat.empty() ? nlohmann::json::array() : nlohmann::json::array({flat_warning})},
               {"training_summary", s}});
    return;
  }
  PrintModelSummary(o, model, table.inputs.size(), fit_ms);
}

// The subcommand's description in --help: what it trains, the default, the table's columns.
std::string TrainDescription() {
  return "Train the workpiece model on a process table and write a model file (JSON).\n"
         "Default (no model options): per output a convex combination (stack) of the power law\n"
         "(least squares on log columns), a linear fit, a GP with a power-law mean on log\n"
         "columns, two ARD GPs on raw columns (Matern 5/2, squared exponential) and up to 500\n"
         "rows a trainbr network with 2 tanh units on raw columns (5 fold refits): a candidate\n"
         "enters only if its held-out error beats the power law's by 1 standard error (1.5 from\n"
         "70 rows), and only the GP with the lowest held-out error; weights minimize the\n"
         "held-out error, shrunk toward the power law until the combination's nested held-out\n"
         "error beats it by 1-2 standard errors (1.5-2.5 from 70 rows). --choice hard: one\n"
         "candidate per output instead, the simplest within one standard error of the lowest,\n"
         "a candidate leaving the power law only by 2 standard errors (2.5 from 70 rows).\n"
         "Held-out errors: closed-form leave-one-out for the linear fits; for GPs below 70 rows\n"
         "5-fold refits with their hyperparameters refitted (none has seen the held-out rows),\n"
         "from 70 rows their closed-form leave-one-out. GP length scales have a\n"
         "log-normal prior that keeps few rows from bending a fit. Tables of 8 and 9 rows: the\n"
         "linear fits only (a note says why); fewer than 8 rows are refused. A constant input\n"
         "is named and left out; a zero or near-zero target keeps its column raw for the log\n"
         "candidates, with a warning; a target the same in every row is named in a warning.\n"
         "From 512 rows a GP keeps 512 rows spread over the\n"
         "table (the others judge it). The sd is calibrated to cover 68.27 % / 95.45 % of\n"
         "held-out residuals at +-1 / +-2 sd; the output's sd (the weighted sum of its\n"
         "candidates' sd) is then scaled down to cover 68.27 % of its own held-out residuals\n"
         "at +-1 sd, as long as +-2 sd still covers 95 % of them.\n"
         "Prints the choice and the table of held-out errors; a progress line every 2 s once\n"
         "a fit takes longer. The same table and seed give the same file byte for byte.\n"
         "--family network|gp|linear|auto and --transform log|identity|auto restrict it.\n"
         "--family network (implied by any network option below, raw columns unless\n"
         "--transform says otherwise): the Bayesian-regularized network (MATLAB trainbr:\n"
         "Levenberg-Marquardt with MacKay's alpha/beta re-estimation); no hidden layer or 4, 6\n"
         "or 8 hidden neurons by the highest log evidence, brnn's stopping rule (--change\n"
         "0.001), per-output noise by 5-fold cross-validation. A warning says when the network\n"
         "ignores its inputs. --trainbr-matlab: the paper's 5-6-2 trained to MATLAB's own\n"
         "criteria. --hidden-sweep: the network's hidden-size sweep instead of a model.\n"
         "Table: CSV with a header row and columns hardness_hrc [HRC], diameter_mm [mm],\n"
         "pitch_mm [mm], raceway_radius_mm [mm], cutting_speed_m_min [m/min] (inputs) and\n"
         "max_elongation_um [um], settle_time_s [s] (targets); '#' lines are comments.\n"
         "Progress goes to stderr, results to stdout. Exit code 0 only on success.\n" +
         ProcessLimitsHelp();
}

}  // namespace

void RegisterTrain(CLI::App& app) {
  auto o = std::make_shared<TrainCliOptions>();
  auto* sub = app.add_subcommand("train", TrainDescription());
  sub->add_option("--data", o->data_path, "training table (CSV, see above)")
      ->required()
      ->check(CLI::ExistingFile);
  auto* out = sub->add_option("--out", o->out_path,
                              "model file to write (JSON, atomically); required unless "
                              "--hidden-sweep");
  sub->add_option("--hidden", o->hidden,
                  "tansig neurons in the hidden layer (0-200; 0 = no hidden layer, a linear\n"
                  "network); 'evidence': the size in {0, 4, 6, 8} with the highest log\n"
                  "evidence ln P(D|alpha,beta) (MacKay 1992);\n"
                  "'auto': the size in {4, 6, 8, 10, 12} with the lowest 5-fold cross-\n"
                  "validation error (normalized RMS; 35 fits, slow). With --trainbr-matlab\n"
                  "'evidence' and 'auto' mean 6 (the paper's size)")
      ->capture_default_str();
  AddSeedOption(sub, &o->seed, "seed of the Nguyen-Widrow initialization; restart k uses seed + k")
      ->capture_default_str();
  sub->add_option("--restarts", o->restarts,
                  "train this many networks (seeds seed..seed+K-1) and keep the one with the\n"
                  "highest log evidence ln P(D|alpha,beta) (MacKay 1992)")
      ->capture_default_str()
      ->check(NumberIn(1, 1000));
  sub->add_option("--epochs", o->epochs, "trainbr epoch limit (MATLAB default 1000)")
      ->capture_default_str()
      ->check(NumberIn(0, 1000000));
  auto* sweep = sub->add_option(
      "--hidden-sweep", o->hidden_sweep,
      "A..B: instead of writing a model, report for each hidden size A..B the training RMS\n"
      "error (um, s), gamma (effective number of parameters), log evidence and k-fold\n"
      "cross-validation RMS error, so the size can be picked as in the paper; 1 <= A <= B <= 200");
  sub->add_option("--folds", o->folds, "k of k-fold cross-validation for --hidden-sweep")
      ->capture_default_str()
      ->check(NumberIn(2, 1000));
  sub->add_flag("--trainbr-matlab", o->trainbr_matlab,
                "the paper's MATLAB trainbr setting: 5-6-2 (or --hidden N) trained to\n"
                "trainbr's own stopping criteria (mu_max, min_grad, --epochs); no size search");
  sub->add_flag("--ard", o->ard,
                "after each trainbr fit, continue with one weight-decay alpha per\n"
                "input's first-layer weights and one for all other weights (MacKay's\n"
                "automatic relevance determination: inputs the data do not support are\n"
                "shrunk), kept only if it took a step and its log evidence is higher;\n"
                "every size fit, restart and noise fold, and every fit of --hidden-sweep\n"
                "(src/product/nn/trainbr.h TrainOptions::ard). With --stop-by-cv the folds\n"
                "choose trainbr's epochs without ARD. Better from about 100 rows and for\n"
                "settle time; docs/network.md");
  sub->add_flag("--stop-by-cv", o->stop_by_cv,
                "stop at the epoch count with the lowest 5-fold cross-validation error\n"
                "(measured in scripts/bench_peers.sh, not better than trainbr's own stopping;\n"
                "src/product/nn/model.h Stopping)");
  sub->add_option("--change", o->change,
                  "R brnn's stopping rule: stop when the objective F = beta ssE + alpha ssX\n"
                  "(dimensionless, normalized targets) changed by less than this between each\n"
                  "of the last 4 epochs; 0 = off (MATLAB). Default 0.001 (brnn's), not allowed\n"
                  "with --trainbr-matlab")
      ->check(NumberIn(0.0, 1e6));
  sub->add_option("--noise-folds", o->noise_folds,
                  "K of the K-fold cross-validation that sets each output's noise level")
      ->capture_default_str()
      ->check(NumberIn(2, 1000));
  sub->add_option("--threads", o->threads,
                  "threads for restarts, stopping/noise folds and sweep fits (0 = all cores);\n"
                  "the result is identical for any count")
      ->capture_default_str()
      ->check(NumberIn(0, 256));
  sub->add_flag("--json", o->json, "machine output: JSON summary on stdout");
  sub->add_option("--family", o->family,
                  "auto (default): the family choice by cross-validated error; network: the\n"
                  "Bayesian-regularized network; gp: a Gaussian process (ARD Matern 5/2);\n"
                  "linear: least squares (on log columns a power law)")
      ->check(CLI::IsMember({"auto", "network", "gp", "linear"}));
  sub->add_option("--transform", o->transform,
                  "log: every strictly positive column (all inputs and targets of a valid\n"
                  "table) on a log scale (a linear fit becomes a power law); identity: raw\n"
                  "columns; auto: both, chosen by cross-validated error. Default auto\n"
                  "(identity with --family network)")
      ->check(CLI::IsMember({"auto", "log", "identity"}));
  sub->add_option("--choice", o->choice,
                  "stack (default): per output a convex combination of the candidates' held-out\n"
                  "predictions, shrunk toward the power law (all weight on it until the\n"
                  "combination beats it clearly); hard: one candidate per output (the\n"
                  "simplest within one standard error, a candidate leaving the power law only\n"
                  "by 2 standard errors; the default of earlier versions)")
      ->capture_default_str()
      ->check(CLI::IsMember({"stack", "hard"}));
  out->excludes(sweep);
  // The flags that only the network has (they imply --family network).
  std::vector<CLI::Option*> network_options;
  for (const char* name : {"--hidden", "--restarts", "--epochs", "--hidden-sweep", "--folds",
                           "--trainbr-matlab", "--ard", "--stop-by-cv", "--change",
                           "--noise-folds"})
    network_options.push_back(sub->get_option(name));
  sub->callback([o, network_options] {
    o->network_flags.clear();
    for (const CLI::Option* opt : network_options)
      if (opt->count() > 0) o->network_flags += " " + opt->get_name();
    Run(*o);
  });
}

}  // namespace whirl::cli
