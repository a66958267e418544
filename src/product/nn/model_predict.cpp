// Prediction with a model (nn/model.h): means and predictive standard deviations, and the
// training-domain check.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"
#include "nn/model.h"

// Prediction with the model (nn/model.h): means and predictive standard deviations, and the
// training-domain check.
namespace whirl::nn {

Eigen::MatrixXd InputMatrix(const std::vector<ProcessInputs>& inputs) {
  Eigen::MatrixXd x(ProcessInputs::kCount, inputs.size());
  for (std::size_t q = 0; q < inputs.size(); ++q) {
    const auto a = inputs[q].ToArray();
    for (int i = 0; i < ProcessInputs::kCount; ++i) x(i, q) = a[i];
  }
  return x;
}

Eigen::MatrixXd TargetMatrix(const std::vector<Features>& targets) {
  Eigen::MatrixXd t(Features::kCount, targets.size());
  for (std::size_t q = 0; q < targets.size(); ++q) {
    const auto a = targets[q].ToArray();
    for (int k = 0; k < Features::kCount; ++k) t(k, q) = a[k];
  }
  return t;
}

std::vector<Prediction> PredictBatch(const Model& model, const std::vector<ProcessInputs>& inputs) {
  std::vector<Prediction> out(inputs.size());
  if (inputs.empty()) return out;
  const Eigen::MatrixXd x_raw = InputMatrix(inputs);
  if (!x_raw.allFinite()) throw InputError("predict: an input is NaN or infinite");
  const Eigen::MatrixXd x = model.input_scaling.Apply(x_raw);
  ForwardCache cache;
  model.network.Forward(x, &cache);
  const Eigen::MatrixXd y = model.target_scaling.Reverse(cache.output());
  Eigen::MatrixXd J;
  ErrorJacobian(model.network, cache, &J);  // rows q * S + k, = -dy/dw
  const Eigen::VectorXd half = model.target_scaling.HalfRange();
  const int S = model.network.OutputCount();
  Eigen::VectorXd Sg;
  for (std::size_t q = 0; q < inputs.size(); ++q) {
    std::array<double, Features::kCount> mean{}, sd{}, noise{};
    for (int k = 0; k < S; ++k) {
      const auto g = J.row(static_cast<Eigen::Index>(q) * S + k).transpose();
      Sg.noalias() = model.posterior_covariance * g;
      const double var = model.output_noise_variance(k) + g.dot(Sg);
      mean[k] = y(k, q);
      sd[k] = std::sqrt(std::max(var, 0.0)) * half(k);
      noise[k] = std::sqrt(model.output_noise_variance(k)) * half(k);
    }
    Prediction& p = out[q];
    p.mean = Features::FromArray(mean);
    p.stddev = Features::FromArray(sd);
    p.noise_stddev = Features::FromArray(noise);
    for (int i = 0; i < ProcessInputs::kCount; ++i) {
      if (x_raw(i, q) < model.domain_min(i) || x_raw(i, q) > model.domain_max(i)) {
        p.outside_domain = true;
        p.outside_domain_fields.push_back(model.inputs[i].name);
      }
    }
  }
  return out;
}

OutsideDomainSummary SummarizeOutsideDomain(const Model& model,
                                            const std::vector<Prediction>& predictions) {
  OutsideDomainSummary s;
  for (const auto& v : model.inputs) s.input_names.push_back(v.name);
  s.per_input.assign(s.input_names.size(), 0);
  for (std::size_t q = 0; q < predictions.size(); ++q) {
    if (!predictions[q].outside_domain) continue;
    if (s.rows++ == 0) s.first_row = q;
    for (const auto& f : predictions[q].outside_domain_fields)
      for (std::size_t i = 0; i < s.input_names.size(); ++i)
        if (s.input_names[i] == f) ++s.per_input[i];
  }
  return s;
}

std::string OutsideDomainSummary::Describe(int total_rows, const std::string& first) const {
  std::string inputs;
  for (std::size_t i = 0; i < per_input.size(); ++i)
    if (per_input[i] > 0)
      inputs += (inputs.empty() ? "" : ", ") + input_names[i] + " in " +
                std::to_string(per_input[i]) + (per_input[i] == 1 ? " row" : " rows");
  if (total_rows == 1) return first + " lies outside the training domain in " + inputs;
  return std::to_string(rows) + " of " + std::to_string(total_rows) +
         " rows lie outside the training domain (" + inputs + "; first: " + first + ")";
}

Prediction Predict(const Model& model, const ProcessInputs& inputs) {
  return PredictBatch(model, {inputs}).front();
}

}  // namespace whirl::nn
