#pragma once
// A trained elongation-feature model: the network of nn/network.h with its mapminmax scalings,
// names and units, training domain, training summary and Laplace posterior; JSON file I/O; and
// prediction with a standard deviation.
//
// Predictive uncertainty (MacKay 1992 section 4 "error bars"; Bishop 1995 section 10.3), per
// output k at input x, in the normalized target space:
//   var_k(x) = sigma_k^2 + g_k(x)' A^-1 g_k(x),
//   sigma_k^2 = the noise variance of output k (schema 2): calibrated by K-fold cross-
//               validation when the model is trained (CalibrateOutputNoise below):
//               sigma_k^2 = the smallest level at which +-1 predictive sigma,
//               sqrt(sigma_k^2 + v_ik), covers 68.27 % of the held-out errors r_ik (bisection;
//               coverage is monotone in sigma_k^2), r_ik the held-out error of the fold model at
//               row i and v_ik its weight-uncertainty term g' A^-1 g there (normalized units of
//               the full model).
//               Schema 1 files (one level for both outputs, trainbr's sigma_nu^2 = 1 / (2 beta) =
//               ssE / (n - gamma)) still load, with sigma_k^2 = sigma_nu^2 for both outputs.
//               Why: trainbr's one level is ssE / (n - gamma) over both outputs; with 20 rows
//               gamma nears n and it shrinks, with 500 rows one output's noise inflates the
//               other's (coverage measured in docs/network.md).
//   A^-1 = (2 (beta J'J + alpha I))^-1        (posterior covariance of w, J at the final weights),
//   g_k(x) = d y_k / d w at x (flat order, nn/network.h),
// with MATLAB's alpha, beta (F = beta ssE + alpha ssX, see nn/trainbr.h for why the factors 2).
// In original units: stddev_k = sqrt(var_k) * (xmax_k - xmin_k) / 2 (mapminmax half range; 1 for
// a constant target). The mean is the network output mapped back by mapminmax.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/process.h"
#include "nn/network.h"
#include "nn/trainbr.h"

namespace whirl::nn {

/// A named network input or output.
struct VariableInfo {
  std::string name;  ///< column name, e.g. "hardness_hrc"
  std::string unit;  ///< e.g. "HRC"
};

struct Model {
  static constexpr int kSchemaVersion = 2;  ///< 1 still loads (one noise level)
  static constexpr const char* kFormat = "whirl-nn-model";

  Network network;                          ///< weights in the normalized space
  MapMinMax input_scaling;                  ///< mapminmax of the five inputs (training ranges)
  MapMinMax target_scaling;                 ///< mapminmax of the two targets
  std::vector<VariableInfo> inputs;         ///< kInputColumns with kInputUnits, in order
  std::vector<VariableInfo> outputs;        ///< kTargetColumns with kTargetUnits, in order
  Eigen::VectorXd domain_min;               ///< per input: smallest training value, original units
  Eigen::VectorXd domain_max;               ///< per input: largest training value, original units
  TrainSummary training_summary;            ///< of the chosen restart
  std::uint64_t seed = 0;                   ///< base seed of the restart series (--seed)
  std::uint64_t init_seed = 0;              ///< seed of the chosen restart (seed + its index)
  int restarts = 1;                         ///< number of restarts trained
  std::vector<RestartRecord> restart_runs;  ///< every restart (seed, log evidence, ...)
  TrainOptions train_options;               ///< the trainbr options used
  std::string training_data;                ///< provenance: file name of the training table
  int training_samples = 0;                 ///< Q
  std::string error_space = "normalized";   ///< errors measured in the mapminmax target space
  double noise_variance = 0;                ///< trainbr's sigma_nu^2 = 1 / (2 beta), normalized
  Eigen::VectorXd output_noise_variance;    ///< sigma_k^2 per output, normalized target units
  std::string noise_calibration;            ///< how sigma_k^2 was obtained (provenance)
  std::string stopping;  ///< how the epoch limit was set ("training.stopping"; optional key)
  /// How the hidden size was set ("training.hidden_selection"; optional key).
  std::string hidden_selection;
  Eigen::MatrixXd posterior_covariance;  ///< A^-1, N x N, flat order (see header comment)

  /// Throws InputError naming the key and the rule if anything is missing or inconsistent.
  void Validate() const;
};
// The model file (model.cpp): every key checked, schema 1 files still load (ReadUncertainty).
void to_json(nlohmann::json& j, const Model& m);
/// Validates everything (schema version, sizes, finiteness, names); InputError names the key.
void from_json(const nlohmann::json& j, Model& m);

/// The inputs and outputs of every model, with their units, in order (kInputColumns with
/// kInputUnits, kTargetColumns with kTargetUnits): a model file must list exactly these.
std::vector<VariableInfo> ExpectedInputs();
std::vector<VariableInfo> ExpectedOutputs();

/// Limits of a model file (LoadModel), checked before anything is allocated: at most kMaxLayers
/// layer sizes, each in [1, kMaxLayerSize] neurons, at most kMaxParameters weights and biases
/// (8 MB), training epochs in [0, kMaxEpochs] (as `whirl train --epochs`).
inline constexpr std::size_t kMaxLayers = 8;
inline constexpr double kMaxLayerSize = 1000;
inline constexpr double kMaxParameters = 1e6;
inline constexpr double kMaxEpochs = 1e6;

/// Reads and validates a model file. A wrong, truncated or inconsistent file is an InputError
/// whose message names the file and the offending key.
Model LoadModel(const std::filesystem::path& path);
/// Writes the model as JSON atomically (round-trip double formatting, so reloading predicts
/// bit-identically).
void SaveModel(const std::filesystem::path& path, const Model& model);

// Prediction (model_predict.cpp).
struct Prediction {
  Features mean;    ///< network output, original units
  Features stddev;  ///< predictive standard deviation (noise + weight uncertainty), original units
  bool outside_domain = false;                     ///< some input lies outside the training domain
  std::vector<std::string> outside_domain_fields;  ///< names of those inputs, in input order
  Features noise_stddev;  ///< the noise part alone, sqrt(sigma_nu^2) * half range
};

/// Rows outside the training domain, summarized for one warning line (whirl predict prints this
/// instead of one line per row; the per-row list is in its --json output).
struct OutsideDomainSummary {
  int rows = 0;                ///< predictions with outside_domain set
  std::size_t first_row = 0;   ///< index of the first such prediction (valid when rows > 0)
  std::vector<int> per_input;  ///< per model input: rows in which that input is outside
  std::vector<std::string> input_names;  ///< model input names, same order as per_input
  /// "552 of 1000 rows lie outside the training domain (hardness_hrc in 300 rows, ...; first:
  /// <first>)".
  std::string Describe(int total_rows, const std::string& first) const;
};
OutsideDomainSummary SummarizeOutsideDomain(const Model& model,
                                            const std::vector<Prediction>& predictions);

/// Prediction for one process (see the header comment for the formula).
Prediction Predict(const Model& model, const ProcessInputs& inputs);
/// Predictions for many processes (one forward pass for the means).
std::vector<Prediction> PredictBatch(const Model& model, const std::vector<ProcessInputs>& inputs);

// Training (model_train.cpp): TrainModel with its default, the hidden size and epoch limit
// choices, and the check of a trained model for flat outputs.
/// When training stops.
///   kCrossValidated (measured, not the default): the epoch limit is chosen by K-fold
///   cross-validation: each fold
///     trains with trainbr from the Nguyen-Widrow initialization of `seed` and records its
///     held-out squared error (normalized by the table's mapminmax half ranges, both outputs
///     equally) after every epoch; the limit is the epoch count E in [1, train.epochs] with the
///     lowest sum over folds (ties: the smallest E), and the model is trained with epochs = E.
///     Why: with 20 rows trainbr run to convergence reaches gamma = 30-40 of n = 40 and may
///     overfit. In scripts/bench_peers.sh it did NOT beat kTrainbrMatlab (docs/network.md), so
///     it stays an option (--stop-by-cv).
///   kTrainbrMatlab (default): trainbr's own stopping (MATLAB's criteria, at most train.epochs
///     epochs, plus R brnn's rule when train.change > 0, as in DefaultTrainingOptions); with
///     change = 0 what the LibTorch cross-check compares against.
enum class Stopping { kTrainbrMatlab, kCrossValidated };

/// How `whirl train` builds a model.
struct ModelTrainOptions {
  /// Non-empty: one tansig hidden layer whose size is the candidate with the lowest k-fold
  /// cross-validation error (SweepRow::cv_rms_normalized of nn/selection.h, stopping_folds
  /// folds, one start per fit; ties: the earlier candidate); hidden_sizes is then ignored.
  /// `whirl train --hidden auto` uses {4, 6, 8, 10, 12}; its default (`--hidden evidence`,
  /// hidden_by_evidence below) uses {0, 4, 6, 8}, where 0 is no hidden layer (a linear network,
  /// evidence choice only). Why (scripts/bench_peers.sh, docs/network.md): at 100 rows six neurons
  /// shared by two outputs are too few; at 20 rows the evidence sometimes prefers a collapsed
  /// network that ignores its inputs (FlatOutputs) to every fitted one, and a linear fit then
  /// has more evidence.
  std::vector<int> hidden_candidates;
  /// How a size among hidden_candidates is chosen: false = k-fold cross-validation (above);
  /// true = the highest log evidence ln P(D | alpha, beta) of the fit on all rows (MacKay 1992,
  /// model comparison; nn/trainbr.h LogEvidence, which counts the 2^A H! / (H - A)! equivalent
  /// networks of A active neurons), one fit per candidate (restarts each), then the noise
  /// calibration of the chosen model only.
  bool hidden_by_evidence = false;
  Stopping stopping = Stopping::kTrainbrMatlab;  ///< see Stopping
  int stopping_folds = 5;  ///< K of the stopping cross-validation (min(K, rows); rows >= 4)
  /// Restarts and folds run on this many threads (core/parallel.h; <= 0: all cores). The model
  /// is identical for any thread count.
  int threads = 0;
  std::vector<int> hidden_sizes = {6};  ///< tansig hidden layers (paper: one layer of 6)
  std::uint64_t seed = 1;               ///< restart k initializes with seed + k
  int restarts = 1;                     ///< keep the highest log evidence of this many runs
  TrainOptions train;                   ///< trainbr options (MATLAB defaults)
  /// Per-output noise by K-fold cross-validation (0 = keep trainbr's one level for both outputs;
  /// else min(noise_folds, rows) folds, each trained with min(restarts, 3) restarts).
  int noise_folds = 5;
};

/// R brnn's default `change` (TrainOptions::change), the stopping rule of the default training.
inline constexpr double kBrnnChange = 0.001;

/// The default of `whirl train` (measured with scripts/bench_peers.sh; figures in
/// docs/network.md): no hidden layer (linear) or one tansig hidden layer of
/// 4, 6 or 8 neurons, the choice of the highest log evidence (hidden_by_evidence), each fit
/// trainbr with R brnn's stopping rule (TrainOptions::change = kBrnnChange), then 5-fold
/// cross-validated noise per output.
/// Why: trainbr run to MATLAB's own criteria takes many more epochs for the same test error as
/// brnn's rule; six neurons shared by two outputs are too few at 100 rows, where the evidence
/// picks 8. Available, not the default: TrainOptions::ard (`--ard`).
ModelTrainOptions DefaultTrainingOptions();

/// ModelTrainOptions::hidden_sizes for a network with `size` hidden neurons: none for 0 (a linear
/// 5-2 network, `--hidden 0` and the evidence choice's first candidate), else one tansig layer.
std::vector<int> HiddenLayers(int size);

/// Progress of TrainModel: restart index (0-based) and the epoch just finished.
using ModelProgress = std::function<void(int restart, const EpochInfo& info)>;

/// Fits mapminmax on the table, trains `restarts` networks and returns the chosen model.
/// `data_name` goes into the model's provenance. Throws InputError if the table has no targets,
/// fewer than 2 rows or inconsistent lengths.
Model TrainModel(const ProcessTable& table, const ModelTrainOptions& options,
                 const std::string& data_name, const ModelProgress& progress = {});

/// An output the trained network hardly lets depend on the inputs. On small noisy tables trainbr's
/// evidence can prefer the collapsed fixed point (alpha large, every weight near 0, gamma near 0):
/// the network then predicts about one value for every process (scripts/bench_peers.sh: 3 of 20
/// Friedman tables of 20 rows, at every hidden size; docs/network.md).
struct FlatOutput {
  int output = 0;            ///< index into Features (kTargetColumns)
  double spread_ratio = 0;   ///< sd of the network's mean predictions / sd of the targets
  double prediction_sd = 0;  ///< sd of the mean predictions over the rows, original units
  double target_sd = 0;      ///< sd of the targets over the rows, original units
};
/// An output is flat when its spread_ratio is below this. Measured on the benchmark's 20-row
/// Friedman tables: collapsed fits have ratios below 1e-4, every other fit 0.3 or more.
inline constexpr double kFlatSpreadRatio = 0.05;
/// The flat outputs of `model` over the rows of `table` (its training table): population sd of
/// the network's mean predictions against the sd of the targets, per output. Outputs whose targets
/// are constant are skipped. InputError if the table has no targets.
std::vector<FlatOutput> FlatOutputs(const Model& model, const ProcessTable& table);
/// One sentence for the user about `flat` (non-empty), naming the outputs, their ratios and
/// gamma; whirl train prints it as a warning.
std::string DescribeFlatOutputs(const Model& model, const std::vector<FlatOutput>& flat);

/// The epoch limit of Stopping::kCrossValidated (see there), from `folds` folds (row q held out in
/// fold q % folds) of `table`; `curve`, if set, receives the summed held-out squared error after
/// 1..options.train.epochs epochs. InputError unless 2 <= folds <= rows.
int ChooseEpochsByCrossValidation(const ProcessTable& table, const ModelTrainOptions& options,
                                  int folds, std::vector<double>* curve = nullptr);

// Calibration of the predictive sd (model_calibration.cpp).
/// Sets model->output_noise_variance and noise_calibration by K-fold cross-validation on the
/// table the model was trained on (see the header comment). InputError if folds < 2 or the table
/// has fewer rows than folds. `fold_models`, if given (one per fold), are the fold fits already
/// made: TrainModel of the rows outside fold f (row q in fold q % folds) with the fold options
/// this function sets (the family choice's refits of a network, family/family.cpp); they are used
/// instead of refitting, and the caller answers for their being those fits.
void CalibrateOutputNoise(const ProcessTable& table, const ModelTrainOptions& options, int folds,
                          Model* model, const std::vector<Model>* fold_models = nullptr);

// Tables as matrices (model_predict.cpp).
/// Inputs (5 x Q) and targets (2 x Q) of a table, original units.
Eigen::MatrixXd InputMatrix(const std::vector<ProcessInputs>& inputs);
Eigen::MatrixXd TargetMatrix(const std::vector<Features>& targets);

}  // namespace whirl::nn
