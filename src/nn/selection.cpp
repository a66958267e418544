#include "nn/selection.h"

#include <cmath>
#include <string>

#include "core/error.h"
#include "nn/model.h"

namespace whirl::nn {

void SweepOptions::Validate(int rows) const {
  if (hidden_min < 1)
    throw InputError("hidden sweep: first size " + std::to_string(hidden_min) + " must be >= 1");
  if (hidden_max < hidden_min)
    throw InputError("hidden sweep: last size " + std::to_string(hidden_max) +
                     " must be >= first size " + std::to_string(hidden_min));
  if (folds < 2 || folds > rows)
    throw InputError("folds = " + std::to_string(folds) +
                     ": must be in [2, rows = " + std::to_string(rows) + "]");
  if (restarts < 1) throw InputError("restarts = " + std::to_string(restarts) + ": must be >= 1");
  train.Validate();
}

void to_json(nlohmann::json& j, const SweepRow& r) {
  auto vec = [](const Eigen::VectorXd& v) {
    return std::vector<double>(v.data(), v.data() + v.size());
  };
  j = nlohmann::json{{"hidden", r.hidden},
                     {"parameter_count", r.parameter_count},
                     {"train_sse_normalized", r.train_sse_normalized},
                     {"train_rms", vec(r.train_rms)},
                     {"gamma", r.gamma},
                     {"log_evidence", r.log_evidence},
                     {"cv_rms", vec(r.cv_rms)},
                     {"cv_rms_normalized", r.cv_rms_normalized}};
}

std::vector<SweepRow> HiddenSweep(const ProcessTable& table, const SweepOptions& options,
                                  const std::function<void(int, int)>& progress) {
  const int Q = static_cast<int>(table.inputs.size());
  if (static_cast<int>(table.targets.size()) != Q)
    throw InputError(table.source + ": the hidden sweep needs the target columns");
  options.Validate(Q);
  const Eigen::MatrixXd x_raw = InputMatrix(table.inputs);
  const Eigen::MatrixXd t_raw = TargetMatrix(table.targets);
  const MapMinMax full_targets = MapMinMax::Fit(t_raw);
  const Eigen::VectorXd half = full_targets.HalfRange();
  const int total = (options.hidden_max - options.hidden_min + 1) * (options.folds + 1);
  int done = 0;
  std::vector<SweepRow> rows;
  for (int h = options.hidden_min; h <= options.hidden_max; ++h) {
    const std::vector<int> sizes = {ProcessInputs::kCount, h, Features::kCount};
    SweepRow row;
    row.hidden = h;
    {
      const MapMinMax xs = MapMinMax::Fit(x_raw);
      const TrainingData data{xs.Apply(x_raw), full_targets.Apply(t_raw), full_targets};
      const RestartResult r =
          TrainBrRestarts(data, sizes, options.seed, options.restarts, options.train);
      row.parameter_count = r.best.summary.parameter_count;
      row.train_sse_normalized = r.best.summary.sse;
      row.train_rms = r.best.summary.rms_error;
      row.gamma = r.best.summary.gamma;
      row.log_evidence = r.best.summary.log_evidence;
      if (progress) progress(++done, total);
    }
    Eigen::VectorXd sq = Eigen::VectorXd::Zero(Features::kCount);
    for (int f = 0; f < options.folds; ++f) {
      std::vector<int> train_idx, test_idx;
      for (int q = 0; q < Q; ++q) (q % options.folds == f ? test_idx : train_idx).push_back(q);
      Eigen::MatrixXd xt(x_raw.rows(), train_idx.size()), tt(t_raw.rows(), train_idx.size());
      Eigen::MatrixXd xv(x_raw.rows(), test_idx.size()), tv(t_raw.rows(), test_idx.size());
      for (std::size_t c = 0; c < train_idx.size(); ++c) {
        xt.col(c) = x_raw.col(train_idx[c]);
        tt.col(c) = t_raw.col(train_idx[c]);
      }
      for (std::size_t c = 0; c < test_idx.size(); ++c) {
        xv.col(c) = x_raw.col(test_idx[c]);
        tv.col(c) = t_raw.col(test_idx[c]);
      }
      const MapMinMax xs = MapMinMax::Fit(xt);
      const MapMinMax ts = MapMinMax::Fit(tt);
      const TrainingData data{xs.Apply(xt), ts.Apply(tt), ts};
      const RestartResult r =
          TrainBrRestarts(data, sizes, options.seed, options.restarts, options.train);
      const Eigen::MatrixXd y = ts.Reverse(r.best.network.Forward(xs.Apply(xv)));
      sq += (tv - y).array().square().rowwise().sum().matrix();
      if (progress) progress(++done, total);
    }
    row.cv_rms = (sq / Q).cwiseSqrt();
    row.cv_rms_normalized = std::sqrt((sq.array() / half.array().square()).sum() /
                                      (static_cast<double>(Q) * Features::kCount));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace whirl::nn
