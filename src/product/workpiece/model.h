#pragma once
// The workpiece model every command that predicts uses (predict, curve, plan, compare, evaluate,
// machine, demo): either the paper's Bayesian-regularized network (nn/model.h) or a choice among
// model families (family/family.h: power law, Gaussian process, network, each output on its own),
// with one prediction: mean, standard deviation and the training-domain guard.
//
// Prediction (Predict, PredictBatch), per output, original units:
//   network: nn::PredictBatch (Laplace sd with cross-validated noise, nn/model.h);
//   family:  family::PredictChoice (sd in the candidate's transformed space, mapped back by the
//            delta method, family/transform.h); noise_stddev is not separated (left 0).
//   domain:  outside_domain is set when an input lies outside [smallest, largest] training value
//            of that input (original units), and outside_domain_fields names those inputs in
//            input order; the commands turn it into a warning or an error (cli/common.h).
//
// Files (LoadWorkpieceModel, SaveWorkpieceModel):
//   a network is written as the network file of nn/model.h (format "whirl-nn-model", schema 2),
//     byte for byte what nn::SaveModel writes, so paper-mode files, the LibTorch cross-check and
//     the TorchScript export read it; network files of schema 1 and 2 load;
//   a family choice is written as format "whirl-workpiece-model", schema_version 3 (continuing
//     the network file's numbering), with the keys
//       "kind": "family"; "inputs", "outputs": names and units (nn::ExpectedInputs/Outputs);
//       "domain": {"min", "max"} per input, original units; "training": {"data", "samples"};
//       "choice": family::Choice (family/family.h, models, CV table and the per-output choice).
//   Every key is checked; an error is an InputError naming the file and the key.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "core/process.h"
#include "family/family.h"
#include "nn/model.h"

namespace whirl::workpiece {

/// Mean, sd, domain flags (nn/model.h Prediction; see the header comment for a family).
using Prediction = nn::Prediction;

struct WorkpieceModel {
  static constexpr int kSchemaVersion = 3;
  static constexpr const char* kFormat = "whirl-workpiece-model";
  enum class Kind { kNetwork, kFamily };
  Kind kind = Kind::kNetwork;
  nn::Model network;      ///< Kind::kNetwork
  family::Choice choice;  ///< Kind::kFamily
  /// Per input, the smallest and largest training value, original units (a network: its own).
  Eigen::VectorXd domain_min, domain_max;
  std::string training_data;  ///< provenance: file name of the training table
  int training_samples = 0;

  bool IsNetwork() const { return kind == Kind::kNetwork; }
  /// "network 5-6-2" or "max_elongation_um: linear/log, settle_time_s: gp-matern52-constant/log".
  std::string Describe() const;
  /// The model's family in words for a legend: "network", "power law" (linear/log), "linear",
  /// "Gaussian process", "stack"; two outputs of different families "power law / Gaussian
  /// process" (max elongation / settle time).
  std::string FamilyLabel() const;
};

/// A network as a workpiece model (its domain and provenance copied).
WorkpieceModel FromNetwork(nn::Model network);
/// A family choice fitted on `table` (the domain is the table's input ranges).
WorkpieceModel FromChoice(family::Choice choice, const ProcessTable& table,
                          const std::string& data_name);

/// Predictions for many processes; InputError if an input is not finite.
std::vector<Prediction> PredictBatch(const WorkpieceModel& model,
                                     const std::vector<ProcessInputs>& inputs);
Prediction Predict(const WorkpieceModel& model, const ProcessInputs& inputs);

/// Rows outside the training domain summarized for one warning line (nn/model.h).
nn::OutsideDomainSummary SummarizeOutsideDomain(const std::vector<Prediction>& predictions);

/// Reads either file of the header comment; InputError naming the file and the key otherwise.
WorkpieceModel LoadWorkpieceModel(const std::filesystem::path& path);
/// Writes the file of the header comment atomically.
void SaveWorkpieceModel(const std::filesystem::path& path, const WorkpieceModel& model);
/// The network of the file at `path`, for the commands that need one (`command`: "crosscheck",
/// "export"). A family model is the InputError "model file '<path>': <command> needs a network
/// model; this file holds <Describe()>, which is not a network (train one with
/// 'whirl train --family network')".
nn::Model LoadNetworkModel(const std::filesystem::path& path, const std::string& command);

/// How `whirl train` builds a model (TrainWorkpieceModel).
enum class FamilyFlag { kAuto, kNetwork, kGaussianProcess, kLinear };
enum class TransformFlag { kAuto, kLog, kIdentity };
FamilyFlag ParseFamilyFlag(const std::string& s);  ///< "auto|network|gp|linear"; else InputError
TransformFlag ParseTransformFlag(const std::string& s);  ///< "auto|log|identity"; else InputError

struct TrainOptions {
  FamilyFlag family = FamilyFlag::kAuto;
  TransformFlag transform = TransformFlag::kAuto;
  /// The network's training (nn/model.h), used when family is kNetwork with the identity
  /// transform: the network trained on the raw columns, written as a network file.
  nn::ModelTrainOptions network = nn::DefaultTrainingOptions();
  /// The choice's options; its candidates are replaced by Candidates(family, transform).
  family::ChoiceOptions choice;
};

/// The candidates of a choice for the flags:
///   kAuto:            ChoiceOptions::DefaultCandidates() (power law, linear, a GP with a
///                     power-law mean on log columns, two ARD GPs, a 2-unit network),
///   kLinear:          linear/log, linear/identity,
///   kGaussianProcess: gp-matern52-linear/log, gp-matern52-constant/identity,
///   kNetwork:         network-evidence/log, network-evidence/identity,
/// keeping those of `transform` (kAuto: both). Listed from the simplest (one-standard-error
/// rule, family/family.h).
std::vector<family::Candidate> Candidates(FamilyFlag family, TransformFlag transform);

/// family kNetwork with transform kIdentity: nn::TrainModel with options.network (the network of
/// earlier versions; `progress` receives its epochs); otherwise family::ChooseFamily over
/// Candidates(family, transform) (also when only one candidate is left: its CV row is reported).
/// InputError for a bad table or options.
WorkpieceModel TrainWorkpieceModel(const ProcessTable& table, const TrainOptions& options,
                                   const std::string& data_name,
                                   const nn::ModelProgress& progress = {});

/// The choice's CV table as text: one line per candidate with its cross-validated RMSE per output
/// (um, s), the score and the fit time, and the chosen candidate of each output marked; then a
/// "note:" line per output with family::Choice::notes.
std::string FormatChoiceTable(const family::Choice& choice);
/// The same table as JSON for `whirl train --json`: per candidate its name, cv_rmse, score and
/// fit_ms (the fit time, which the model file does not store).
nlohmann::json ChoiceTableJson(const family::Choice& choice);

}  // namespace whirl::workpiece
