// Calibration of the predictive standard deviation (nn/model.h, CalibrateOutputNoise): the noise
// level per output from K-fold cross-validated residuals.
#include <Eigen/Core>
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "nn/model.h"

namespace whirl::nn {
namespace {

// sigma^2: the smallest level at which +-1 predictive sigma (sqrt(sigma^2 + var_w[i])) covers
// 68.27 % of the held-out squared errors r2 (bisection; the coverage is monotone in sigma^2).
double NoiseForCoverage(const std::vector<double>& r2, const std::vector<double>& var_w) {
  constexpr double kOneSigma = 0.6827;
  auto coverage = [&](double s2) {
    int in = 0;
    for (std::size_t i = 0; i < r2.size(); ++i) in += r2[i] <= s2 + var_w[i] ? 1 : 0;
    return static_cast<double>(in) / static_cast<double>(r2.size());
  };
  double lo = 0.0, hi = *std::max_element(r2.begin(), r2.end()) + 1e-300;
  if (coverage(lo) >= kOneSigma) hi = 0.0;
  for (int it = 0; it < 200 && hi > lo; ++it) {
    const double mid = 0.5 * (lo + hi);
    (coverage(mid) >= kOneSigma ? hi : lo) = mid;
  }
  return hi;
}

}  // namespace

void CalibrateOutputNoise(const ProcessTable& table, const ModelTrainOptions& options, int folds,
                          Model* model, const std::vector<Model>* fold_models) {
  const int rows = static_cast<int>(table.inputs.size());
  if (folds < 2 || rows < folds)
    throw InputError("noise calibration: " + std::to_string(folds) + " folds for " +
                     std::to_string(rows) + " rows; needs 2 <= folds <= rows");
  if (fold_models && fold_models->size() != static_cast<std::size_t>(folds))
    throw InputError("noise calibration: " + std::to_string(fold_models->size()) +
                     " fold models for " + std::to_string(folds) + " folds");
  ModelTrainOptions fold_options = options;
  fold_options.noise_folds = 0;
  fold_options.restarts = std::min(options.restarts, 3);
  fold_options.stopping = Stopping::kTrainbrMatlab;  // the epochs the model was trained with
  fold_options.train = model->train_options;
  fold_options.threads = 1;
  const Eigen::VectorXd half = model->target_scaling.HalfRange();
  const int S = Features::kCount;
  // Per fold: (r^2, weight variance) per output and held-out row; gathered in fold order below.
  std::vector<std::vector<std::vector<std::pair<double, double>>>> per_fold(
      static_cast<std::size_t>(folds), std::vector<std::vector<std::pair<double, double>>>(S));
  ParallelFor(static_cast<std::size_t>(folds), options.threads, [&](std::size_t fi) {
    const int f = static_cast<int>(fi);
    ProcessTable train, held;
    train.source = held.source = table.source;
    for (int i = 0; i < rows; ++i) {
      ProcessTable& t = i % folds == f ? held : train;
      t.inputs.push_back(table.inputs[i]);
      t.targets.push_back(table.targets[i]);
    }
    Model trained;
    if (!fold_models) trained = TrainModel(train, fold_options, "fold");
    const Model& fm = fold_models ? (*fold_models)[fi] : trained;
    const std::vector<Prediction> p = PredictBatch(fm, held.inputs);
    const Eigen::VectorXd fold_half = fm.target_scaling.HalfRange();
    for (std::size_t i = 0; i < held.inputs.size(); ++i) {
      const auto mean = p[i].mean.ToArray(), sd = p[i].stddev.ToArray();
      const auto truth = held.targets[i].ToArray();
      for (int k = 0; k < S; ++k) {
        const double r = (truth[k] - mean[k]) / half(k);
        // Weight part of the fold model's variance, in the full model's normalized units.
        const double v =
            (sd[k] * sd[k] - fm.output_noise_variance(k) * fold_half(k) * fold_half(k)) /
            (half(k) * half(k));
        per_fold[fi][k].emplace_back(r * r, std::max(v, 0.0));
      }
    }
  });
  std::vector<std::vector<double>> r2(S), var_w(S);
  for (const auto& fold : per_fold)
    for (int k = 0; k < S; ++k)
      for (const auto& [a, b] : fold[k]) {
        r2[k].push_back(a);
        var_w[k].push_back(b);
      }
  model->output_noise_variance.resize(S);
  for (int k = 0; k < S; ++k) model->output_noise_variance(k) = NoiseForCoverage(r2[k], var_w[k]);
  model->noise_calibration =
      std::to_string(folds) +
      "-fold cross-validation on the training table: per output the "
      "smallest noise variance at which +-1 sigma (noise + weight variance of the fold model) "
      "covers 68.27 % of the held-out errors";
}

}  // namespace whirl::nn
