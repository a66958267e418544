// Designs for the workpiece model's training table (design.h).
#include "design/design.h"

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include "core/error.h"
#include "core/limits.h"
#include "core/numbers.h"
#include "family/family.h"
#include "family/linear.h"
#include "family/transform.h"
#include "gp/gp.h"
#include "nn/network.h"

namespace whirl::design {
namespace {

// ---- First design: the power law on log inputs -----------------------------------------------

// Rows f(x_c) = (1, standardized ln x_j of the varying inputs), candidates x coefficients.
Eigen::MatrixXd PowerLawRows(const std::vector<ProcessInputs>& cands,
                             std::vector<std::string>* names) {
  const int n = static_cast<int>(cands.size());
  Eigen::MatrixXd logs(n, ProcessInputs::kCount);
  for (int c = 0; c < n; ++c) {
    const auto a = cands[c].ToArray();
    for (int j = 0; j < ProcessInputs::kCount; ++j) logs(c, j) = std::log(a[j]);
  }
  std::vector<int> used;
  for (int j = 0; j < ProcessInputs::kCount; ++j) {
    const double spread = logs.col(j).maxCoeff() - logs.col(j).minCoeff();
    if (spread > 1e-12) used.push_back(j);
  }
  Eigen::MatrixXd f(n, 1 + static_cast<int>(used.size()));
  f.col(0).setOnes();
  for (std::size_t u = 0; u < used.size(); ++u) {
    const Eigen::VectorXd v = logs.col(used[u]);
    const double mean = v.mean();
    const double sd = std::sqrt((v.array() - mean).square().mean());
    f.col(1 + static_cast<int>(u)) = (v.array() - mean) / sd;
    names->push_back(kInputColumns[used[u]]);
  }
  return f;
}

// The Bayesian D design's potential columns (design.h, "Bayesian D") over the candidates:
// squares (and pairwise products) of f's standardized log inputs, each the residual of its
// least-squares regression on f's columns, scaled to a range of 2; columns without range left out.
Eigen::MatrixXd PotentialColumns(const Eigen::MatrixXd& f, BayesPrior::Terms terms) {
  const Eigen::MatrixXd u = f.rightCols(f.cols() - 1);
  std::vector<Eigen::VectorXd> raw;
  for (Eigen::Index i = 0; i < u.cols(); ++i) raw.push_back(u.col(i).array().square());
  if (terms == BayesPrior::Terms::kSquaresInteractions)
    for (Eigen::Index i = 0; i < u.cols(); ++i)
      for (Eigen::Index j = i + 1; j < u.cols(); ++j)
        raw.push_back(u.col(i).cwiseProduct(u.col(j)));
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(f);
  std::vector<Eigen::VectorXd> kept;
  for (const auto& z : raw) {
    const Eigen::VectorXd r = z - f * qr.solve(z);
    const double range = r.maxCoeff() - r.minCoeff();
    if (range > 1e-9 * std::max(1.0, z.cwiseAbs().maxCoeff())) kept.push_back(2.0 * r / range);
  }
  Eigen::MatrixXd out(f.rows(), static_cast<Eigen::Index>(kept.size()));
  for (std::size_t k = 0; k < kept.size(); ++k) out.col(static_cast<Eigen::Index>(k)) = kept[k];
  return out;
}

// The criterion (larger is better) of the rows `picked` of f, the diagonal `prior` added to
// F'F (zeros but for Criterion::kBayesD, which is then D's); -inf when that is singular.
double CriterionValue(const Eigen::MatrixXd& f, const std::vector<int>& picked, Criterion c,
                      const Eigen::MatrixXd& w, const Eigen::VectorXd& prior) {
  Eigen::MatrixXd m = prior.asDiagonal();
  for (int i : picked) m.noalias() += f.row(i).transpose() * f.row(i);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(m);
  const Eigen::VectorXd d = ldlt.vectorD();
  if (ldlt.info() != Eigen::Success || d.minCoeff() <= 1e-10 * std::max(1.0, d.maxCoeff()))
    return -std::numeric_limits<double>::infinity();
  if (c != Criterion::kI) return d.array().log().sum();
  return -(ldlt.solve(w)).trace();  // mean_c f_c' M^-1 f_c = tr(M^-1 W)
}

// Greedy start: each pick the candidate of largest f' (M + prior + eps I)^-1 f (the D rule of
// Wynn).
std::vector<int> GreedyStart(const Eigen::MatrixXd& f, int count, const Eigen::VectorXd& prior) {
  const int p = static_cast<int>(f.cols());
  Eigen::MatrixXd m = 1e-6 * Eigen::MatrixXd::Identity(p, p);
  m.diagonal() += prior;
  std::vector<int> picked;
  std::vector<char> taken(f.rows(), 0);
  for (int k = 0; k < count; ++k) {
    const Eigen::MatrixXd mi = m.inverse();
    int best = -1;
    double best_v = -1;
    for (int c = 0; c < f.rows(); ++c) {
      if (taken[c]) continue;
      const double v = f.row(c) * mi * f.row(c).transpose();
      if (v > best_v * (1 + 1e-12)) best_v = v, best = c;
    }
    taken[best] = 1;
    picked.push_back(best);
    m.noalias() += f.row(best).transpose() * f.row(best);
  }
  return picked;
}

// Fedorov exchanges until no swap improves the criterion (at most 50 passes).
void Exchange(const Eigen::MatrixXd& f, Criterion c, const Eigen::MatrixXd& w,
              const Eigen::VectorXd& prior, std::vector<int>* picked) {
  std::vector<char> taken(f.rows(), 0);
  for (int i : *picked) taken[i] = 1;
  double value = CriterionValue(f, *picked, c, w, prior);
  for (int pass = 0; pass < 50; ++pass) {
    bool improved = false;
    for (auto& slot : *picked) {
      for (int cand = 0; cand < f.rows(); ++cand) {
        if (taken[cand]) continue;
        const int old = slot;
        slot = cand;
        const double v = CriterionValue(f, *picked, c, w, prior);
        if (v > value + 1e-9 * std::max(1.0, std::abs(value))) {
          taken[old] = 0, taken[cand] = 1, value = v, improved = true;
        } else {
          slot = old;
        }
      }
    }
    if (!improved) break;
  }
}

// The explaining order: each next screw has the highest variance factor given those before it.
std::vector<Pick> ExplainingOrder(const Eigen::MatrixXd& f, const std::vector<int>& design) {
  const int p = static_cast<int>(f.cols());
  Eigen::MatrixXd m = 1e-9 * Eigen::MatrixXd::Identity(p, p);
  std::vector<int> left = design;
  std::vector<Pick> out;
  while (!left.empty()) {
    const Eigen::MatrixXd mi = m.inverse();
    std::size_t best = 0;
    double best_v = -1;
    for (std::size_t i = 0; i < left.size(); ++i) {
      const double v = f.row(left[i]) * mi * f.row(left[i]).transpose();
      if (v > best_v * (1 + 1e-12)) best_v = v, best = i;
    }
    const int c = left[best];
    left.erase(left.begin() + static_cast<long>(best));
    Pick pick;
    pick.candidate = c;
    const bool first = static_cast<int>(out.size()) < p;
    m.noalias() += f.row(c).transpose() * f.row(c);
    const double after = f.row(c) * m.inverse() * f.row(c).transpose();
    pick.sd_now = {first ? std::numeric_limits<double>::infinity() : std::sqrt(best_v), 0};
    pick.sd_after = {std::sqrt(after), 0};
    pick.why = first ? "one of the " + std::to_string(p) +
                           " screws that determine the power law's coefficients (spread in the "
                           "log inputs)"
                     : "the power law's prediction is least known here given the screws before "
                       "it: sd factor " + FormatSignificant(std::sqrt(best_v), 3) + " -> " +
                           FormatSignificant(std::sqrt(after), 3);
    out.push_back(pick);
  }
  return out;
}

// ---- Space filling: maximin picks --------------------------------------------------------------

// The smallest distance from point c of `u` to the points `from` of `u` (rows), +inf if none.
double NearestDistance(const Eigen::MatrixXd& u, int c, const std::vector<int>& from) {
  double d = std::numeric_limits<double>::infinity();
  for (int i : from) d = std::min(d, (u.row(c) - u.row(i)).norm());
  return d;
}

// The unpicked row of u (among the first `n` rows: the candidates) farthest from the rows
// `near` (picked candidates and measured screws); ties to the lower index. -1 when all taken.
int FarthestCandidate(const Eigen::MatrixXd& u, int n, const std::vector<char>& taken,
                      const std::vector<int>& near, double* distance) {
  int best = -1;
  *distance = -1;
  for (int c = 0; c < n; ++c) {
    if (taken[c]) continue;
    const double d = NearestDistance(u, c, near);
    if (d > *distance * (1 + 1e-12)) *distance = d, best = c;
  }
  return best;
}

// The unpicked row of u (among the first `n` rows: the candidates) whose pick most lowers the
// mean over the list (at most kCoverageRows rows, every k-th) of each row's distance to its
// nearest row of `near`; *before / *after: that mean now and after the pick (design.h,
// FillRule::kCoverage). Ties to the lower index; -1 when all taken.
int CoverageCandidate(const Eigen::MatrixXd& u, int n, const std::vector<char>& taken,
                      const std::vector<int>& near, double* before, double* after) {
  const int step = (n + kCoverageRows - 1) / kCoverageRows;
  std::vector<int> rows;
  for (int i = 0; i < n; i += step) rows.push_back(i);
  const auto m = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd z(m, u.cols());
  Eigen::VectorXd nearest(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    z.row(r) = u.row(rows[static_cast<std::size_t>(r)]);
    nearest(r) = NearestDistance(u, rows[static_cast<std::size_t>(r)], near);
  }
  int best = -1;
  double best_sum = std::numeric_limits<double>::infinity();
  for (int c = 0; c < n; ++c) {
    if (taken[c]) continue;
    const Eigen::VectorXd to_c = (z.rowwise() - u.row(c)).rowwise().norm();
    const double sum = to_c.cwiseMin(nearest).sum();
    if (sum < best_sum * (1 - 1e-12)) best_sum = sum, best = c;
  }
  *before = nearest.mean();
  *after = best_sum / static_cast<double>(m);
  return best;
}

std::string WhyCoverage(double before, double after) {
  return "coverage: the candidate that most lowers the mean distance from the list's screws to "
         "their nearest measured one (" + FormatSignificant(before, 3) + " -> " +
         FormatSignificant(after, 3) + " in standardized log inputs), so that where the model is "
         "wrong in a way its variance does not know, a screw was measured nearby";
}

std::string WhySpaceFilling(double distance) {
  return "space filling: the candidate farthest from the screws before it (distance " +
         FormatSignificant(distance, 3) + " in standardized log inputs), so that the model's "
         "cross-validation sees the inside of the range and a bend";
}

// One space-filling pick by `rule` among the first n rows of u, away from `near`, and its why.
int FillCandidate(FillRule rule, const Eigen::MatrixXd& u, int n, const std::vector<char>& taken,
                  const std::vector<int>& near, std::string* why) {
  if (rule == FillRule::kCoverage) {
    double before = 0, after = 0;
    const int c = CoverageCandidate(u, n, taken, near, &before, &after);
    *why = WhyCoverage(before, after);
    return c;
  }
  double distance = 0;
  const int c = FarthestCandidate(u, n, taken, near, &distance);
  *why = WhySpaceFilling(distance);
  return c;
}

// ---- Next screws: integrated variance reduction --------------------------------------------

// One candidate model's output over the candidates: latent covariance in the transformed space,
// the delta method's factor, the calibrated prediction noise and the fitted noise of a new row.
struct MemberState {
  Eigen::MatrixXd cov;
  Eigen::VectorXd g;
  double prediction_noise = 0, measurement_noise = 0;
  double Variance(int c) const { return g(c) * g(c) * (std::max(cov(c, c), 0.0) + prediction_noise); }
  double Denominator(int j) const { return std::max(cov(j, j), 0.0) + measurement_noise; }
  double VarianceAfter(int c, int j) const {  // at c once j is measured
    const double denom = Denominator(j);
    const double drop = denom > 0 ? cov(c, j) * cov(c, j) / denom : 0.0;
    return g(c) * g(c) * (std::max(cov(c, c) - drop, 0.0) + prediction_noise);
  }
  double Reduction(int j) const {  // sum_c g_c^2 C[c,j]^2 / (C[j,j] + s^2)
    const double denom = Denominator(j);
    if (denom <= 0) return 0;
    return (g.array().square() * cov.col(j).array().square()).sum() / denom;
  }
  void Measure(int j) {
    const double denom = Denominator(j);
    if (denom <= 0) return;
    const Eigen::VectorXd col = cov.col(j);
    cov.noalias() -= col * col.transpose() / denom;
  }
};

// One output's state over the candidates as the model predicts it (family::PredictChoice): the
// sd is scale * sum_m share_m sd_m over the members (one member with share 1 where a candidate
// takes the output whole; scale = Choice::sd_scale). The criterion's weight: 1 / mean predictive
// variance now (original units).
struct OutputState {
  std::vector<MemberState> members;
  std::vector<double> shares;
  double scale = 1;
  double weight = 1;
  double Sd(int c, int measured = -1) const {
    double s = 0;
    for (std::size_t m = 0; m < members.size(); ++m)
      s += shares[m] * std::sqrt(measured < 0 ? members[m].Variance(c)
                                              : members[m].VarianceAfter(c, measured));
    return scale * s;
  }
  double Variance(int c) const {
    const double sd = Sd(c);
    return sd * sd;
  }
  int Size() const { return static_cast<int>(members.front().g.size()); }
  double Rms() const {
    double s = 0;
    for (int c = 0; c < Size(); ++c) s += Variance(c);
    return std::sqrt(s / Size());
  }
  double FloorRms() const {  // the sd with every latent variance at 0
    double s = 0;
    for (int c = 0; c < Size(); ++c) {
      double sd = 0;
      for (std::size_t m = 0; m < members.size(); ++m)
        sd += shares[m] * std::abs(members[m].g(c)) * std::sqrt(members[m].prediction_noise);
      s += scale * scale * sd * sd;
    }
    return std::sqrt(s / Size());
  }
  // sum_c (variance now - variance once j is measured); one member: its closed form times
  // scale^2 (the latent covariance and the noise of a Gaussian model scaled alike).
  double Reduction(int j) const {
    if (members.size() == 1) return scale * scale * members.front().Reduction(j);
    double s = 0;
    for (int c = 0; c < Size(); ++c) {
      const double after = Sd(c, j);
      s += Variance(c) - after * after;
    }
    return s;
  }
  void Measure(int j) {
    for (auto& m : members) m.Measure(j);
  }
};

OutputState Single(MemberState m) {
  OutputState s;
  s.members.push_back(std::move(m));
  s.shares = {1.0};
  return s;
}

void CheckUsedInputs(const family::FamilyModel& m, const workpiece::WorkpieceModel& model,
                     const std::vector<ProcessInputs>& cands, const std::vector<int>& lines) {
  for (int j = 0; j < ProcessInputs::kCount; ++j) {
    if (m.transform.input_used[j]) continue;
    const double trained = model.domain_min(j);
    for (std::size_t c = 0; c < cands.size(); ++c) {
      const double v = cands[c].ToArray()[j];
      if (std::abs(v - trained) > 1e-9 * std::max(1.0, std::abs(trained)))
        throw InputError(
            std::string("the model leaves out ") + kInputColumns[j] + " (constant " +
            FormatSignificant(trained, 6) + " in its training table '" + model.training_data +
            "'), but " +
            (lines.size() == cands.size() ? "line " + std::to_string(lines[c])
                                          : "candidate " + std::to_string(c + 1)) +
            " has " + kInputColumns[j] + " = " +
            FormatSignificant(v, 6) + ": the model cannot say what that input changes; train it "
            "on a table that varies " + kInputColumns[j] + " or keep the candidates at " +
            FormatSignificant(trained, 6));
    }
  }
}

// A network's output k over the rows z (all five transformed inputs, one column per candidate):
// its mean and the Laplace covariance g_k(x_c)' A^-1 g_k(x_j) of nn/model.h, both in the
// transformed output's units (the mapminmax half range); prediction noise the calibrated
// sigma_k^2, the noise of a new row trainbr's 1 / (2 beta), the level its posterior assumes.
MemberState NetworkState(const nn::Model& net, int k, const Eigen::MatrixXd& z,
                         Eigen::VectorXd* mean_z) {
  if (net.posterior_covariance.size() == 0)
    throw InputError("design: the network of output " + std::string(kTargetColumns[k]) +
                     " has no posterior covariance (trained without regularization)");
  nn::ForwardCache cache;
  net.network.Forward(net.input_scaling.Apply(z), &cache);
  *mean_z = net.target_scaling.Reverse(cache.output()).row(k).transpose();
  Eigen::MatrixXd jac;
  nn::ErrorJacobian(net.network, cache, &jac);  // rows q * S + k, = -dy/dw
  const int outputs = net.network.OutputCount();
  Eigen::MatrixXd gk(z.cols(), jac.cols());
  for (Eigen::Index q = 0; q < z.cols(); ++q) gk.row(q) = jac.row(q * outputs + k);
  const double half = net.target_scaling.HalfRange()(k), half2 = half * half;
  MemberState s;
  s.cov = half2 * (gk * net.posterior_covariance * gk.transpose());
  s.prediction_noise = half2 * net.output_noise_variance(k);
  s.measurement_noise = half2 * net.noise_variance;
  return s;
}

// Member m's output k over the candidates x (original units, one column per candidate).
MemberState StateOf(const family::FamilyModel& m, int k, const Eigen::MatrixXd& x) {
  const Eigen::MatrixXd z = family::TransformInputs(m.transform, x);
  const Eigen::MatrixXd used = family::UsedInputRows(m.transform, z);
  MemberState s;
  Eigen::VectorXd mean_z;
  if (m.candidate.family == family::Family::kNetwork) {
    s = NetworkState(m.network, k, z, &mean_z);
  } else if (m.candidate.family == family::Family::kLinear) {
    const auto& lin = m.linears[k];
    mean_z = family::PredictLinear(lin, used).mean;
    s.cov = family::LatentCovariance(lin, used);
    s.prediction_noise = lin.noise_variance;
    s.measurement_noise = lin.fitted_noise_variance;
  } else {
    const auto& gp = m.gps[k];
    mean_z = gp::PredictGp(gp, used).mean;
    s.cov = gp::PosteriorCovariance(gp, used);
    s.prediction_noise = gp.noise_variance * gp.target_scale * gp.target_scale;
    s.measurement_noise = gp.SigmaN2() * gp.target_scale * gp.target_scale;
  }
  const auto t = m.transform.outputs[k];
  s.g.resize(mean_z.size());
  for (Eigen::Index c = 0; c < mean_z.size(); ++c)
    s.g(c) = family::InverseDerivative(t, mean_z(c));
  return s;
}

// The choice of a family model (a network model: InputError).
const family::Choice& ChoiceOf(const workpiece::WorkpieceModel& model) {
  if (model.IsNetwork())
    throw InputError("the model (trained on '" + model.training_data +
                     "') is a network (" + model.Describe() + "); the next screws need a family "
                     "model: train one with 'whirl train' without --family network or "
                     "--trainbr-matlab");
  return model.choice;
}

// Whether the choice predicts output k by the power law alone (linear/log on a log output).
bool PowerLawAlone(const family::Choice& choice, int k) {
  int parts = 0;
  for (double w : choice.weights[k]) parts += w > 0;
  const auto& m = choice.models[choice.model_of_output[k]];
  return parts <= 1 && m.candidate.family == family::Family::kLinear && m.candidate.log &&
         m.OutputName(k) == m.candidate.Name();
}

// The candidate that predicts output k, or of a stacked output the one of largest weight.
const family::FamilyModel& ModelOfOutput(const workpiece::WorkpieceModel& model, int k) {
  const auto& choice = ChoiceOf(model);
  return choice.models[choice.model_of_output[k]];
}

std::array<OutputState, Features::kCount> States(const workpiece::WorkpieceModel& model,
                                                 const std::vector<ProcessInputs>& cands,
                                                 const std::vector<int>& lines) {
  const auto& choice = ChoiceOf(model);
  std::array<OutputState, Features::kCount> states;
  Eigen::MatrixXd x(ProcessInputs::kCount, static_cast<Eigen::Index>(cands.size()));
  for (std::size_t c = 0; c < cands.size(); ++c) {
    const auto a = cands[c].ToArray();
    for (int j = 0; j < ProcessInputs::kCount; ++j) x(j, static_cast<Eigen::Index>(c)) = a[j];
  }
  for (int k = 0; k < Features::kCount; ++k) {
    std::vector<std::pair<int, double>> parts;  // (model, weight)
    if (choice.weights[k].empty()) parts.push_back({choice.model_of_output[k], 1.0});
    for (std::size_t j = 0; j < choice.weights[k].size(); ++j)
      if (choice.weights[k][j] > 0) parts.push_back({static_cast<int>(j), choice.weights[k][j]});
    for (const auto& [j, w] : parts) {
      const auto& m = choice.models[static_cast<std::size_t>(j)];
      CheckUsedInputs(m, model, cands, lines);
      states[k].members.push_back(StateOf(m, k, x));
      states[k].shares.push_back(w);
    }
    states[k].scale = choice.sd_scale[k];
  }
  return states;
}

// The power-GP of NextRule on the screws z (d x m, standardized log inputs) with targets y (m):
// power-law mean, flat prior on its coefficients, Matern 5/2 departure of sd `ratio` (scatter sd
// 1) and length rule.length_scale. InputError (collinear screws) from Factorize.
gp::Gp PowerGp(const Eigen::MatrixXd& z, const Eigen::VectorXd& y, double ratio,
               const NextRule& rule) {
  const int d = static_cast<int>(z.rows());
  gp::Gp g;
  g.kernel = gp::Kernel::kMatern52;
  g.mean = gp::Mean::kLinear;
  g.input_shift = Eigen::VectorXd::Zero(d);
  g.input_scale = Eigen::VectorXd::Ones(d);
  g.theta = Eigen::VectorXd::Zero(d + 2);
  g.theta.head(d).setConstant(std::log(rule.length_scale));
  g.theta(d) = std::log(ratio);
  g.z = z;
  g.u = y;
  g.Factorize();
  return g;
}

int CheckMeasuredCount(int m, int d) {
  if (m < d + 1)
    throw InputError("the power-GP rule needs at least " + std::to_string(d + 1) +
                     " measured screws (--measured: the power law's coefficients), got " +
                     std::to_string(m));
  return m;
}

// P_ii at or below which a screw's leave-one-out is undetermined (PowerLawLackOfFit; the scatter's
// variance is 1, so the power law alone has P_ii = 1 - leverage).
constexpr double kUndetermined = 1e-9;

// The departure's sd of "the power law alone" in PowerLawLackOfFit: K = I up to 1e-12.
constexpr double kPowerLawOnlyRatio = 1e-6;

const char* kCollinear =
    "the measured screws (--measured) do not determine a power law (their log inputs are "
    "collinear); the power-GP rule needs them spread in every input";

// The power-GP rule's state (design.h, NextRule): the posterior covariance over the candidates
// (rows 0..n-1 of u, standardized log inputs) of a GP with a power-law mean (flat prior on its
// coefficients), an isotropic Matern 5/2 departure of sd rule.departure_ratio and length
// rule.length_scale, conditioned on the measured screws (rows n.. of u) with scatter sd 1.
// Targets do not enter a GP's covariance, so none are needed.
OutputState PowerGpState(const Eigen::MatrixXd& u, int n, const NextRule& rule) {
  const int d = static_cast<int>(u.cols());
  const int m = CheckMeasuredCount(static_cast<int>(u.rows()) - n, d);
  gp::Gp g;
  try {
    g = PowerGp(u.bottomRows(m).transpose(), Eigen::VectorXd::Zero(m), rule.departure_ratio, rule);
  } catch (const InputError&) {
    throw InputError(kCollinear);
  }
  MemberState s;
  s.cov = gp::PosteriorCovariance(g, u.topRows(n).transpose());
  s.g = Eigen::VectorXd::Ones(n);
  s.measurement_noise = g.SigmaN2();
  return Single(std::move(s));
}

template <class States>
int BestCandidate(const States& states, const std::vector<char>& taken, double* score) {
  int best = -1;
  *score = -1;
  for (std::size_t j = 0; j < taken.size(); ++j) {
    if (taken[j]) continue;
    double s = 0;
    for (const auto& st : states) s += st.weight * st.Reduction(static_cast<int>(j));
    if (s > *score * (1 + 1e-12)) *score = s, best = static_cast<int>(j);
  }
  return best;
}

// Why the pick j of the variance rule was made; `share` = its reduction as a fraction of the
// criterion's mean variance over the list (design.h: each variance weighed by its mean).
// own[k]: output k's variance is the chosen family's (NextRule); lack_of_fit: kSwitch's ratios.
std::string WhyNext(const std::array<OutputState, Features::kCount>& states, int j, double share,
                    const NextRule& rule, const std::array<bool, Features::kCount>& own,
                    const NextDesign& d, const workpiece::Prediction& now) {
  const std::array<double, Features::kCount>& lack_of_fit = d.lack_of_fit_ratio;
  const NextRule::Model model = rule.model;
  const std::array<bool, Features::kCount>& gp_chosen = own;  // kAuto: own where a GP is chosen
  const std::string pct = FormatSignificant(100 * share, 3) + " % of its mean";
  std::string why;
  if (model == NextRule::Model::kSwitch) {
    why = "largest expected reduction of the prediction variance over the list (" + pct + "; ";
    const std::string limit = FormatSignificant(rule.switch_ratio, 3);
    for (int k = 0; k < Features::kCount; ++k) {
      const std::string ratio = FormatSignificant(lack_of_fit[k], 3);
      why += std::string(k ? "; " : "") + kTargetColumns[k] +
             (own[k] ? ": the power law fits its measured screws (leave-one-out error ratio " +
                           ratio + " <= " + limit + "), the chosen family's variance"
              : lack_of_fit[k] > rule.switch_ratio
                  ? ": its measured screws depart from the power law (leave-one-out error "
                    "ratio " + ratio + " > " + limit + "), a power law with a smooth "
                    "departure's variance"
                  : ": the model's choice left the power law (leave-one-out error ratio " +
                        ratio + " <= " + limit + "), a power law with a smooth departure's "
                        "variance");
    }
    why += ")";
  } else if (model == NextRule::Model::kAuto && gp_chosen[0] != gp_chosen[1]) {
    why = "largest expected reduction of the prediction variance over the list (" + pct +
          "; for " + kTargetColumns[gp_chosen[0] ? 0 : 1] + " the chosen GP's, for " +
          kTargetColumns[gp_chosen[0] ? 1 : 0] +
          ", whose chosen family is linear, a power law with a smooth departure's)";
  } else if (model == NextRule::Model::kPowerGp ||
             (model == NextRule::Model::kAuto && !gp_chosen[0])) {
    why = "largest expected reduction of the prediction variance over the list of a power law "
          "with a smooth departure (a GP on the log inputs, given the measured screws): " + pct;
  } else {
    why = "largest expected reduction of the prediction variance over the list (" + pct +
          (model == NextRule::Model::kSum
               ? "; the chosen family's, both outputs, and a power law with a smooth departure's "
                 "weighed equally)"
               : ", both outputs weighed equally)");
    const double here = states[0].weight * states[0].Reduction(j);
    const double there = states[1].weight * states[1].Reduction(j);
    why += here >= there ? "; for the chosen family mostly max elongation"
                         : "; for the chosen family mostly settle time";
  }
  if (now.outside_domain) {
    std::string fields;
    for (const auto& f : now.outside_domain_fields) fields += (fields.empty() ? "" : ", ") + f;
    why += "; outside the training domain in " + fields;
  }
  return why;
}

void ApplyStopRule(const StopRule& rule, std::array<OutputState, Features::kCount> states,
                   std::vector<char> taken, NextDesign* d) {
  if (!rule.Any()) return;
  static const char* kUnit[] = {"um", "s"};
  std::string reason;
  bool enough = true, floor = false;
  for (int k = 0; k < Features::kCount; ++k) {
    if (rule.tolerance[k] <= 0) continue;
    const std::string name = kTargetColumns[k];
    const std::string tol = FormatSignificant(rule.tolerance[k], 3) + " " + kUnit[k];
    if (d->rms_sd_floor[k] > rule.tolerance[k]) {
      floor = true;
      reason += name + ": the scatter alone (the floor of the predictive sd) is " +
                FormatSignificant(d->rms_sd_floor[k], 3) + " " + kUnit[k] + ", above " + tol +
                ": no number of screws reaches it with this model. ";
    } else if (d->rms_sd_now[k] > rule.tolerance[k]) {
      enough = false;
      reason += name + ": RMS sd " + FormatSignificant(d->rms_sd_now[k], 3) + " " + kUnit[k] +
                " above " + tol + ". ";
    } else {
      reason += name + ": RMS sd " + FormatSignificant(d->rms_sd_now[k], 3) + " " + kUnit[k] +
                " within " + tol + ". ";
    }
  }
  if (floor) {
    d->stop = "floor";
  } else if (enough) {
    d->stop = "enough";
    reason += "Further measurements no longer pay.";
  } else {
    d->stop = "continue";
    const int limit = std::min<int>(kStopLookAhead, static_cast<int>(taken.size()));
    for (int n = 1; n <= limit; ++n) {
      double score = 0;
      const int j = BestCandidate(states, taken, &score);
      if (j < 0) break;
      taken[j] = 1;
      for (auto& st : states) st.Measure(j);
      bool reached = true;
      for (int k = 0; k < Features::kCount; ++k)
        reached = reached && (rule.tolerance[k] <= 0 || states[k].Rms() <= rule.tolerance[k]);
      if (reached) {
        d->screws_to_tolerance = n;
        break;
      }
    }
    reason += d->screws_to_tolerance > 0
                  ? "Expected within tolerance after about " +
                        std::to_string(d->screws_to_tolerance) +
                        " screws of this list (hyperparameters as now)."
                  : "Not reached by " + std::to_string(limit) +
                        " screws of this list with the model as it is.";
  }
  if (!reason.empty() && reason.back() == ' ') reason.pop_back();
  d->stop_reason = reason;
}

}  // namespace

Criterion ParseCriterion(const std::string& s) {
  if (s == "d") return Criterion::kD;
  if (s == "i") return Criterion::kI;
  if (s == "bayes-d") return Criterion::kBayesD;
  throw InputError("--criterion '" + s + "': expected 'd' (D-optimal), 'i' (I-optimal) or "
                   "'bayes-d' (Bayesian D-optimal with potential terms)");
}

std::string ToString(Criterion c) {
  return c == Criterion::kD ? "d" : c == Criterion::kI ? "i" : "bayes-d";
}

BayesPrior::Terms ParsePotentialTerms(const std::string& s) {
  if (s == "squares") return BayesPrior::Terms::kSquares;
  if (s == "squares+interactions") return BayesPrior::Terms::kSquaresInteractions;
  throw InputError("--potential-terms '" + s + "': expected 'squares' or "
                   "'squares+interactions'");
}

std::string ToString(BayesPrior::Terms t) {
  return t == BayesPrior::Terms::kSquares ? "squares" : "squares+interactions";
}

NextRule::Model ParseNextModel(const std::string& s) {
  if (s == "power-gp") return NextRule::Model::kPowerGp;
  if (s == "chosen") return NextRule::Model::kChosen;
  if (s == "sum") return NextRule::Model::kSum;
  if (s == "auto") return NextRule::Model::kAuto;
  if (s == "switch") return NextRule::Model::kSwitch;
  throw InputError("--variance '" + s + "': expected 'power-gp' (a GP with a power-law mean on "
                   "the log inputs), 'chosen' (the chosen family's), 'sum' (both), 'auto' (per "
                   "output the chosen GP's where cross-validation chose a GP, else power-gp) or "
                   "'switch' (per output the chosen family's while the power law fits the "
                   "measured screws, else power-gp)");
}

std::string ToString(NextRule::Model m) {
  switch (m) {
    case NextRule::Model::kPowerGp: return "power-gp";
    case NextRule::Model::kChosen: return "chosen";
    case NextRule::Model::kSum: return "sum";
    case NextRule::Model::kAuto: return "auto";
    case NextRule::Model::kSwitch: break;
  }
  return "switch";
}

NextRule::Evidence ParseEvidence(const std::string& s) {
  if (s == "lack-of-fit") return NextRule::Evidence::kLackOfFit;
  if (s == "choice") return NextRule::Evidence::kChoice;
  throw InputError("--departure-evidence '" + s + "': expected 'lack-of-fit' (the power law's "
                   "leave-one-out error over the power-gp's above --switch-ratio) or 'choice' "
                   "(that, or the model's choice not keeping the power law alone)");
}

std::string ToString(NextRule::Evidence e) {
  return e == NextRule::Evidence::kChoice ? "choice" : "lack-of-fit";
}

FillRule ParseFillRule(const std::string& s) {
  if (s == "maximin") return FillRule::kMaximin;
  if (s == "coverage") return FillRule::kCoverage;
  throw InputError("--space-filling-rule '" + s + "': expected 'maximin' (farthest from the "
                   "screws before it) or 'coverage' (most lowers the mean distance from the "
                   "list to its nearest screw)");
}

std::string ToString(FillRule r) { return r == FillRule::kCoverage ? "coverage" : "maximin"; }

SpaceFilling::When ParseFillWhen(const std::string& s) {
  if (s == "always") return SpaceFilling::When::kAlways;
  if (s == "departure") return SpaceFilling::When::kDeparture;
  throw InputError("--space-filling-when '" + s + "': expected 'always' or 'departure' (only "
                   "where --variance switch finds a departure from the power law)");
}

std::string ToString(SpaceFilling::When w) {
  return w == SpaceFilling::When::kDeparture ? "departure" : "always";
}

void InputRanges::Validate(const std::array<const char*, ProcessInputs::kCount>& flags) const {
  for (int j = 0; j < ProcessInputs::kCount; ++j) {
    const std::string what = std::string(flags[j]) + " " + FormatSignificant(lo[j], 6) + ".." +
                             FormatSignificant(hi[j], 6);
    if (!std::isfinite(lo[j]) || !std::isfinite(hi[j]) || lo[j] <= 0)
      throw InputError(what + ": bounds must be finite and positive (the power law takes logs)");
    if (lo[j] > hi[j])
      throw InputError(what + ": reversed range (the lower bound is above the upper bound)");
    std::array<double, ProcessInputs::kCount> a{};
    for (int i = 0; i < ProcessInputs::kCount; ++i) a[i] = lo[i];
    CheckProcessInputs(ProcessInputs::FromArray(a), "design ranges (lower bounds)");
    for (int i = 0; i < ProcessInputs::kCount; ++i) a[i] = hi[i];
    CheckProcessInputs(ProcessInputs::FromArray(a), "design ranges (upper bounds)");
  }
}

std::vector<ProcessInputs> GridCandidates(const InputRanges& r, int levels) {
  if (levels < 2 || levels > 9)
    throw InputError("--levels " + std::to_string(levels) + ": must lie in [2, 9]");
  std::array<std::vector<double>, ProcessInputs::kCount> values;
  for (int j = 0; j < ProcessInputs::kCount; ++j) {
    const int n = r.lo[j] == r.hi[j] ? 1 : levels;
    for (int i = 0; i < n; ++i) {
      const double t = n == 1 ? 0.0 : static_cast<double>(i) / (n - 1);
      const double v = std::exp(std::log(r.lo[j]) + t * (std::log(r.hi[j]) - std::log(r.lo[j])));
      values[j].push_back(i == 0 ? r.lo[j] : i == n - 1 ? r.hi[j] : v);  // the bounds exactly
    }
  }
  std::vector<ProcessInputs> out;
  std::array<std::size_t, ProcessInputs::kCount> idx{};
  while (true) {
    std::array<double, ProcessInputs::kCount> a{};
    for (int j = 0; j < ProcessInputs::kCount; ++j) a[j] = values[j][idx[j]];
    out.push_back(ProcessInputs::FromArray(a));
    int j = ProcessInputs::kCount - 1;
    while (j >= 0 && ++idx[j] == values[j].size()) idx[j--] = 0;
    if (j < 0) break;
  }
  return out;
}

namespace {

// The power-law sd factor sqrt(f_c' M^-1 f_c) of row c, M the information of `picked`.
double SdFactor(const Eigen::MatrixXd& f, const std::vector<int>& picked, int c) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(f.cols(), f.cols());
  for (int i : picked) m.noalias() += f.row(i).transpose() * f.row(i);
  return std::sqrt(std::max(0.0, double(f.row(c) * m.inverse() * f.row(c).transpose())));
}

// `k` more picks of the first design, each by `rule` (maximin or coverage) given those before.
void AddSpaceFilling(const Eigen::MatrixXd& f, int k, FillRule rule, std::vector<int>* picked,
                     std::vector<Pick>* picks) {
  const Eigen::MatrixXd u = f.rightCols(f.cols() - 1);
  std::vector<char> taken(f.rows(), 0);
  for (int i : *picked) taken[i] = 1;
  for (int i = 0; i < k; ++i) {
    Pick pick;
    const int c = FillCandidate(rule, u, static_cast<int>(f.rows()), taken, *picked, &pick.why);
    pick.candidate = c;
    pick.sd_now = {SdFactor(f, *picked, c), 0};
    taken[c] = 1;
    picked->push_back(c);
    pick.sd_after = {SdFactor(f, *picked, c), 0};
    picks->push_back(pick);
  }
}

// `k` more picks of the first design, each of largest integrated variance reduction under the
// power-GP rule (NextRule) given the picks before it.
void AddPowerGpPicks(const Eigen::MatrixXd& f, int k, const NextRule& rule,
                     std::vector<int>* picked, std::vector<Pick>* picks) {
  if (k == 0) return;
  const int n = static_cast<int>(f.rows());
  const Eigen::MatrixXd u = f.rightCols(f.cols() - 1);
  Eigen::MatrixXd all(n + static_cast<int>(picked->size()), u.cols());
  all.topRows(n) = u;
  for (std::size_t i = 0; i < picked->size(); ++i) all.row(n + long(i)) = u.row((*picked)[i]);
  std::array<OutputState, 1> state = {PowerGpState(all, n, rule)};
  state[0].weight = 1.0 / std::max(state[0].members[0].cov.diagonal().mean(), 1e-300);
  std::vector<char> taken(n, 0);
  for (int i : *picked) taken[i] = 1;
  for (int i = 0; i < k; ++i) {
    double score = 0;
    const int c = BestCandidate(state, taken, &score);
    Pick pick;
    pick.candidate = c;
    pick.sd_now = {SdFactor(f, *picked, c), 0};
    taken[c] = 1;
    picked->push_back(c);
    state[0].Measure(c);
    pick.sd_after = {SdFactor(f, *picked, c), 0};
    pick.why = "inside the range: largest expected reduction of the prediction variance over the "
               "list of a power law with a smooth departure given the screws before it (" +
               FormatSignificant(100 * score / n, 3) + " % of its mean)";
    picks->push_back(pick);
  }
}

// The smallest distance between two picks, standardized log inputs (f's columns after the 1).
double MinPairDistance(const Eigen::MatrixXd& f, const std::vector<int>& picked) {
  const Eigen::MatrixXd u = f.rightCols(f.cols() - 1);
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < picked.size(); ++i)
    d = std::min(d, NearestDistance(u, picked[i], {picked.begin(), picked.begin() + long(i)}));
  return d;
}

std::string WhyBayes(const Pick& p, const BayesPrior& bayes) {
  return "Bayesian D-optimal (DuMouchel & Jones 1994; potential terms " + ToString(bayes.terms) +
         ", tau " + FormatSignificant(bayes.tau, 3) + "): a bend of the power law in the log "
         "inputs would show here; power-law sd factor " + FormatSignificant(p.sd_now[0], 3) +
         " -> " + FormatSignificant(p.sd_after[0], 3);
}

// The optimal part of the first design: `count` picks of f by the criterion (greedy start, then
// exchanges; kBayesD on f with its potential columns and their prior, design.h), in the
// explaining order; sets d's bayes_log_det and potential_terms for kBayesD.
std::vector<int> OptimalPicks(const Eigen::MatrixXd& f, int count, Criterion criterion,
                              const BayesPrior& bayes, PowerLawDesign* d) {
  const Eigen::MatrixXd w = f.transpose() * f / static_cast<double>(f.rows());
  Eigen::MatrixXd x = f;
  Eigen::VectorXd prior = Eigen::VectorXd::Zero(f.cols());
  if (criterion == Criterion::kBayesD) {
    if (!(bayes.tau > 0) || !std::isfinite(bayes.tau))
      throw InputError("design --tau " + FormatSignificant(bayes.tau, 6) +
                       ": must be positive and finite (the potential terms' prior sd)");
    const Eigen::MatrixXd z = PotentialColumns(f, bayes.terms);
    x.conservativeResize(Eigen::NoChange, f.cols() + z.cols());
    x.rightCols(z.cols()) = z;
    prior = Eigen::VectorXd::Zero(x.cols());
    prior.tail(z.cols()).setConstant(1.0 / (bayes.tau * bayes.tau));
    d->potential_terms = static_cast<int>(z.cols());
  }
  std::vector<int> picked = GreedyStart(x, count, prior);
  Exchange(x, criterion, w, prior, &picked);
  if (criterion == Criterion::kBayesD)
    d->bayes_log_det = CriterionValue(x, picked, criterion, w, prior);
  const Eigen::VectorXd none = Eigen::VectorXd::Zero(f.cols());
  if (!std::isfinite(CriterionValue(f, picked, Criterion::kD, w, none)))
    throw InputError("design: the candidates do not determine a power law (their log inputs "
                     "are collinear); add candidates that vary the inputs independently");
  d->picks = ExplainingOrder(f, picked);
  if (criterion == Criterion::kBayesD)
    for (std::size_t i = static_cast<std::size_t>(f.cols()); i < d->picks.size(); ++i)
      d->picks[i].why = WhyBayes(d->picks[i], bayes);
  return picked;
}

}  // namespace

PowerLawDesign DesignPowerLaw(const std::vector<ProcessInputs>& cands, int count,
                              Criterion criterion, int space_filling, int inside,
                              const NextRule& rule, FillRule fill, const BayesPrior& bayes) {
  if (cands.empty()) throw InputError("design: the candidate list is empty");
  PowerLawDesign d;
  d.criterion = criterion;
  d.space_filling = space_filling;
  const Eigen::MatrixXd f = PowerLawRows(cands, &d.inputs);
  d.coefficients = static_cast<int>(f.cols());
  const int n = static_cast<int>(cands.size());
  if (space_filling < 0 || space_filling >= count)
    throw InputError("design --space-filling " + std::to_string(space_filling) +
                     ": must lie in [0, --count - 1]");
  if (inside == kInsideAuto)
    inside = criterion == Criterion::kBayesD
                 ? 0
                 : std::clamp(count - space_filling - d.coefficients, 0, kDefaultInside);
  if (inside < 0 || inside + space_filling >= count)
    throw InputError("design --inside " + std::to_string(inside) +
                     ": must lie in [0, --count - --space-filling - 1]");
  const int needed = d.coefficients + space_filling + inside;
  if (needed > n)
    throw InputError("design --count " + std::to_string(count) + ": the " + std::to_string(n) +
                     " candidates are too few: the power law in the " +
                     std::to_string(d.inputs.size()) + " inputs that vary over them has " +
                     std::to_string(d.coefficients) + " coefficients, and the design needs " +
                     std::to_string(needed) +
                     " different candidates (the coefficients plus --space-filling " +
                     std::to_string(space_filling) + " plus --inside " + std::to_string(inside) +
                     "); give more candidate screws");
  if (count - space_filling - inside < d.coefficients || count > n)
    throw InputError("design --count " + std::to_string(count) + ": the power law in the " +
                     std::to_string(d.inputs.size()) + " inputs that vary over the " +
                     std::to_string(n) + " candidates has " + std::to_string(d.coefficients) +
                     " coefficients; the count must lie in [" +
                     std::to_string(d.coefficients + space_filling + inside) + ", " +
                     std::to_string(n) + "] (the coefficients plus --space-filling " +
                     std::to_string(space_filling) + " plus --inside " + std::to_string(inside) +
                     ", at most the candidates)");
  std::vector<int> picked = OptimalPicks(f, count - space_filling - inside, criterion, bayes, &d);
  AddPowerGpPicks(f, inside, rule, &picked, &d.picks);
  d.inside = inside;
  AddSpaceFilling(f, space_filling, fill, &picked, &d.picks);
  const Eigen::VectorXd none = Eigen::VectorXd::Zero(f.cols());
  d.log_det = CriterionValue(f, picked, Criterion::kD, Eigen::MatrixXd(), none) -
              d.coefficients * std::log(count);
  d.min_distance = MinPairDistance(f, picked);
  double sum = 0, mx = 0;
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(f.cols(), f.cols());
  for (int i : picked) m.noalias() += f.row(i).transpose() * f.row(i);
  const Eigen::MatrixXd mi = m.inverse();
  for (int c = 0; c < n; ++c) {
    const double v = std::sqrt(std::max(0.0, double(f.row(c) * mi * f.row(c).transpose())));
    sum += v, mx = std::max(mx, v);
  }
  d.mean_sd_factor = sum / n;
  d.max_sd_factor = mx;
  return d;
}

namespace {

// Per output, whether the rule uses the chosen family's own variance (design.h, NextRule);
// gp_chosen[k]: cross-validation chose a GP for output k (kAuto); departure[k]: the measured
// screws depart from the power law (kSwitch).
using OutputFlags = std::array<bool, Features::kCount>;
OutputFlags OwnVariance(const NextRule& rule, const OutputFlags& gp_chosen,
                        const OutputFlags& departure) {
  OutputFlags own{};
  for (int k = 0; k < Features::kCount; ++k) {
    switch (rule.model) {
      case NextRule::Model::kChosen:
      case NextRule::Model::kSum: own[k] = true; break;
      case NextRule::Model::kPowerGp: own[k] = false; break;
      case NextRule::Model::kAuto: own[k] = gp_chosen[k]; break;
      case NextRule::Model::kSwitch: own[k] = !departure[k]; break;
    }
  }
  return own;
}

// The states the picks are made with (design.h, NextRule), each weighed by its mean variance
// over the list; *units = the number of variances of equal weight (for WhyNext's share).
std::vector<OutputState> CriterionStates(const std::array<OutputState, Features::kCount>& model,
                                         const std::array<bool, Features::kCount>& own,
                                         const Eigen::MatrixXd& u, int n, const NextRule& rule,
                                         double* units) {
  std::vector<OutputState> out;
  int power_gp_outputs = 0;
  for (int k = 0; k < Features::kCount; ++k) {
    if (own[k]) out.push_back(model[k]);
    power_gp_outputs += !own[k];
  }
  *units = static_cast<double>(out.size());
  const bool sum = rule.model == NextRule::Model::kSum;
  if (sum || power_gp_outputs > 0) {
    OutputState s = PowerGpState(u, n, rule);
    const double mean = s.members[0].cov.diagonal().mean();
    // kAuto, kSwitch: the power-GP stands in for each output that does not use its own.
    const double share = sum                                    ? Features::kCount
                         : rule.model == NextRule::Model::kPowerGp ? 1.0
                                                                   : power_gp_outputs;
    s.weight = mean > 0 ? share / mean : 0.0;
    *units += share;
    out.push_back(std::move(s));
  }
  return out;
}

// kSwitch's figures per output from the measured screws' rows z of u and their targets.
std::array<LackOfFit, Features::kCount> MeasuredLackOfFit(const Eigen::MatrixXd& z,
                                                          const std::vector<Features>& targets,
                                                          const NextRule& rule) {
  std::array<LackOfFit, Features::kCount> out;
  const Eigen::Index m = z.rows();
  for (int k = 0; k < Features::kCount; ++k) {
    Eigen::VectorXd ln_y(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      const double y = targets[static_cast<std::size_t>(i)].ToArray()[k];
      if (!(y > 0) || !std::isfinite(y))
        throw InputError("design --variance switch: measured screw " + std::to_string(i + 1) +
                         " has " + kTargetColumns[k] + " = " + FormatSignificant(y, 6) +
                         "; the power law's fit needs positive targets");
      ln_y(i) = std::log(y);
    }
    out[k] = PowerLawLackOfFit(z, ln_y, rule);
  }
  return out;
}

void CheckNextArguments(int n, int count, const SpaceFilling& fill, const NextRule& rule) {
  if (count < 1 || count > n)
    throw InputError("design --count " + std::to_string(count) + ": must lie in [1, " +
                     std::to_string(n) + "] (the candidates)");
  if (fill.screws < 0 || fill.screws > count)
    throw InputError("design --space-filling " + std::to_string(fill.screws) +
                     ": must lie in [0, --count " + std::to_string(count) + "]");
  if (fill.screws > 0 && fill.measured.empty())
    throw InputError("design --space-filling " + std::to_string(fill.screws) +
                     " with --model needs --measured (the screws measured so far, e.g. the "
                     "model's training table): the space-filling picks keep away from them");
  if (rule.model != NextRule::Model::kChosen && fill.measured.empty())
    throw InputError("design --variance " + ToString(rule.model) + " needs --measured (the "
                     "screws measured so far, e.g. the model's training table): the power law "
                     "with a departure is conditioned on them ('--variance chosen' does without)");
  if (!(rule.departure_ratio > 0) || !(rule.length_scale > 0) ||
      !std::isfinite(rule.departure_ratio) || !std::isfinite(rule.length_scale))
    throw InputError("design: --departure-ratio and --length-scale must be finite and positive");
  if (!(rule.switch_ratio > 0) || !std::isfinite(rule.switch_ratio))
    throw InputError("design: --switch-ratio must be finite and positive");
  if (rule.evidence == NextRule::Evidence::kChoice && rule.model != NextRule::Model::kSwitch)
    throw InputError("design --departure-evidence choice needs --variance switch (it says when "
                     "the switch takes the power law with a smooth departure's variance)");
  if (fill.when == SpaceFilling::When::kDeparture && rule.model != NextRule::Model::kSwitch)
    throw InputError("design --space-filling-when departure needs --variance switch (its lack of "
                     "fit says where the measured screws depart from the power law)");
  if (rule.model == NextRule::Model::kSwitch &&
      fill.measured_targets.size() != fill.measured.size())
    throw InputError("design --variance switch needs the measured screws' targets (--measured "
                     "with the columns " + std::string(kTargetColumns[0]) + " and " +
                     kTargetColumns[1] + ", e.g. the model's training table): it judges the "
                     "power law's fit to them");
}

}  // namespace

LackOfFit PowerLawLackOfFit(const Eigen::MatrixXd& z, const Eigen::VectorXd& ln_y,
                            const NextRule& rule) {
  const int m = CheckMeasuredCount(static_cast<int>(z.rows()), static_cast<int>(z.cols()));
  if (ln_y.size() != m) throw InputError("design: lack of fit: screws and targets differ in count");
  LackOfFit f;
  const double mean = ln_y.mean();
  const double sd = std::sqrt((ln_y.array() - mean).square().mean());
  if (!(sd > 0)) return f;  // constant targets: the power law fits exactly
  const Eigen::VectorXd y = (ln_y.array() - mean) / sd;
  std::array<gp::LeaveOneOut, 2> loo;
  std::array<Eigen::ArrayXd, 2> p;  // P_ii
  std::array<double, 2> ratios = {kPowerLawOnlyRatio, rule.departure_ratio};
  for (int v = 0; v < 2; ++v) {
    gp::Gp g;
    try {
      g = PowerGp(z.transpose(), y, ratios[v], rule);
    } catch (const InputError&) {
      throw InputError(kCollinear);
    }
    loo[v] = gp::LeaveOneOutGp(g);
    p[v] = 1.0 / (loo[v].latent_variance.array() + g.SigmaN2());
  }
  double sum0 = 0, sum1 = 0;
  for (int i = 0; i < m; ++i) {
    bool ok = true;
    for (int v = 0; v < 2; ++v)
      ok = ok && p[v](i) > kUndetermined && std::isfinite(loo[v].residual(i));
    if (!ok) continue;
    ++f.rows;
    sum0 += loo[0].residual(i) * loo[0].residual(i);
    sum1 += loo[1].residual(i) * loo[1].residual(i);
  }
  if (f.rows < 2) return f;
  f.power_law_rmse = sd * std::sqrt(sum0 / f.rows);
  f.power_gp_rmse = sd * std::sqrt(sum1 / f.rows);
  f.ratio = f.power_gp_rmse > 0 ? f.power_law_rmse / f.power_gp_rmse : 0.0;
  return f;
}

NextDesign DesignNext(const workpiece::WorkpieceModel& model,
                      const std::vector<ProcessInputs>& cands, int count, const StopRule& stop,
                      const std::vector<int>& lines, const SpaceFilling& fill,
                      const NextRule& rule) {
  if (cands.empty()) throw InputError("design: the candidate list is empty");
  const int n = static_cast<int>(cands.size());
  CheckNextArguments(n, count, fill, rule);
  auto states = States(model, cands, lines);
  NextDesign d;
  d.now = workpiece::PredictBatch(model, cands);
  for (int k = 0; k < Features::kCount; ++k) {
    d.rms_sd_now[k] = states[k].Rms();
    d.rms_sd_floor[k] = states[k].FloorRms();
    states[k].weight = d.rms_sd_now[k] > 0 ? 1.0 / (d.rms_sd_now[k] * d.rms_sd_now[k]) : 0.0;
  }
  const auto initial = states;
  std::vector<ProcessInputs> all = cands;
  all.insert(all.end(), fill.measured.begin(), fill.measured.end());
  std::vector<std::string> names;
  const Eigen::MatrixXd rows = PowerLawRows(all, &names);
  const Eigen::MatrixXd u = rows.rightCols(rows.cols() - 1);
  double units = 0;
  std::array<bool, Features::kCount> gp_chosen{};
  for (int k = 0; k < Features::kCount; ++k)
    gp_chosen[k] = ModelOfOutput(model, k).candidate.family == family::Family::kGaussianProcess;
  if (rule.model == NextRule::Model::kSwitch) {
    const auto fits = MeasuredLackOfFit(u.bottomRows(u.rows() - n), fill.measured_targets, rule);
    for (int k = 0; k < Features::kCount; ++k) {
      d.lack_of_fit_ratio[k] = fits[k].ratio;
      d.choice_departure[k] = rule.evidence == NextRule::Evidence::kChoice &&
                              !PowerLawAlone(model.choice, k);
      d.departure[k] = fits[k].ratio > rule.switch_ratio || d.choice_departure[k];
    }
  }
  const bool departs = d.departure[0] || d.departure[1];
  d.space_filling = fill.when == SpaceFilling::When::kDeparture && !departs ? 0 : fill.screws;
  const auto own = OwnVariance(rule, gp_chosen, d.departure);
  auto crit = CriterionStates(states, own, u, n, rule, &units);
  std::vector<int> near(fill.measured.size());
  std::iota(near.begin(), near.end(), n);
  std::vector<char> taken(n, 0);
  for (int i = 0; i < count; ++i) {
    Pick p;
    if (i >= count - d.space_filling) {
      p.candidate = FillCandidate(fill.rule, u, n, taken, near, &p.why);
    } else {
      double score = 0;
      p.candidate = BestCandidate(crit, taken, &score);
      p.why = WhyNext(states, p.candidate, score / n / units, rule, own, d, d.now[p.candidate]);
    }
    const int j = p.candidate;
    for (int k = 0; k < Features::kCount; ++k) p.sd_now[k] = std::sqrt(initial[k].Variance(j));
    taken[j] = 1;
    near.push_back(j);
    for (auto& st : states) st.Measure(j);
    for (auto& st : crit) st.Measure(j);
    for (int k = 0; k < Features::kCount; ++k) p.sd_after[k] = std::sqrt(states[k].Variance(j));
    d.picks.push_back(p);
  }
  for (int k = 0; k < Features::kCount; ++k) d.rms_sd_after[k] = states[k].Rms();
  ApplyStopRule(stop, initial, std::vector<char>(n, 0), &d);
  return d;
}

}  // namespace whirl::design
