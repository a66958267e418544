#include "nn/selection.h"

#include <cmath>
#include <string>

#include "core/error.h"
#include "core/parallel.h"
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
  const int sizes_count = options.hidden_max - options.hidden_min + 1;
  const int per_size = options.folds + 1;  // slot 0: the fit on all rows; 1..folds: the folds
  const int total = sizes_count * per_size;
  std::vector<TrainSummary> full(static_cast<std::size_t>(sizes_count));
  std::vector<Eigen::VectorXd> fold_sq(static_cast<std::size_t>(total));
  // Every fit (sizes x (folds + 1)) is one task of the one parallel-for; each writes only its own
  // slot and the sums below run in a fixed order, so any thread count gives the same rows.
  ParallelFor(
      static_cast<std::size_t>(total), options.threads,
      [&](std::size_t task) {
        const int h = options.hidden_min + static_cast<int>(task) / per_size;
        const int f = static_cast<int>(task) % per_size - 1;
        const std::vector<int> sizes = {ProcessInputs::kCount, h, Features::kCount};
        if (f < 0) {
          const MapMinMax xs = MapMinMax::Fit(x_raw);
          const TrainingData data{xs.Apply(x_raw), full_targets.Apply(t_raw), full_targets};
          full[task / per_size] =
              TrainBrRestarts(data, sizes, options.seed, options.restarts, options.train, {}, 1)
                  .best.summary;
          return;
        }
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
            TrainBrRestarts(data, sizes, options.seed, options.restarts, options.train, {}, 1);
        const Eigen::MatrixXd y = ts.Reverse(r.best.network.Forward(xs.Apply(xv)));
        fold_sq[task] = (tv - y).array().square().rowwise().sum().matrix();
      },
      [&](std::size_t done, std::size_t n) {
        if (progress) progress(static_cast<int>(done), static_cast<int>(n));
      });
  std::vector<SweepRow> rows;
  for (int i = 0; i < sizes_count; ++i) {
    const TrainSummary& s = full[static_cast<std::size_t>(i)];
    SweepRow row;
    row.hidden = options.hidden_min + i;
    row.parameter_count = s.parameter_count;
    row.train_sse_normalized = s.sse;
    row.train_rms = s.rms_error;
    row.gamma = s.gamma;
    row.log_evidence = s.log_evidence;
    Eigen::VectorXd sq = Eigen::VectorXd::Zero(Features::kCount);
    for (int f = 0; f < options.folds; ++f)
      sq += fold_sq[static_cast<std::size_t>(i * per_size + f + 1)];
    row.cv_rms = (sq / Q).cwiseSqrt();
    row.cv_rms_normalized = std::sqrt((sq.array() / half.array().square()).sum() /
                                      (static_cast<double>(Q) * Features::kCount));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace whirl::nn
