// Training a model (nn/model.h): the default training, the choice of the hidden size (by log
// evidence or cross-validation), the epoch limit by cross-validation, and the check for flat
// outputs of a trained model.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/numbers.h"
#include "core/parallel.h"
#include "nn/model.h"
#include "nn/selection.h"

namespace whirl::nn {
namespace {

// ModelTrainOptions::hidden_by_evidence: one fit per candidate size (in parallel, each on one
// thread; the choice happens after all fits, in candidate order: the same for any thread count).
Model TrainModelHiddenByEvidence(const ProcessTable& table, const ModelTrainOptions& options,
                                 const std::string& data_name) {
  const int rows = static_cast<int>(table.inputs.size());
  std::vector<Model> fits(options.hidden_candidates.size());
  ParallelFor(fits.size(), options.threads, [&](std::size_t i) {
    ModelTrainOptions one = options;
    one.hidden_candidates.clear();
    one.hidden_sizes = HiddenLayers(options.hidden_candidates[i]);
    // linear: every start reaches the same fit (to the stopping rule), so one is enough
    if (one.hidden_sizes.empty()) one.restarts = 1;
    one.noise_folds = 0;  // calibrated below, for the chosen size only
    one.threads = 1;
    fits[i] = TrainModel(table, one, data_name);
  });
  std::size_t best = 0;
  std::string tried;
  for (std::size_t i = 0; i < fits.size(); ++i) {
    const double ev = fits[i].training_summary.log_evidence;
    tried += (tried.empty() ? "" : ", ") + std::to_string(options.hidden_candidates[i]) + ": " +
             MessageNumber(ev);
    if (ev > fits[best].training_summary.log_evidence) best = i;
  }
  Model m = std::move(fits[best]);
  const int size = options.hidden_candidates[best];
  m.hidden_selection = "hidden size " + std::to_string(size) + " of the highest log evidence (" +
                       tried + ")" + (size == 0 ? "; 0 = no hidden layer (linear)" : "");
  ModelTrainOptions chosen = options;
  chosen.hidden_candidates.clear();
  chosen.hidden_sizes = HiddenLayers(size);
  if (size == 0) chosen.restarts = 1;
  if (options.noise_folds > 0 && rows >= 4)
    CalibrateOutputNoise(table, chosen, std::min(options.noise_folds, rows), &m);
  return m;
}

// ModelTrainOptions::hidden_candidates: one tansig layer, size by k-fold CV (nn/selection.h).
Model TrainModelAutoHidden(const ProcessTable& table, const ModelTrainOptions& options,
                           const std::string& data_name, const ModelProgress& progress) {
  const int rows = static_cast<int>(table.inputs.size());
  ModelTrainOptions fixed = options;
  fixed.hidden_candidates.clear();
  if (rows < 4) {
    fixed.hidden_sizes = HiddenLayers(options.hidden_candidates.front());
    Model m = TrainModel(table, fixed, data_name, progress);
    m.hidden_selection = "hidden size " + std::to_string(options.hidden_candidates.front()) +
                         ", the first candidate: " + std::to_string(rows) +
                         " rows are too few to choose";
    return m;
  }
  if (options.hidden_by_evidence) return TrainModelHiddenByEvidence(table, options, data_name);
  SweepOptions sweep;
  sweep.folds = std::min(options.stopping_folds, rows);
  sweep.seed = options.seed;
  sweep.train = options.train;
  sweep.threads = options.threads;
  std::string tried;
  double best_cv = std::numeric_limits<double>::infinity();
  int best = options.hidden_candidates.front();
  for (int h : options.hidden_candidates) {
    sweep.hidden_min = sweep.hidden_max = h;
    const SweepRow row = HiddenSweep(table, sweep).front();
    tried += (tried.empty() ? "" : ", ") + std::to_string(h) + ": " +
             FormatSignificant(row.cv_rms_normalized, 4);
    if (row.cv_rms_normalized < best_cv) {
      best_cv = row.cv_rms_normalized;
      best = h;
    }
  }
  fixed.hidden_sizes = {best};
  Model m = TrainModel(table, fixed, data_name, progress);
  m.hidden_selection = "hidden size " + std::to_string(best) + " chosen by " +
                       std::to_string(sweep.folds) +
                       "-fold cross-validation (lowest cv_rms_normalized; " + tried + ")";
  return m;
}

}  // namespace

std::vector<int> HiddenLayers(int size) {
  return size == 0 ? std::vector<int>{} : std::vector<int>{size};
}

ModelTrainOptions DefaultTrainingOptions() {
  ModelTrainOptions o;
  o.hidden_candidates = {0, 4, 6, 8};
  o.hidden_by_evidence = true;
  o.train.change = kBrnnChange;
  return o;
}

namespace {

void CheckTrainingTable(const ProcessTable& table, const ModelTrainOptions& options) {
  if (table.targets.size() != table.inputs.size())
    throw InputError(table.source + ": the training table needs the target columns " +
                     kTargetColumns[0] + " and " + kTargetColumns[1]);
  if (table.inputs.size() < 2)
    throw InputError(table.source + ": " + std::to_string(table.inputs.size()) +
                     " training rows; at least 2 are needed");
  for (std::size_t h = 0; h < options.hidden_sizes.size(); ++h)
    if (options.hidden_sizes[h] < 1)
      throw InputError("hidden size " + std::to_string(options.hidden_sizes[h]) + ": must be >= 1");
}

// The trainbr options of the fit on all rows: options.train, with the epoch limit chosen by
// cross-validation under Stopping::kCrossValidated. `stopping` receives how it stops (the
// model's provenance, Model::stopping).
TrainOptions StoppingRule(const ProcessTable& table, const ModelTrainOptions& options,
                          std::string* stopping) {
  const int rows = static_cast<int>(table.inputs.size());
  TrainOptions train = options.train;
  *stopping = "trainbr (MATLAB): run to its own stopping criteria, at most " +
              std::to_string(train.epochs) + " epochs";
  if (train.change > 0)
    *stopping =
        "trainbr with R brnn's rule: stop when F = beta ssE + alpha ssX changed by less "
        "than " +
        FormatNumber(train.change) +
        " over the last 4 epochs, else MATLAB's "
        "criteria, at most " +
        std::to_string(train.epochs) + " epochs";
  if (options.stopping == Stopping::kCrossValidated && rows >= 4) {
    const int folds = std::min(options.stopping_folds, rows);
    train.epochs = ChooseEpochsByCrossValidation(table, options, folds);
    *stopping = "epochs chosen by " + std::to_string(folds) +
                "-fold cross-validation: " + std::to_string(train.epochs) + " of at most " +
                std::to_string(options.train.epochs) +
                " (the epoch count with the lowest summed held-out squared error, normalized)";
  }
  if (train.ard)
    *stopping +=
        "; then the ARD stage (one alpha per input's weights, the same stopping rule "
        "and epoch limit, counted again), kept if it took a step and its log evidence "
        "is higher";
  return train;
}

// The chosen restart of `r` as the model's network, summary, provenance, training domain
// (`x_raw`, the inputs in original units) and trainbr's one noise level for both outputs.
void TakeRestart(RestartResult r, const ModelTrainOptions& options, const TrainOptions& train,
                 const Eigen::MatrixXd& x_raw, const std::string& data_name, Model* model) {
  Model& m = *model;
  m.network = std::move(r.best.network);
  m.inputs = ExpectedInputs();
  m.outputs = ExpectedOutputs();
  m.domain_min = x_raw.rowwise().minCoeff();
  m.domain_max = x_raw.rowwise().maxCoeff();
  m.training_summary = r.best.summary;
  m.seed = options.seed;
  m.init_seed = r.best.init_seed;
  m.restarts = options.restarts;
  m.restart_runs = r.runs;
  m.train_options = train;
  m.training_data = data_name;
  m.training_samples = static_cast<int>(x_raw.cols());
  m.noise_variance = r.best.summary.noise_variance;
  m.output_noise_variance = Eigen::VectorXd::Constant(Features::kCount, m.noise_variance);
  m.noise_calibration = "trainbr: one noise level 1/(2 beta) for every output";
  m.posterior_covariance = std::move(r.best.posterior_covariance);
}

}  // namespace

Model TrainModel(const ProcessTable& table, const ModelTrainOptions& options,
                 const std::string& data_name, const ModelProgress& progress) {
  CheckTrainingTable(table, options);
  if (!options.hidden_candidates.empty())
    return TrainModelAutoHidden(table, options, data_name, progress);
  const Eigen::MatrixXd x_raw = InputMatrix(table.inputs);
  const Eigen::MatrixXd t_raw = TargetMatrix(table.targets);
  Model m;
  m.hidden_selection =
      "fixed: " + std::to_string(options.hidden_sizes.size()) + " hidden layer(s) as given";
  m.input_scaling = MapMinMax::Fit(x_raw);
  m.target_scaling = MapMinMax::Fit(t_raw);
  TrainingData data{m.input_scaling.Apply(x_raw), m.target_scaling.Apply(t_raw), m.target_scaling};
  std::vector<int> sizes = {ProcessInputs::kCount};
  sizes.insert(sizes.end(), options.hidden_sizes.begin(), options.hidden_sizes.end());
  sizes.push_back(Features::kCount);
  if (options.train.regularization != Regularization::kBayesian)
    throw InputError("a model file needs Bayesian regularization (its Laplace uncertainty)");
  const TrainOptions train = StoppingRule(table, options, &m.stopping);
  TakeRestart(TrainBrRestarts(data, sizes, options.seed, options.restarts, train, progress,
                              options.threads),
              options, train, x_raw, data_name, &m);
  m.Validate();
  const int rows = static_cast<int>(table.inputs.size());
  if (options.noise_folds > 0 && rows >= 4)
    CalibrateOutputNoise(table, options, std::min(options.noise_folds, rows), &m);
  return m;
}

std::vector<FlatOutput> FlatOutputs(const Model& model, const ProcessTable& table) {
  if (table.targets.size() != table.inputs.size() || table.inputs.empty())
    throw InputError(table.source + ": the flatness check needs the training rows with targets");
  const Eigen::MatrixXd x = model.input_scaling.Apply(InputMatrix(table.inputs));
  const Eigen::MatrixXd y = model.target_scaling.Reverse(model.network.Forward(x));
  const Eigen::MatrixXd t = TargetMatrix(table.targets);
  auto sd = [](const Eigen::RowVectorXd& v) {
    return std::sqrt((v.array() - v.mean()).square().mean());
  };
  std::vector<FlatOutput> flat;
  for (int k = 0; k < static_cast<int>(t.rows()); ++k) {
    const double target_sd = sd(t.row(k)), prediction_sd = sd(y.row(k));
    if (!(target_sd > 0)) continue;
    const double ratio = prediction_sd / target_sd;
    if (ratio < kFlatSpreadRatio) flat.push_back({k, ratio, prediction_sd, target_sd});
  }
  return flat;
}

std::string DescribeFlatOutputs(const Model& model, const std::vector<FlatOutput>& flat) {
  std::string names, ratios;
  for (std::size_t i = 0; i < flat.size(); ++i) {
    const std::string sep = i == 0 ? "" : (i + 1 == flat.size() ? " and " : ", ");
    names += sep + model.outputs.at(static_cast<std::size_t>(flat[i].output)).name;
    ratios += (i == 0 ? "" : ", ") + MessageNumber(flat[i].spread_ratio);
  }
  const auto& s = model.training_summary;
  return "the network is nearly flat in " + names + ": over the " +
         std::to_string(model.training_samples) +
         " training rows its predictions vary by less than " +
         MessageNumber(100 * kFlatSpreadRatio) + " % of the targets' spread (sd ratio " + ratios +
         "; gamma " + MessageNumber(s.gamma) + " of " + std::to_string(s.parameter_count) + "). " +
         (model.hidden_selection.find("highest log evidence") != std::string::npos
              ? "The evidence preferred it to every size tried, so it predicts "
              : "It predicts ") +
         "about one value for every process, with the cross-validated noise as its "
         "uncertainty. More training rows usually help (docs/network.md)";
}

int ChooseEpochsByCrossValidation(const ProcessTable& table, const ModelTrainOptions& options,
                                  int folds, std::vector<double>* curve) {
  const int rows = static_cast<int>(table.inputs.size());
  if (folds < 2 || rows < folds)
    throw InputError("stopping by cross-validation: " + std::to_string(folds) + " folds for " +
                     std::to_string(rows) + " rows; needs 2 <= folds <= rows");
  const int max_epochs = options.train.epochs;
  if (max_epochs < 1) return max_epochs;
  const Eigen::MatrixXd x_raw = InputMatrix(table.inputs);
  const Eigen::MatrixXd t_raw = TargetMatrix(table.targets);
  const Eigen::VectorXd half = MapMinMax::Fit(t_raw).HalfRange();
  std::vector<int> sizes = {ProcessInputs::kCount};
  sizes.insert(sizes.end(), options.hidden_sizes.begin(), options.hidden_sizes.end());
  sizes.push_back(Features::kCount);
  // fold_sse[f][e-1]: held-out squared error (normalized by the full table's half ranges) of
  // fold f's network after e epochs; a run that stops early keeps its last value.
  std::vector<std::vector<double>> fold_sse(static_cast<std::size_t>(folds));
  ParallelFor(static_cast<std::size_t>(folds), options.threads, [&](std::size_t fi) {
    std::vector<int> tr, te;
    for (int q = 0; q < rows; ++q) (q % folds == static_cast<int>(fi) ? te : tr).push_back(q);
    Eigen::MatrixXd xt(x_raw.rows(), tr.size()), tt(t_raw.rows(), tr.size());
    Eigen::MatrixXd xv(x_raw.rows(), te.size()), tv(t_raw.rows(), te.size());
    for (std::size_t c = 0; c < tr.size(); ++c) {
      xt.col(c) = x_raw.col(tr[c]);
      tt.col(c) = t_raw.col(tr[c]);
    }
    for (std::size_t c = 0; c < te.size(); ++c) {
      xv.col(c) = x_raw.col(te[c]);
      tv.col(c) = t_raw.col(te[c]);
    }
    const MapMinMax xs = MapMinMax::Fit(xt), ts = MapMinMax::Fit(tt);
    const TrainingData data{xs.Apply(xt), ts.Apply(tt), ts};
    const Eigen::MatrixXd xv_n = xs.Apply(xv);
    std::vector<double>& out = fold_sse[fi];
    out.reserve(static_cast<std::size_t>(max_epochs));
    Network net = Network::Zeros(sizes);
    InitNguyenWidrow(options.seed, &net);
    TrainOptions fold_train = options.train;
    fold_train.ard = false;  // the folds choose trainbr's epochs; the ARD stage follows them
    TrainBr(data, net, fold_train, [&](const EpochInfo& info) {
      const Eigen::MatrixXd y = ts.Reverse(info.network->Forward(xv_n));
      out.push_back(((tv - y).array().colwise() / half.array()).square().sum());
    });
    if (out.empty()) out.push_back(std::numeric_limits<double>::infinity());
    out.resize(static_cast<std::size_t>(max_epochs), out.back());
  });
  std::vector<double> total(static_cast<std::size_t>(max_epochs), 0.0);
  for (const auto& f : fold_sse)
    for (int e = 0; e < max_epochs; ++e) total[e] += f[e];
  const int best = static_cast<int>(std::min_element(total.begin(), total.end()) - total.begin());
  if (curve) *curve = total;
  return best + 1;
}

}  // namespace whirl::nn
