#include "family/linear.h"

#include <Eigen/QR>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/json_file.h"

namespace whirl::family {
namespace {

Eigen::MatrixXd Design(const LinearModel& m, const Eigen::MatrixXd& x) {
  Eigen::MatrixXd a(x.cols(), x.rows() + 1);
  a.col(0).setOnes();
  a.rightCols(x.rows()) =
      (m.input_scale.cwiseInverse().asDiagonal() * (x.colwise() - m.input_shift)).transpose();
  return a;
}

// An array of finite numbers: the value `v`, named `where` in messages.
Eigen::VectorXd ToVector(const nlohmann::json& v, const std::string& where) {
  const std::vector<double> x = RequireNumbers(v, where);
  return Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
}

Eigen::VectorXd ToVector(const nlohmann::json& j, const char* key) {
  return ToVector(RequireKey(j, key, "linear model"), std::string("linear model: '") + key + "'");
}

// Rules of a linear fit's numbers in a file: wide enough for any fit of whirl's tables
// (transformed units), narrow enough that no prediction overflows.
constexpr Range kShiftRange{-1e7, 1e7, false, "", "a mean of transformed inputs"};
constexpr Range kScaleRange{0, 1e7, true, "", "an sd of transformed inputs"};
constexpr Range kCoefRange{-1e9, 1e9, false, "", "units of the transformed output"};
constexpr Range kAtaInvRange{-1e9, 1e9, false, "", "(A'A)^-1 of standardized inputs"};
constexpr Range kVarianceRange{0, 1e14, false, "", "units of the transformed output squared"};

void CheckEach(const Eigen::VectorXd& v, const Range& range, const std::string& key) {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    CheckRange(v(i), range, key + "[" + std::to_string(i) + "]", "linear model");
}

std::vector<double> ToStd(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

}  // namespace

LinearModel FitLinear(const Eigen::MatrixXd& x, const Eigen::VectorXd& y) {
  const Eigen::Index d = x.rows(), n = x.cols();
  if (y.size() != n || !x.allFinite() || !y.allFinite())
    throw InputError("linear model: " + std::to_string(n) + " input columns and " +
                     std::to_string(y.size()) + " targets; need equal sizes and finite values");
  if (n <= d + 2)
    throw InputError("linear model: " + std::to_string(n) + " rows for " + std::to_string(d + 1) +
                     " coefficients; needs at least " + std::to_string(d + 3));
  LinearModel m;
  m.input_shift = x.rowwise().mean();
  m.input_scale =
      ((x.colwise() - m.input_shift).rowwise().squaredNorm() / static_cast<double>(n)).cwiseSqrt();
  for (Eigen::Index i = 0; i < d; ++i)
    if (!(m.input_scale(i) > 0)) m.input_scale(i) = 1.0;
  const Eigen::MatrixXd a = Design(m, x);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  m.coef = qr.solve(y);
  m.ata_inv = (a.transpose() * a).ldlt().solve(Eigen::MatrixXd::Identity(d + 1, d + 1));
  m.fitted_noise_variance = (y - a * m.coef).squaredNorm() / static_cast<double>(n - d - 1);
  m.noise_variance = m.fitted_noise_variance;
  return m;
}

LinearPrediction PredictLinear(const LinearModel& m, const Eigen::MatrixXd& x) {
  if (x.rows() != m.input_shift.size())
    throw InputError("linear model: predictions need " + std::to_string(m.input_shift.size()) +
                     " inputs, got " + std::to_string(x.rows()));
  const Eigen::MatrixXd a = Design(m, x);
  LinearPrediction p;
  p.mean = a * m.coef;
  p.latent_variance = m.fitted_noise_variance * (a * m.ata_inv).cwiseProduct(a).rowwise().sum();
  return p;
}

Eigen::MatrixXd LatentCovariance(const LinearModel& m, const Eigen::MatrixXd& x) {
  if (x.rows() != m.input_shift.size())
    throw InputError("linear model: covariances need " + std::to_string(m.input_shift.size()) +
                     " inputs, got " + std::to_string(x.rows()));
  const Eigen::MatrixXd a = Design(m, x);
  return m.fitted_noise_variance * a * m.ata_inv * a.transpose();
}

LinearLeaveOneOut LeaveOneOutLinear(const LinearModel& m, const Eigen::MatrixXd& x,
                                    const Eigen::VectorXd& y) {
  const Eigen::MatrixXd a = Design(m, x);
  const Eigen::ArrayXd h = (a * m.ata_inv).cwiseProduct(a).rowwise().sum().array();
  const Eigen::ArrayXd e = (y - a * m.coef).array();
  const Eigen::ArrayXd one_minus = (1.0 - h).max(1e-12);
  return {(e / one_minus).matrix(), (m.fitted_noise_variance * h / one_minus).matrix()};
}

void to_json(nlohmann::json& j, const LinearModel& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index r = 0; r < m.ata_inv.rows(); ++r) rows.push_back(ToStd(m.ata_inv.row(r)));
  j = {{"input_shift", ToStd(m.input_shift)},
       {"input_scale", ToStd(m.input_scale)},
       {"coef", ToStd(m.coef)},
       {"ata_inv", rows},
       {"fitted_noise_variance", m.fitted_noise_variance},
       {"noise_variance", m.noise_variance}};
}

void from_json(const nlohmann::json& j, LinearModel& m) {
  if (!j.is_object()) throw InputError("linear model: must be a JSON object");
  m.input_shift = ToVector(j, "input_shift");
  m.input_scale = ToVector(j, "input_scale");
  m.coef = ToVector(j, "coef");
  const Eigen::Index p = m.coef.size();
  if (m.input_scale.size() != m.input_shift.size() || p != m.input_shift.size() + 1 || p < 2)
    throw InputError(
        "linear model: 'input_scale' (one per input) and 'coef' (inputs + 1) must match "
        "'input_shift' (at least one input)");
  CheckEach(m.input_shift, kShiftRange, "input_shift");
  CheckEach(m.input_scale, kScaleRange, "input_scale");
  CheckEach(m.coef, kCoefRange, "coef");
  if (!j.contains("ata_inv") || !j.at("ata_inv").is_array() ||
      j.at("ata_inv").size() != static_cast<std::size_t>(p))
    throw InputError("linear model: 'ata_inv' must hold " + std::to_string(p) + " rows");
  m.ata_inv.resize(p, p);
  for (Eigen::Index r = 0; r < p; ++r) {
    const Eigen::VectorXd row =
        ToVector(j.at("ata_inv")[r], "linear model: 'ata_inv[" + std::to_string(r) + "]'");
    if (row.size() != p)
      throw InputError("linear model: 'ata_inv' rows must hold " + std::to_string(p) + " values");
    CheckEach(row, kAtaInvRange, "ata_inv[" + std::to_string(r) + "]");
    m.ata_inv.row(r) = row.transpose();
  }
  m.fitted_noise_variance =
      RequireNumberIn(j, "fitted_noise_variance", kVarianceRange, "linear model");
  m.noise_variance = RequireNumberIn(j, "noise_variance", kVarianceRange, "linear model");
}

}  // namespace whirl::family
