#include "family/family.h"

#include <Eigen/QR>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <mutex>

#include "core/error.h"
#include "core/numbers.h"
#include "core/parallel.h"

namespace whirl::family {
namespace {

constexpr double kOneSigma = 0.6827;  // share of a normal within +-1 sd
constexpr double kTwoSigma = 0.9545;  // share of a normal within +-2 sd

std::string KernelShort(gp::Kernel k) {
  return k == gp::Kernel::kSquaredExponential ? "se" : "matern52";
}

// The table with its inputs and targets mapped through `t` (a table in the transformed space).
ProcessTable TransformedTable(const ProcessTable& table, const TableTransform& t) {
  const Eigen::MatrixXd x = TransformInputs(t, nn::InputMatrix(table.inputs));
  const Eigen::MatrixXd y = TransformTargets(t, nn::TargetMatrix(table.targets));
  ProcessTable out;
  out.source = table.source;
  for (Eigen::Index q = 0; q < x.cols(); ++q) {
    std::array<double, ProcessInputs::kCount> a{};
    std::array<double, Features::kCount> f{};
    for (int i = 0; i < ProcessInputs::kCount; ++i) a[i] = x(i, q);
    for (int k = 0; k < Features::kCount; ++k) f[k] = y(k, q);
    out.inputs.push_back(ProcessInputs::FromArray(a));
    out.targets.push_back(Features::FromArray(f));
  }
  return out;
}

// `fold_fits`: the choice's refits of the candidate (ChooseFamily), one per fold of row q in fold
// q % folds, on `t`'s transform; with `calibrate` they are the calibration's own fold fits when
// nn::CalibrateOutputNoise would train them with the same options on the same folds (it trains
// with min(restarts, 3) restarts and trainbr's own stopping; a size by evidence is chosen per fold
// in the refits, not in the calibration), and are then taken instead of refitted: the same model.
nn::Model FitNetwork(const ProcessTable& t, const Candidate& c, const FitOptions& o,
                     bool calibrate, const std::vector<nn::Model>* fold_fits = nullptr) {
  nn::ModelTrainOptions m = nn::DefaultTrainingOptions();
  m.seed = o.seed;
  m.restarts = o.network_restarts;
  m.threads = o.threads;
  m.noise_folds = calibrate ? o.network_noise_folds : 0;
  if (c.hidden != Candidate::kHiddenByEvidence) {
    m.hidden_candidates.clear();
    m.hidden_by_evidence = false;
    m.hidden_sizes = nn::HiddenLayers(c.hidden);
    if (c.hidden == 0) m.restarts = 1;
  }
  const int rows = static_cast<int>(t.inputs.size()), folds = std::min(m.noise_folds, rows);
  const bool reuse = fold_fits && calibrate && rows >= 4 && folds >= 2 &&
                     fold_fits->size() == static_cast<std::size_t>(folds) &&
                     c.hidden != Candidate::kHiddenByEvidence && m.restarts <= 3 &&
                     m.stopping == nn::Stopping::kTrainbrMatlab;
  if (!reuse) return nn::TrainModel(t, m, t.source);
  nn::ModelTrainOptions uncalibrated = m;
  uncalibrated.noise_folds = 0;
  nn::Model model = nn::TrainModel(t, uncalibrated, t.source);
  nn::CalibrateOutputNoise(t, m, folds, &model, fold_fits);  // as TrainModel would with m
  return model;
}

// Fold of each of `rows` rows among min(folds, rows) folds: row q in fold q % min(folds, rows).
std::vector<int> FoldOfRows(int rows, int folds) {
  const int k = std::min(folds, rows);
  std::vector<int> fold(static_cast<std::size_t>(rows));
  for (int q = 0; q < rows; ++q) fold[static_cast<std::size_t>(q)] = q % k;
  return fold;
}

// Held-out residuals r and latent variances v (units of y) of K-fold refits, row q held out in
// fold q % K; fit_predict(train rows, held-out rows, &mean, &latent variance).
using FoldFitPredict = std::function<void(const Eigen::VectorXi&, const Eigen::VectorXi&,
                                          Eigen::VectorXd*, Eigen::VectorXd*)>;
void KFoldResiduals(const Eigen::VectorXd& y, int folds, const FoldFitPredict& fit_predict,
                    Eigen::VectorXd* r, Eigen::VectorXd* v) {
  const int n = static_cast<int>(y.size()), k = std::min(folds, n);
  const std::vector<int> fold_of = FoldOfRows(n, k);
  r->resize(n);
  v->resize(n);
  for (int f = 0; f < k; ++f) {
    std::vector<int> tr, te;
    for (int q = 0; q < n; ++q) (fold_of[q] == f ? te : tr).push_back(q);
    const Eigen::VectorXi tri =
        Eigen::Map<Eigen::VectorXi>(tr.data(), static_cast<Eigen::Index>(tr.size()));
    const Eigen::VectorXi tei =
        Eigen::Map<Eigen::VectorXi>(te.data(), static_cast<Eigen::Index>(te.size()));
    Eigen::VectorXd mean, latent;
    fit_predict(tri, tei, &mean, &latent);
    (*r)(tei) = y(tei) - mean;
    (*v)(tei) = latent;
  }
}

gp::GpOptions CandidateGpOptions(const FitOptions& o, const Candidate& c) {
  gp::GpOptions go = o.gp;
  go.kernel = c.kernel;
  go.mean = c.mean;
  go.isotropic = c.isotropic;
  return go;
}

// Output k of a linear or GP candidate fitted on (x, y): held-out residuals r and latent variances
// v (transformed units) by closed-form leave-one-out (folds == 0) or K-fold refits (a GP from the
// full fit's hyperparameters, one start; with cold_start from GpOptions' fixed starting points).
struct HeldOut {
  Eigen::VectorXd r, v;
};
HeldOut OutputHeldOut(const FamilyModel& m, int k, const Eigen::MatrixXd& x,
                      const Eigen::VectorXd& y, const FitOptions& o, int folds,
                      bool cold_start = false) {
  HeldOut h;
  const bool linear = m.candidate.family == Family::kLinear;
  if (folds == 0 && linear) {
    const LinearLeaveOneOut loo = LeaveOneOutLinear(m.linears[k], x, y);
    return {loo.residual, loo.latent_variance};
  }
  if (folds == 0) {
    const gp::Gp& gp = m.gps[k];
    const gp::LeaveOneOut loo = gp::LeaveOneOutGp(gp);
    if (gp.rows.empty()) return {loo.residual, loo.latent_variance};
    // A GP on a subset of the rows (GpOptions::max_rows): the other rows are held out already.
    const gp::GpPrediction p = gp::PredictGp(gp, x);
    h.r = y - p.mean;
    h.v = p.latent_variance;
    h.r(gp.rows) = loo.residual;
    h.v(gp.rows) = loo.latent_variance;
    return h;
  }
  const gp::GpOptions go = CandidateGpOptions(o, m.candidate);
  KFoldResiduals(
      y, folds,
      [&](const Eigen::VectorXi& tr, const Eigen::VectorXi& te, Eigen::VectorXd* mean,
          Eigen::VectorXd* latent) {
        if (linear) {
          const LinearPrediction p =
              PredictLinear(FitLinear(x(Eigen::all, tr), y(tr)), x(Eigen::all, te));
          *mean = p.mean;
          *latent = p.latent_variance;
          return;
        }
        const gp::GpPrediction p = gp::PredictGp(
            cold_start ? gp::FitGp(x(Eigen::all, tr), y(tr), go)
                       : gp::FitGpFrom(x(Eigen::all, tr), y(tr), go, m.gps[k].theta),
            x(Eigen::all, te));
        *mean = p.mean;
        *latent = p.latent_variance;
      },
      &h.r, &h.v);
  return h;
}

// The noise of output k from its held-out residuals h (CoverageNoiseVariance, +-1 sd); with
// `loo` (FitOptions::calibrate_two_sd) at least the level at which the closed-form leave-one-out
// residuals are covered at both +-1 and +-2 sd.
void SetNoise(const HeldOut& h, const HeldOut* loo, int k, FamilyModel* m) {
  double s2 = CoverageNoiseVariance(h.r, h.v);
  if (loo) s2 = std::max(s2, CoverageNoiseVariance(loo->r, loo->v, true));
  if (m->candidate.family == Family::kLinear)
    m->linears[k].noise_variance = s2;
  else
    m->gps[k].noise_variance = s2 / (m->gps[k].target_scale * m->gps[k].target_scale);
}

// SetNoise for output k (x, y transformed) from its residuals h of `folds` (OutputHeldOut), with
// the closed-form leave-one-out residuals when FitOptions::calibrate_two_sd.
void SetNoiseFrom(const HeldOut& h, int folds, const FitOptions& o, const Eigen::MatrixXd& x,
                  const Eigen::VectorXd& y, int k, FamilyModel* m) {
  if (!o.calibrate_two_sd) return SetNoise(h, nullptr, k, m);
  if (folds == 0) return SetNoise(h, &h, k, m);
  const HeldOut loo = OutputHeldOut(*m, k, x, y, o, 0);
  SetNoise(h, &loo, k, m);
}

std::string CalibrationText(int folds, bool two_sd) {
  return "per output the smallest noise variance at which +-1 sd (noise + latent variance) "
         "covers 68.27 % of the " +
         (folds == 0 ? std::string("closed-form leave-one-out residuals")
                     : std::to_string(folds) +
                           "-fold cross-validation residuals (refits; a GP's hyperparameters "
                           "refitted)") +
         (two_sd ? ", and +-1 sd 68.27 % and +-2 sd 95.45 % of the closed-form leave-one-out "
                   "residuals"
                 : "");
}

// Held-out errors in original units, t_ik - g^-1(z_ik - r_ik), of output k.
Eigen::RowVectorXd OriginalErrors(const FamilyModel& m, int k, const Eigen::RowVectorXd& t,
                                  const Eigen::VectorXd& z, const HeldOut& h) {
  Eigen::RowVectorXd e(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i)
    e(i) = t(i) - Inverse(m.transform.outputs[k], z(i) - h.r(i));
  return e;
}

// x: the used inputs, y: the targets, both transformed.
std::vector<gp::Gp> FitGps(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, const Candidate& c,
                           const FitOptions& o) {
  const gp::GpOptions go = CandidateGpOptions(o, c);
  std::vector<gp::Gp> gps(static_cast<std::size_t>(y.rows()));
  for (Eigen::Index k = 0; k < y.rows(); ++k) gps[k] = gp::FitGp(x, y.row(k).transpose(), go);
  return gps;
}

std::vector<LinearModel> FitLinears(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) {
  std::vector<LinearModel> fits;
  for (Eigen::Index k = 0; k < y.rows(); ++k) fits.push_back(FitLinear(x, y.row(k).transpose()));
  return fits;
}

// The used inputs of `table` through the model's transform (UsedInputCount() x rows).
Eigen::MatrixXd ModelInputs(const FamilyModel& m, const std::vector<ProcessInputs>& inputs) {
  return UsedInputRows(m.transform, TransformInputs(m.transform, nn::InputMatrix(inputs)));
}

// The inputs mapped through t, one row per input row.
std::vector<ProcessInputs> TransformedRows(const TableTransform& t,
                                           const std::vector<ProcessInputs>& inputs) {
  const Eigen::MatrixXd z = TransformInputs(t, nn::InputMatrix(inputs));
  std::vector<ProcessInputs> rows;
  for (Eigen::Index q = 0; q < z.cols(); ++q) {
    std::array<double, ProcessInputs::kCount> a{};
    for (int i = 0; i < ProcessInputs::kCount; ++i) a[i] = z(i, q);
    rows.push_back(ProcessInputs::FromArray(a));
  }
  return rows;
}

// Means (2 x Q) in the transformed space.
Eigen::MatrixXd TransformedMeans(const FamilyModel& m, const std::vector<ProcessInputs>& z,
                                 Eigen::MatrixXd* sd) {
  Eigen::MatrixXd mean(Features::kCount, z.size());
  sd->resize(Features::kCount, z.size());
  if (m.candidate.family == Family::kNetwork) {
    const std::vector<nn::Prediction> p = nn::PredictBatch(m.network, z);
    for (std::size_t q = 0; q < p.size(); ++q)
      for (int k = 0; k < Features::kCount; ++k) {
        mean(k, q) = p[q].mean.ToArray()[k];
        (*sd)(k, q) = p[q].stddev.ToArray()[k];
      }
    return mean;
  }
  const Eigen::MatrixXd x = UsedInputRows(m.transform, nn::InputMatrix(z));
  for (int k = 0; k < Features::kCount && m.candidate.family == Family::kLinear; ++k) {
    const LinearPrediction p = PredictLinear(m.linears[k], x);
    mean.row(k) = p.mean.transpose();
    sd->row(k) =
        (p.latent_variance.array() + m.linears[k].noise_variance).sqrt().matrix().transpose();
  }
  for (int k = 0; k < Features::kCount && m.candidate.family == Family::kGaussianProcess; ++k) {
    const gp::GpPrediction p = gp::PredictGp(m.gps[k], x);
    mean.row(k) = p.mean.transpose();
    sd->row(k) = p.Stddev().transpose();
  }
  return mean;
}

ProcessTable Rows(const ProcessTable& table, const std::vector<int>& fold_of, int fold,
                  bool held_out) {
  ProcessTable out;
  out.source = table.source;
  for (std::size_t i = 0; i < table.inputs.size(); ++i)
    if ((fold_of[i] == fold) == held_out) {
      out.inputs.push_back(table.inputs[i]);
      out.targets.push_back(table.targets[i]);
    }
  return out;
}

FamilyModel Unfitted(const ProcessTable& table, const Candidate& candidate);

// A network candidate fitted on all rows of `table` (FitNetwork; `fold_fits` as there).
FamilyModel NetworkCandidate(const ProcessTable& table, const Candidate& candidate,
                             const FitOptions& options, bool calibrate,
                             const std::vector<nn::Model>* fold_fits) {
  FamilyModel m = Unfitted(table, candidate);
  m.network = FitNetwork(TransformedTable(table, m.transform), candidate, options, calibrate,
                         fold_fits);
  m.calibration = m.network.noise_calibration;
  return m;
}

// Held-out errors (2 x rows, original units) of one candidate's fold fit; a network fold fit is
// moved into `network` (true) when its transform is the whole table's, so that it is a fold fit
// of the table's network (FitNetwork's fold_fits).
bool FoldErrors(const ProcessTable& table, const Candidate& c, const FitOptions& o, int folds,
                int fold, Eigen::MatrixXd* err, nn::Model* network) {
  const std::vector<int> fold_of = FoldOfRows(static_cast<int>(table.inputs.size()), folds);
  const ProcessTable train = Rows(table, fold_of, fold, false),
                     held = Rows(table, fold_of, fold, true);
  FamilyModel m = FitCandidate(train, c, o, false);
  const std::vector<FamilyPrediction> p = PredictFamily(m, held.inputs);
  for (std::size_t i = 0, row = 0; row < table.inputs.size(); ++row) {
    if (fold_of[row] != fold) continue;
    for (int k = 0; k < Features::kCount; ++k) {
      (*err)(k, static_cast<Eigen::Index>(row)) =
          held.targets[i].ToArray()[k] - p[i].mean.ToArray()[k];
    }
    ++i;
  }
  if (c.family != Family::kNetwork) return false;
  const TableTransform whole = Unfitted(table, c).transform;
  if (m.transform.inputs != whole.inputs || m.transform.outputs != whole.outputs ||
      m.transform.input_used != whole.input_used)
    return false;
  *network = std::move(m.network);
  return true;
}

void CheckTable(const ProcessTable& table);
void CheckRows(const ProcessTable& table, const Candidate& c, int inputs);

// Folds of the held-out errors of linear and GP candidates: 0 = closed-form leave-one-out.
int HeldOutFolds(const ChoiceOptions& o, int folds) { return o.closed_form_loo ? 0 : folds; }

// Fits (or takes from `full`, the closed-form fits) each candidate that predicts an output
// (chosen, or a positive stacking weight) on all rows, with calibration (a network's from its
// fold fits in `fold_networks`, if any: FitNetwork); fills models, model_of_output and, for
// stacked outputs, weights.
void FitChosen(const ProcessTable& table, const ChoiceOptions& options,
               const std::array<Eigen::VectorXd, Features::kCount>& stack,
               std::vector<FamilyModel>& full, const std::vector<char>& calibrated,
               const std::vector<std::vector<nn::Model>>& fold_networks, Choice* choice) {
  std::vector<int> fitted;
  auto model_of = [&](int c) {
    const auto it = std::find(fitted.begin(), fitted.end(), c);
    if (it != fitted.end()) return static_cast<int>(it - fitted.begin());
    fitted.push_back(c);
    if (options.candidates[c].family != Family::kNetwork) {
      if (!calibrated[c]) Calibrate(table, options.fit, &full[c]);
      choice->models.push_back(std::move(full[c]));
    } else {
      const std::vector<nn::Model>& folds = fold_networks[static_cast<std::size_t>(c)];
      choice->models.push_back(NetworkCandidate(table, options.candidates[c], options.fit, true,
                                                folds.empty() ? nullptr : &folds));
    }
    return static_cast<int>(fitted.size()) - 1;
  };
  for (int k = 0; k < Features::kCount; ++k) {
    choice->model_of_output[k] = model_of(choice->chosen[k]);
    for (Eigen::Index c = 0; c < stack[k].size(); ++c)
      if (stack[k](c) > 0) model_of(static_cast<int>(c));
  }
  for (int k = 0; k < Features::kCount; ++k) {
    if (stack[k].size() == 0) continue;
    choice->weights[k].assign(fitted.size(), 0.0);
    for (std::size_t j = 0; j < fitted.size(); ++j) choice->weights[k][j] = stack[k](fitted[j]);
  }
}

void CheckTable(const ProcessTable& table) {
  if (table.targets.size() != table.inputs.size())
    throw InputError(table.source + ": the training table needs the target columns " +
                     kTargetColumns[0] + " and " + kTargetColumns[1]);
  if (table.inputs.size() < 4)
    throw InputError(table.source + ": " + std::to_string(table.inputs.size()) +
                     " training rows; choosing a model family needs at least 4");
}

void CheckRows(const ProcessTable& table, const Candidate& c, int inputs) {
  const int rows = static_cast<int>(table.inputs.size()), need = MinimumRows(c, inputs);
  if (rows >= need) return;
  const std::string what =
      c.family == Family::kLinear
          ? "a linear fit in " + std::to_string(inputs) + " inputs (" + std::to_string(inputs + 1) +
                " coefficients, and 2 rows to judge it)"
          : c.family == Family::kGaussianProcess ? "its mean's coefficients and 2 rows to judge it"
                                                 : "a network";
  throw InputError(table.source + ": " + std::to_string(rows) + " training rows; " + c.Name() +
                   " needs at least " + std::to_string(need) + " (" + what +
                   "): add rows, or choose other candidates (--family)");
}

}  // namespace

std::string Candidate::Name() const {
  const std::string t = log ? "/log" : "/identity";
  if (family == Family::kLinear) return "linear" + t;
  if (family == Family::kNetwork)
    return (hidden == kHiddenByEvidence ? std::string("network-evidence")
                                        : "network-h" + std::to_string(hidden)) +
           t;
  return "gp-" + KernelShort(kernel) + (isotropic ? "-iso-" : "-") + gp::ToString(mean) + t;
}

Candidate ParseCandidate(const std::string& name) {
  const auto slash = name.rfind('/');
  const std::string bad = "candidate '" + name +
                          "': must be linear, network-evidence, network-hN or gp-(se|matern52)-"
                          "[iso-](constant|linear), then /identity or /log";
  if (slash == std::string::npos) throw InputError(bad);
  Candidate c;
  const std::string body = name.substr(0, slash), t = name.substr(slash + 1);
  if (t != "log" && t != "identity") throw InputError(bad);
  c.log = t == "log";
  c.family = Family::kLinear;
  if (c.Name() == name) return c;
  for (const Family f : {Family::kNetwork, Family::kGaussianProcess}) {
    c.family = f;
    for (int h = Candidate::kHiddenByEvidence; h <= 64 && f == Family::kNetwork; ++h) {
      c.hidden = h;
      if (c.Name() == name) return c;
    }
    for (const auto k : {gp::Kernel::kSquaredExponential, gp::Kernel::kMatern52})
      for (const auto m : {gp::Mean::kConstant, gp::Mean::kLinear}) {
        for (const bool iso : {false, true}) {
          c.kernel = k;
          c.mean = m;
          c.isotropic = iso;
          if (f == Family::kGaussianProcess && c.Name() == name) return c;
        }
      }
  }
  throw InputError(bad);
}

namespace {

// `candidate` with its transform of `table`, nothing fitted yet (FitCandidate's first step).
FamilyModel Unfitted(const ProcessTable& table, const Candidate& candidate) {
  CheckTable(table);
  FamilyModel m;
  m.candidate = candidate;
  if (candidate.log)
    m.transform = LogWherePositive(table);
  else
    LeaveOutConstantInputs(table, &m.transform);
  CheckRows(table, candidate, m.transform.UsedInputCount());
  return m;
}

// The fits of a linear or GP model m from Unfitted, on all rows of `table`.
void FitOwnColumns(const ProcessTable& table, const FitOptions& options, FamilyModel* m) {
  const Eigen::MatrixXd x = ModelInputs(*m, table.inputs);
  const Eigen::MatrixXd y = TransformTargets(m->transform, nn::TargetMatrix(table.targets));
  if (m->candidate.family == Family::kLinear)
    m->linears = FitLinears(x, y);
  else
    m->gps = FitGps(x, y, m->candidate, options);
}

}  // namespace

FamilyModel FitCandidate(const ProcessTable& table, const Candidate& candidate,
                         const FitOptions& options, bool calibrate) {
  if (candidate.family == Family::kNetwork)
    return NetworkCandidate(table, candidate, options, calibrate, nullptr);
  FamilyModel m = Unfitted(table, candidate);
  FitOwnColumns(table, options, &m);
  if (calibrate) Calibrate(table, options, &m);
  return m;
}

int CalibrationFolds(const FitOptions& options, int rows, const FamilyModel& m) {
  const int k = std::min(options.calibration_folds, rows);
  if (k == 0 || m.candidate.family == Family::kNetwork) return k;
  if (options.loo_calibration_rows > 0 && rows >= options.loo_calibration_rows) return 0;
  // A GP on a subset of the rows: the rows it does not keep are held out already.
  if (m.candidate.family == Family::kGaussianProcess && options.gp.max_rows > 0 &&
      rows > options.gp.max_rows)
    return 0;
  const int smallest_training_split = rows - (rows + k - 1) / k;
  return smallest_training_split >= MinimumRows(m.candidate, m.transform.UsedInputCount()) ? k : 0;
}

void Calibrate(const ProcessTable& table, const FitOptions& options, FamilyModel* m) {
  const Eigen::MatrixXd x = ModelInputs(*m, table.inputs);
  const Eigen::MatrixXd y = TransformTargets(m->transform, nn::TargetMatrix(table.targets));
  const int folds = CalibrationFolds(options, static_cast<int>(table.inputs.size()), *m);
  for (int k = 0; k < Features::kCount; ++k) {
    const Eigen::VectorXd yk = y.row(k).transpose();
    SetNoiseFrom(OutputHeldOut(*m, k, x, yk, options, folds, true), folds, options, x, yk, k, m);
  }
  m->calibration = CalibrationText(folds, options.calibrate_two_sd);
}

namespace {

using HeldOuts = std::array<HeldOut, Features::kCount>;

// The noise calibration of m (fitted on `table`) from its held-out residuals h of `folds`.
void CalibrateFrom(const ProcessTable& table, const FitOptions& options, int folds,
                   const HeldOuts& h, FamilyModel* m) {
  const Eigen::MatrixXd x = ModelInputs(*m, table.inputs);
  const Eigen::MatrixXd y = TransformTargets(m->transform, nn::TargetMatrix(table.targets));
  for (int k = 0; k < Features::kCount; ++k)
    SetNoiseFrom(h[k], folds, options, x, y.row(k).transpose(), k, m);
  m->calibration = CalibrationText(folds, options.calibrate_two_sd);
}

}  // namespace

// Held-out errors (original units) of m's `folds` (0: closed form; K-fold refits from the fixed
// starting points with `cold`, from the full fit's hyperparameters otherwise: these need m
// fitted, the others only its transform), with m's calibration from them (`calibrate`); the
// residuals in `kept` if non-null.
Eigen::MatrixXd HeldOutErrors(const ProcessTable& table, const FitOptions& options, int folds,
                              FamilyModel* m, bool calibrate, bool cold = true,
                              HeldOuts* kept = nullptr) {
  if (m->candidate.family == Family::kNetwork)
    throw InputError("held-out errors of a fitted model: not available for " + m->candidate.Name());
  const Eigen::MatrixXd x = ModelInputs(*m, table.inputs);
  const Eigen::MatrixXd t = nn::TargetMatrix(table.targets);
  const Eigen::MatrixXd y = TransformTargets(m->transform, t);
  Eigen::MatrixXd err(t.rows(), t.cols());
  HeldOuts h;
  for (int k = 0; k < Features::kCount; ++k) {
    h[k] = OutputHeldOut(*m, k, x, y.row(k).transpose(), options, folds, cold);
    err.row(k) = OriginalErrors(*m, k, t.row(k), y.row(k).transpose(), h[k]);
  }
  if (calibrate) CalibrateFrom(table, options, folds, h, m);
  if (kept) *kept = std::move(h);
  return err;
}

Eigen::MatrixXd LeaveOneOutSquaredErrors(const FamilyModel& m, const ProcessTable& table) {
  FamilyModel copy = m;
  return HeldOutErrors(table, {}, 0, &copy, false).array().square().matrix();
}

std::vector<FamilyPrediction> PredictFamily(const FamilyModel& model,
                                            const std::vector<ProcessInputs>& inputs) {
  std::vector<FamilyPrediction> out(inputs.size());
  if (inputs.empty()) return out;
  Eigen::MatrixXd sd;
  const Eigen::MatrixXd mean = TransformedMeans(model, TransformedRows(model.transform, inputs), &sd);
  for (std::size_t q = 0; q < inputs.size(); ++q) {
    std::array<double, Features::kCount> m{}, s{};
    for (int k = 0; k < Features::kCount; ++k) {
      const MeanSd back = MapBack(model.transform.outputs[k], mean(k, q), sd(k, q));
      m[k] = back.mean;
      s[k] = back.sd;
    }
    out[q] = {Features::FromArray(m), Features::FromArray(s)};
  }
  return out;
}

Eigen::VectorXd ConvexStackWeights(const Eigen::MatrixXd& predictions,
                                   const Eigen::VectorXd& target) {
  const Eigen::Index n = predictions.rows(), nc = predictions.cols();
  if (n == 0 || nc == 0 || nc > 12 || target.size() != n)
    throw InputError("stacking weights: " + std::to_string(n) + " x " + std::to_string(nc) +
                     " predictions and " + std::to_string(target.size()) +
                     " targets; need rows > 0, 1 to 12 candidates, one target per row");
  // With sum w = 1, target - predictions w = errors w: the problem in the candidates' errors,
  // scaled to their largest, is far better conditioned than in the predictions (which share
  // the target's level: a Friedman #2 output of about 1000 lost every support set to rounding).
  Eigen::MatrixXd e = (-predictions).colwise() + target;
  const double scale = e.cwiseAbs().maxCoeff();
  if (scale > 0) e /= scale;
  const Eigen::MatrixXd gram = e.transpose() * e;
  Eigen::VectorXd best = Eigen::VectorXd::Unit(nc, 0);
  double best_sse = gram(0, 0);
  int best_size = 1;
  for (unsigned mask = 1; mask < (1u << nc); ++mask) {
    std::vector<Eigen::Index> on;
    for (Eigen::Index c = 0; c < nc; ++c)
      if (mask & (1u << c)) on.push_back(c);
    const Eigen::Index m = static_cast<Eigen::Index>(on.size());
    Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(m + 1, m + 1);  // [E'E 1; 1' 0]
    kkt.topLeftCorner(m, m) = gram(on, on);
    kkt.topRightCorner(m, 1).setOnes();
    kkt.bottomLeftCorner(1, m).setOnes();
    const Eigen::VectorXd rhs = Eigen::VectorXd::Unit(m + 1, m);
    Eigen::VectorXd w = kkt.completeOrthogonalDecomposition().solve(rhs).head(m);
    if (!w.allFinite() || (w.array() < 0).any() || std::abs(w.sum() - 1.0) > 1e-6) continue;
    w /= w.sum();
    const double sse = w.dot(gram(on, on) * w);
    const double tol = 1e-12 * std::max(best_sse, 1e-300);
    if (sse < best_sse - tol || (sse <= best_sse + tol && m < best_size)) {
      best.setZero();
      best(on) = w;
      best_sse = sse;
      best_size = static_cast<int>(m);
    }
  }
  return best;
}

namespace {

// Mean and standard error of paired differences (below).
struct MeanAndSe {
  double mean, se;
};
MeanAndSe OfDifferences(const Eigen::ArrayXd& d);

}  // namespace

ShrunkStack ShrunkStackWeights(const Eigen::MatrixXd& predictions, const Eigen::VectorXd& target,
                               int folds, double start_se, double full_se) {
  ShrunkStack out;
  const Eigen::VectorXd all = ConvexStackWeights(predictions, target);
  const Eigen::Index n = predictions.rows();
  if (folds < 2) throw InputError("stacking weights: " + std::to_string(folds) + " folds; need >= 2");
  const int k = static_cast<int>(std::min<Eigen::Index>(folds, n));
  Eigen::VectorXd stacked(n);
  for (int f = 0; f < k && n >= 2; ++f) {
    std::vector<Eigen::Index> train, held;
    for (Eigen::Index q = 0; q < n; ++q) (q % k == f ? held : train).push_back(q);
    const Eigen::VectorXd w = ConvexStackWeights(predictions(train, Eigen::all), target(train));
    stacked(held) = predictions(held, Eigen::all) * w;
  }
  if (n < 2) stacked = predictions * all;
  const Eigen::ArrayXd d = (target - predictions.col(0)).array().square() -
                           (target - stacked).array().square();
  const MeanAndSe m = OfDifferences(d);
  out.z = m.se > 0 ? m.mean / m.se : (m.mean > 0 ? std::numeric_limits<double>::infinity() : 0.0);
  if (full_se < 0)
    out.share = 1;
  else if (full_se <= start_se)
    out.share = out.z > start_se ? 1 : 0;
  else
    out.share = std::clamp((out.z - start_se) / (full_se - start_se), 0.0, 1.0);
  out.weights = out.share * all;
  out.weights(0) += 1 - out.share;
  return out;
}

namespace {

// The mean of paired differences d (row by row, two candidates' squared held-out errors) and its
// standard error (sample sd / sqrt(n)): the comparison behind BeatsFirst and the
// one-standard-error rule.
MeanAndSe OfDifferences(const Eigen::ArrayXd& d) {
  const double n = static_cast<double>(d.size()), mean = d.mean();
  return {mean, std::sqrt((d - mean).square().sum() / std::max(n - 1.0, 1.0) / n)};
}

}  // namespace

bool BeatsFirst(const Eigen::VectorXd& first, const Eigen::VectorXd& other, double z, int wins,
                int blocks, double row_share) {
  if (first.size() != other.size() || first.size() == 0 || blocks < 1)
    throw InputError("leaving the first candidate: " + std::to_string(first.size()) + " and " +
                     std::to_string(other.size()) + " squared errors in " +
                     std::to_string(blocks) + " blocks; need equal sizes > 0 and blocks >= 1");
  const Eigen::ArrayXd d = (first - other).array();
  const double n = static_cast<double>(d.size());
  const auto [mean, se] = OfDifferences(d);
  if (!(mean > z * se) || mean <= 0) return false;
  const int b = std::min<int>(blocks, static_cast<int>(d.size()));
  Eigen::ArrayXd block = Eigen::ArrayXd::Zero(b);
  for (Eigen::Index q = 0; q < d.size(); ++q) block(q % b) += d(q);
  return (block > 0).count() >= std::min(wins, b) &&
         static_cast<double>((d > 0).count()) >= row_share * n;
}

int SimplestWithinOneStandardError(const std::vector<Eigen::VectorXd>& squared_errors) {
  if (squared_errors.empty()) throw InputError("one-standard-error rule: no candidates");
  std::size_t best = 0;
  for (std::size_t c = 1; c < squared_errors.size(); ++c)
    if (squared_errors[c].mean() < squared_errors[best].mean()) best = c;
  double simpler = std::numeric_limits<double>::infinity();  // lowest mean of those before c
  for (std::size_t c = 0; c < squared_errors.size(); ++c) {
    const auto [mean, se] = OfDifferences((squared_errors[c] - squared_errors[best]).array());
    if (mean <= se && squared_errors[c].mean() <= simpler) return static_cast<int>(c);
    simpler = std::min(simpler, squared_errors[c].mean());
  }
  return static_cast<int>(best);
}

namespace {

// The smallest factor kappa at which kappa sd_i >= |r_i| for at least `share` of the rows.
class ScaleQuantiles {
 public:
  ScaleQuantiles(const Eigen::VectorXd& residual, const Eigen::VectorXd& sd) {
    if (residual.size() == 0 || residual.size() != sd.size() || !(sd.array() > 0).all())
      throw InputError("sd scale: " + std::to_string(residual.size()) + " residuals and " +
                       std::to_string(sd.size()) + " sd; need equal sizes > 0 and every sd > 0");
    for (Eigen::Index i = 0; i < residual.size(); ++i)
      ratio_.push_back(std::abs(residual(i)) / sd(i));
    std::sort(ratio_.begin(), ratio_.end());
  }
  double At(double share) const {
    const double n = static_cast<double>(ratio_.size());
    const auto q = static_cast<std::size_t>(std::ceil(share * n - 1e-9));
    return ratio_[std::clamp<std::size_t>(q, 1, ratio_.size()) - 1];
  }

 private:
  std::vector<double> ratio_;
};

}  // namespace

double CoverageScale(const Eigen::VectorXd& residual, const Eigen::VectorXd& sd, bool two_sd) {
  const ScaleQuantiles at(residual, sd);
  return std::clamp(two_sd ? std::max(at.At(kOneSigma), at.At(kTwoSigma) / 2) : at.At(kOneSigma),
                    0.25, 4.0);
}

double StackSdScale(const Eigen::VectorXd& residual, const Eigen::VectorXd& sd, double two_share) {
  if (!(two_share >= 0 && two_share <= 1))
    throw InputError("sd scale: the +-2 sd share " + MessageNumber(two_share) +
                     " must lie in [0, 1]");
  const ScaleQuantiles at(residual, sd);
  const double one = at.At(kOneSigma);
  return std::clamp(two_share > 0 ? std::max(one, at.At(two_share) / 2) : one, 0.25, 1.0);
}

double CoverageNoiseVariance(const Eigen::VectorXd& residual,
                             const Eigen::VectorXd& latent_variance, bool two_sd) {
  if (residual.size() == 0 || residual.size() != latent_variance.size())
    throw InputError("noise calibration: " + std::to_string(residual.size()) + " residuals and " +
                     std::to_string(latent_variance.size()) + " variances; need equal, > 0");
  const Eigen::ArrayXd r2 = residual.array().square();
  auto covers = [&](double s2) {
    const auto v = s2 + latent_variance.array();
    return (r2 <= v).cast<double>().mean() >= kOneSigma &&
           (!two_sd || (r2 <= 4.0 * v).cast<double>().mean() >= kTwoSigma);
  };
  double lo = 0.0, hi = r2.maxCoeff() + 1e-300;
  if (covers(lo)) return 0.0;
  for (int it = 0; it < 200 && hi > lo; ++it) {
    const double mid = 0.5 * (lo + hi);
    (covers(mid) ? hi : lo) = mid;
  }
  return hi;
}

void to_json(nlohmann::json& j, const CvRow& r) {
  j = {{"candidate", r.candidate.Name()},
       {"cv_rmse", std::vector<double>(r.cv_rmse.data(), r.cv_rmse.data() + r.cv_rmse.size())},
       {"score", r.score}};
}

std::string FamilyModel::OutputName(int k) const {
  const std::string name = candidate.Name();
  if (!candidate.log || transform.outputs.at(static_cast<std::size_t>(k)) == ColumnTransform::kLog)
    return name;
  return name + "-inputs";
}

int MinimumRows(const Candidate& c, int inputs) {
  if (c.family == Family::kLinear) return inputs + 3;
  if (c.family == Family::kGaussianProcess) return gp::MeanSize(c.mean, inputs) + 2;
  return 4;
}

std::vector<Candidate> ChoiceOptions::DefaultCandidates() {
  std::vector<Candidate> c;
  for (const char* name : {"linear/log", "linear/identity", "gp-matern52-linear/log",
                           "gp-matern52-constant/identity", "gp-se-constant/identity",
                           "network-h2/identity"})
    c.push_back(ParseCandidate(name));
  return c;
}

double FitDifferenceInSd(const FamilyModel& a, const FamilyModel& b, const ProcessTable& table,
                         int k) {
  if (a.transform.inputs != b.transform.inputs || a.transform.outputs != b.transform.outputs)
    throw InputError("fit difference of " + a.candidate.Name() + " and " + b.candidate.Name() +
                     ": the two must share their transform (" + a.transform.Describe() +
                     " against " + b.transform.Describe() + ")");
  if (k < 0 || k >= Features::kCount || table.targets.size() != table.inputs.size())
    throw InputError("fit difference: output " + std::to_string(k) + " of a table with " +
                     std::to_string(table.targets.size()) + " targets and " +
                     std::to_string(table.inputs.size()) + " rows");
  const std::vector<ProcessInputs> z = TransformedRows(a.transform, table.inputs);
  Eigen::MatrixXd sd;
  const Eigen::VectorXd d =
      (TransformedMeans(a, z, &sd).row(k) - TransformedMeans(b, z, &sd).row(k)).transpose();
  const Eigen::VectorXd y =
      TransformTargets(a.transform, nn::TargetMatrix(table.targets)).row(k).transpose();
  const double spread = std::sqrt((y.array() - y.mean()).square().mean());
  return spread > 0 ? std::sqrt(d.squaredNorm() / static_cast<double>(d.size())) / spread : 0.0;
}

int FittedHyperparameters(const Candidate& c, int inputs) {
  if (c.family != Family::kGaussianProcess) return 0;
  return (c.isotropic ? 1 : inputs) + 2;
}

double GpLogEvidence(const FamilyModel& m, int k) {
  if (k < 0 || static_cast<std::size_t>(k) >= m.gps.size())
    throw InputError("GP evidence: " + m.candidate.Name() + " holds no GP for output " +
                     std::to_string(k));
  const gp::Gp& g = m.gps[static_cast<std::size_t>(k)];
  const double n = static_cast<double>(g.u.size());
  double e = gp::LogMarginalLikelihood(g) - n * std::log(g.target_scale);
  if (m.transform.outputs[k] == ColumnTransform::kLog)  // sum_i ln y_i, ln y_i = shift + s u_i
    e -= n * g.target_shift + g.target_scale * g.u.sum();
  return e;
}

namespace {

// The linear candidate on the columns of candidate c (-1 if there is none).
int LinearOnTheSameColumns(const ChoiceOptions& o, const Candidate& c) {
  for (std::size_t l = 0; l < o.candidates.size(); ++l)
    if (o.candidates[l].family == Family::kLinear && o.candidates[l].log == c.log)
      return static_cast<int>(l);
  return -1;
}

// Held-out errors of output k (original units) from K-fold refits of m (row q held out in fold
// q % K; a GP from GpOptions' fixed starting points with `cold`, so that no hyperparameter has
// seen the held-out rows, else from m's hyperparameters).
Eigen::RowVectorXd RefitErrors(const FamilyModel& m, const ProcessTable& table, const FitOptions& o,
                               int folds, int k, bool cold = true) {
  const Eigen::MatrixXd x = ModelInputs(m, table.inputs);
  const Eigen::MatrixXd t = nn::TargetMatrix(table.targets);
  const Eigen::VectorXd y = TransformTargets(m.transform, t).row(k).transpose();
  return OriginalErrors(m, k, t.row(k), y, OutputHeldOut(m, k, x, y, o, folds, cold));
}
Eigen::VectorXd RefitSquaredErrors(const FamilyModel& m, const ProcessTable& table,
                                   const FitOptions& o, int folds, int k) {
  return RefitErrors(m, table, o, folds, k).array().square().matrix().transpose();
}

// A chosen GP that ChoiceOptions::equivalence_sd checks: few rows per hyperparameter, more degrees
// of freedom than the linear fit, a fit near the linear candidate's on the same columns.
struct NearLinearGp {
  int same = -1;        // that linear candidate
  double distance = 0;  // FitDifferenceInSd to it
  double df = 0;        // gp::EffectiveDegreesOfFreedom
};
constexpr int kLinearCoefficients = ProcessInputs::kCount + 1;

bool IsNearLinearGp(const ProcessTable& table, const ChoiceOptions& o,
                    const std::vector<FamilyModel>& full, int c, int k, NearLinearGp* n) {
  const Candidate& gp = o.candidates[c];
  const int rows = static_cast<int>(table.inputs.size());
  if (o.equivalence_sd <= 0 || gp.family != Family::kGaussianProcess ||
      rows >= ChoiceOptions::kRowsPerHyperparameter * FittedHyperparameters(gp))
    return false;
  n->same = LinearOnTheSameColumns(o, gp);
  if (n->same < 0) return false;
  n->distance = FitDifferenceInSd(full[c], full[n->same], table, k);
  n->df = gp::EffectiveDegreesOfFreedom(full[c].gps[k]);
  return n->distance < o.equivalence_sd && n->df > kLinearCoefficients;
}

std::string SetAsideNote(const ChoiceOptions& o, const FamilyModel& gp, int lin, int k, int rows,
                         const NearLinearGp& n, int folds, double rmse_gp, double rmse_lin) {
  const std::string column = kTargetColumns[k], unit = kTargetUnits[k];
  const std::string& linear = o.candidates[lin].Name();
  return column + ": " + gp.candidate.Name() + " set aside for " + linear + ": at " +
         std::to_string(rows) + " rows (fewer than " +
         std::to_string(ChoiceOptions::kRowsPerHyperparameter) +
         " per GP hyperparameter) it spends " + FormatSignificant(n.df, 3) +
         " degrees of freedom (the linear fit's " + std::to_string(kLinearCoefficients) +
         " coefficients) on a fit that differs from " + o.candidates[n.same].Name() + "'s by " +
         FormatSignificant(n.distance, 2) + " of the training spread (sd) of " +
         (gp.transform.outputs[k] == ColumnTransform::kLog ? "ln(" + column + ")" : column) +
         " (< " + FormatSignificant(o.equivalence_sd, 2) + "), and refitted on " +
         std::to_string(folds) + " folds its RMSE " + FormatSignificant(rmse_gp, 3) + " " + unit +
         " does not beat " + linear + "'s " + FormatSignificant(rmse_lin, 3) + " " + unit +
         " by more than one standard error: not enough to trust its held-out error in the table, "
         "whose hyperparameters were fitted on every row";
}

// ChoiceOptions::equivalence_sd for output k: the reason to set the chosen candidate c aside for
// the linear candidates' choice `lin` (empty: keep c). The refits need every training split to
// hold at least kLinearCoefficients + 2 rows (FitLinear); below that the choice stays.
// `refit_err`: c's held-out errors (2 x rows) of these refits if ChooseFamily has them already.
std::string WhySetAside(const ProcessTable& table, const ChoiceOptions& o,
                        const std::vector<FamilyModel>& full, int c, int lin, int k,
                        const Eigen::MatrixXd* refit_err) {
  NearLinearGp n;
  if (!IsNearLinearGp(table, o, full, c, k, &n)) return "";
  const int rows = static_cast<int>(table.inputs.size());
  const int folds = std::min(o.folds, rows);
  if (rows - (rows + folds - 1) / folds < kLinearCoefficients + 2) return "";
  FitOptions fo = o.fit;
  fo.threads = 1;
  const Eigen::VectorXd e_lin = RefitSquaredErrors(full[lin], table, fo, folds, k);
  const Eigen::VectorXd e_gp = refit_err ? refit_err->row(k).array().square().matrix().transpose()
                                         : RefitSquaredErrors(full[c], table, fo, folds, k);
  if (SimplestWithinOneStandardError({e_lin, e_gp}) == 1) return "";
  return SetAsideNote(o, full[c], lin, k, rows, n, folds, std::sqrt(e_gp.mean()),
                      std::sqrt(e_lin.mean()));
}

// `kept` without its GP candidates but `only` (ChoiceOptions::refit_lowest_gp_rows: the one GP
// judged by refits; the others' held-out errors are their closed-form leave-one-out's).
std::vector<int> WithOneGp(const std::vector<int>& kept, const ChoiceOptions& o, int only) {
  std::vector<int> out;
  for (int c : kept)
    if (o.candidates[c].family != Family::kGaussianProcess || c == only) out.push_back(c);
  return out;
}

// ChoiceOptions::gp_slot_large: per candidate and output the GP's GpLogEvidence (kBic: minus
// (q / 2) ln n), -infinity for other candidates; empty where the held-out errors give the slot.
using GpEvidence = std::vector<std::array<double, Features::kCount>>;

// The GP candidate of highest evidence of output k among all of `o` (the first of equal ones;
// -1 if none).
int HighestEvidenceGp(const ChoiceOptions& o, const GpEvidence& ev, int k) {
  int best = -1;
  for (std::size_t c = 0; c < o.candidates.size(); ++c)
    if (o.candidates[c].family == Family::kGaussianProcess &&
        (best < 0 || ev[c][k] > ev[static_cast<std::size_t>(best)][k]))
      best = static_cast<int>(c);
  return best;
}

// ChoiceOptions::lowest_gp: `kept` without its GP candidates except the one with the lowest
// held-out error of output k (the first of equal ones), which keeps its place; with
// lowest_gp_per_scale below few_rows rows (lowest_gp_per_scale_large from few_rows on) one such
// GP per column scale (Candidate::log); with `ev` from few_rows rows (ChoiceOptions::gp_slot_large)
// the GP of highest evidence among all GP candidates instead, if it is in `kept`.
std::vector<int> WithTheLowestGpOnly(const std::vector<int>& kept,
                                     const std::vector<Eigen::MatrixXd>& err,
                                     const ChoiceOptions& o, int k, const GpEvidence& ev) {
  const bool small = err.front().cols() < o.few_rows;
  if (!ev.empty() && !small) return WithOneGp(kept, o, HighestEvidenceGp(o, ev, k));
  const bool per_scale = small ? o.lowest_gp_per_scale : o.lowest_gp_per_scale_large;
  std::array<int, 2> best = {-1, -1};  // [log]; one slot without per_scale
  for (int c : kept) {
    int& b = best[per_scale && o.candidates[c].log ? 1 : 0];
    if (o.candidates[c].family == Family::kGaussianProcess &&
        (b < 0 || err[c].row(k).squaredNorm() < err[b].row(k).squaredNorm()))
      b = c;
  }
  std::vector<int> out;
  for (int c : kept)
    if (o.candidates[c].family != Family::kGaussianProcess || c == best[0] || c == best[1])
      out.push_back(c);
  return out;
}

// ChoiceOptions::lowest_gp (or the one refitted GP `only` if >= 0) applied to `kept`, whose first
// is the candidate the gate measured the others against. If that leaves none (every candidate
// kept is a GP, as with `whirl train --family gp`, and the slot's GP is one the gate dropped:
// gp_slot_large and `only` pick among all GPs), the first of `kept` takes part alone, as the
// first candidate does in the default list when the slot's GP is dropped.
std::vector<int> GpsThatTakePart(const std::vector<int>& kept,
                                 const std::vector<Eigen::MatrixXd>& err, const ChoiceOptions& o,
                                 int k, int only, const GpEvidence& ev) {
  std::vector<int> out = only >= 0     ? WithOneGp(kept, o, only)
                         : o.lowest_gp ? WithTheLowestGpOnly(kept, err, o, k, ev)
                                       : kept;
  if (out.empty() && !kept.empty()) out.push_back(kept.front());
  return out;
}

// Output k's choice among the candidates `kept` (ChoiceOptions::one_standard_error, or the
// lowest error), after ChoiceOptions::leave_first_se and leave_first_blocks have removed those
// that do not beat the first of `kept` clearly enough; `only`, `ev`: GpsThatTakePart.
int ChooseAmong(const std::vector<int>& given, const std::vector<Eigen::MatrixXd>& err,
                const ChoiceOptions& o, int k, int only = -1, const GpEvidence& ev = {}) {
  const double z = err.front().cols() < o.few_rows ? o.leave_first_se : o.leave_first_se_large;
  const bool all = !o.one_standard_error ||
                   (z <= 0 && o.leave_first_blocks <= 0 && o.leave_first_row_share <= 0);
  std::vector<int> kept;
  for (int c : given)
    if (kept.empty() || all ||
        BeatsFirst(err[given.front()].row(k).array().square().matrix(),
                   err[c].row(k).array().square().matrix(), z, o.leave_first_blocks, o.folds,
                   o.leave_first_row_share))
      kept.push_back(c);
  kept = GpsThatTakePart(kept, err, o, k, only, ev);
  std::vector<Eigen::VectorXd> sq;
  for (int c : kept) sq.push_back(err[c].row(k).array().square().matrix());
  if (o.one_standard_error) return kept[SimplestWithinOneStandardError(sq)];
  std::size_t best = 0;
  for (std::size_t i = 1; i < sq.size(); ++i)
    if (sq[i].mean() < sq[best].mean()) best = i;
  return kept[best];
}

}  // namespace

namespace {

// `o` without its GP candidates on tables too small for their refits (ChoiceOptions::few_rows:
// every training split of `folds` needs the rows of a linear fit in `inputs` inputs), unless they
// are all there is; `note` says so.
ChoiceOptions ActiveCandidates(const ChoiceOptions& given, int rows, int folds, int inputs,
                               std::string* note) {
  ChoiceOptions o = given;
  if (o.network_max_rows > 0 && rows > o.network_max_rows) {
    o.candidates.clear();
    for (const Candidate& c : given.candidates)
      if (c.family != Family::kNetwork) o.candidates.push_back(c);
    if (o.candidates.empty()) return given;
    if (o.candidates.size() < given.candidates.size())
      *note = "above " + std::to_string(o.network_max_rows) +
              " rows the network candidates sit out (their refits would exceed the fit time "
              "budget)";
  }
  ChoiceOptions active = o;
  const int split = rows - (rows + folds - 1) / folds, need = inputs + 3;
  if (!o.closed_form_loo || rows >= o.few_rows || split >= need) return active;
  active.candidates.clear();
  for (const Candidate& c : o.candidates)
    if (c.family == Family::kLinear) active.candidates.push_back(c);
  if (active.candidates.empty() || active.candidates.size() == o.candidates.size()) return o;
  *note = "at " + std::to_string(rows) + " rows the GP candidates sit out (and any network): " +
          "a GP must beat the " +
          "linear fits in " + std::to_string(folds) + "-fold refits, whose training splits of " +
          std::to_string(split) + " rows are fewer than a linear fit in " +
          std::to_string(inputs) + " inputs needs (" + std::to_string(need) + ")";
  return active;
}

// Choice::warnings: the constant inputs left out, and the columns the log candidates keep raw.
std::vector<std::string> TableWarnings(const ProcessTable& table, const ChoiceOptions& o,
                                       const std::vector<int>& constant) {
  std::vector<std::string> out;
  for (int i : constant)
    out.push_back(std::string(kInputColumns[i]) + " is constant (" +
                  MessageNumber(table.inputs.front().ToArray()[i]) + " " + kInputUnits[i] +
                  " in every row of " + table.source +
                  "): left out of the model; its predictions do not depend on it, and other "
                  "values of it are outside the training domain");
  for (int k : ConstantTargets(table))
    out.push_back(std::string(kTargetColumns[k]) + " is the same (" +
                  MessageNumber(table.targets.front().ToArray()[k]) + " " + kTargetUnits[k] +
                  ") in every row of " +
                  table.source + ": there is nothing to learn for it, every candidate predicts "
                  "about that value and the choice for it rests on no evidence; check the column "
                  "(a clipped or rounded measurement?)");
  std::string logs, first;
  for (const Candidate& c : o.candidates)
    if (c.log) {
      if (first.empty()) first = c.Name();
      logs += (logs.empty() ? "" : ", ") + c.Name();
    }
  if (logs.empty()) return out;
  for (const LogException& e : LogExceptions(table)) {
    if (e.input && !LogWherePositive(table).input_used[e.column]) continue;
    const std::string column = e.input ? kInputColumns[e.column] : kTargetColumns[e.column];
    out.push_back(e.Describe(table) + ". The log candidates (" + logs + ") keep " + column +
                  " on its raw scale" +
                  (e.input ? "" : " (named " + first + "-inputs and so on: the log of the inputs only)") +
                  "; check the row");
  }
  return out;
}

}  // namespace

namespace {

// ChoiceOptions::stack for output k of targets t (outputs x rows): the shrunk stacking weights
// of every candidate (ShrunkStackWeights of their held-out predictions t - err), 0 for those
// that stack_gate_se or lowest_gp leave out (`only`, `ev`: GpsThatTakePart).
Eigen::VectorXd OutputStack(const Eigen::MatrixXd& t, const std::vector<Eigen::MatrixXd>& err,
                            const ChoiceOptions& o, int k, int folds, int only,
                            const GpEvidence& ev) {
  const int nc = static_cast<int>(err.size());
  const bool large = t.cols() >= o.few_rows;
  const double gate = large ? o.stack_gate_se_large : o.stack_gate_se;
  const auto squared = [&](int c) -> Eigen::VectorXd {
    return err[c].row(k).array().square().matrix().transpose();
  };
  std::vector<int> in = {0};
  for (int c = 1; c < nc; ++c)
    if (gate <= 0 || BeatsFirst(squared(0), squared(c), gate, 0, folds)) in.push_back(c);
  in = GpsThatTakePart(in, err, o, k, only, ev);
  Eigen::MatrixXd p(t.cols(), static_cast<Eigen::Index>(in.size()));
  for (std::size_t j = 0; j < in.size(); ++j)
    p.col(static_cast<Eigen::Index>(j)) = (t.row(k) - err[in[j]].row(k)).transpose();
  const Eigen::VectorXd w =
      ShrunkStackWeights(p, t.row(k).transpose(), folds,
                         large ? o.stack_start_se_large : o.stack_start_se,
                         large ? o.stack_full_se_large : o.stack_full_se)
          .weights;
  Eigen::VectorXd out = Eigen::VectorXd::Zero(nc);
  for (std::size_t j = 0; j < in.size(); ++j) out(in[j]) = w(static_cast<Eigen::Index>(j));
  return out;
}

// Choice::sd_scale of the stacked outputs (and with stack_scale_single of those one candidate
// takes whole): StackSdScale of the output's held-out residuals sum_c w_c err_c (original units)
// against its sd at the training rows.
void ScaleStackedSd(const ProcessTable& table, const ChoiceOptions& options,
                    const std::array<Eigen::VectorXd, Features::kCount>& stack,
                    const std::vector<Eigen::MatrixXd>& err, Choice* choice) {
  const auto scaled = [&](int k) {
    return stack[k].size() > 0 || (options.stack && options.stack_scale_single);
  };
  if (!scaled(0) && !scaled(1)) return;
  const std::vector<FamilyPrediction> p = PredictChoice(*choice, table.inputs);
  for (int k = 0; k < Features::kCount; ++k) {
    if (!scaled(k)) continue;
    Eigen::VectorXd r = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(p.size()));
    if (stack[k].size() == 0) r = err[static_cast<std::size_t>(choice->chosen[k])].row(k).transpose();
    for (Eigen::Index c = 0; c < stack[k].size(); ++c)
      if (stack[k](c) > 0) r += stack[k](c) * err[static_cast<std::size_t>(c)].row(k).transpose();
    Eigen::VectorXd sd(r.size());
    for (std::size_t q = 0; q < p.size(); ++q)
      sd(static_cast<Eigen::Index>(q)) = std::max(p[q].stddev.ToArray()[k], 1e-300);
    choice->sd_scale[k] = StackSdScale(r, sd, options.stack_sd_two_share);
  }
}

// `fit` for the GP refits of ChooseFamily on a table of `rows` rows
// (ChoiceOptions::refit_hyperparameter_rows, refit_function_tolerance, refit_gradient_tolerance):
// the refits' optimizer tolerances, and hyperparameters from that subset of each refit's
// rows, from one start (single_start_rows lowered to the subset's size, so that the subset takes
// the optimizer settings of the whole table).
FitOptions RefitOptions(const ChoiceOptions& o, FitOptions fit, int rows) {
  gp::GpOptions& gp = fit.gp;
  if (rows < gp.single_start_rows || rows >= o.few_rows) return fit;
  for (BfgsOptions* b : {&gp.bfgs, &gp.bfgs_large}) {
    if (o.refit_function_tolerance > 0) b->function_tolerance = o.refit_function_tolerance;
    if (o.refit_gradient_tolerance > 0) b->gradient_tolerance = o.refit_gradient_tolerance;
  }
  const int subset = o.refit_hyperparameter_rows;
  if (subset <= 0) return fit;
  gp.hyperparameter_rows =
      gp.hyperparameter_rows > 0 ? std::min(gp.hyperparameter_rows, subset) : subset;
  gp.single_start_rows = std::min(gp.single_start_rows, gp.hyperparameter_rows);
  return fit;
}

// ChoiceOptions::refit_lowest_gp_rows applies to a table of `rows` rows.
bool RefitsLowestGpOnly(const ChoiceOptions& o, int rows) {
  return o.closed_form_loo && o.refit_lowest_gp_rows > 0 && rows >= o.refit_lowest_gp_rows &&
         rows < o.few_rows;
}

// ChoiceOptions::refit_lowest_gp_rows: per output k the GP candidate of `full` (fitted on all
// rows) with the lowest closed-form leave-one-out error in `err`, its row k of `err` replaced by
// the errors of refits on ChoiceOptions::refit_folds folds (0: `folds`); returns it per output
// (-1: no GP candidate).
std::array<int, Features::kCount> RefitLowestGp(const ProcessTable& table, const ChoiceOptions& o,
                                                int folds, const std::vector<FamilyModel>& full,
                                                std::vector<Eigen::MatrixXd>* err) {
  std::array<int, Features::kCount> only;
  only.fill(-1);
  FitOptions fo = o.fit;
  fo.threads = 1;
  // The refits take the optimizer settings of the whole table (one start from single_start_rows)
  // even where fewer folds leave fewer rows in a training split.
  if (static_cast<int>(table.inputs.size()) >= fo.gp.single_start_rows) fo.gp.single_start_rows = 0;
  fo.gp.bfgs.max_iterations = fo.gp.bfgs_large.max_iterations =
      o.refit_iterations > 0 ? o.refit_iterations : fo.gp.bfgs.max_iterations;
  for (int k = 0; k < Features::kCount; ++k)
    for (std::size_t c = 0; c < o.candidates.size(); ++c)
      if (o.candidates[c].family == Family::kGaussianProcess &&
          (only[k] < 0 || (*err)[c].row(k).squaredNorm() < (*err)[only[k]].row(k).squaredNorm()))
        only[k] = static_cast<int>(c);
  ParallelFor(Features::kCount, o.fit.threads, [&](std::size_t k) {
    const int c = only[k];
    if (c >= 0)
      (*err)[c].row(static_cast<Eigen::Index>(k)) =
          RefitErrors(full[c], table, fo, o.refit_folds > 0 ? o.refit_folds : folds,
                      static_cast<int>(k), o.refit_iterations <= 0);
  });
  return only;
}

// ChoiceOptions::gp_loo_hyperparameter_penalty: `err` with the rows of the GP candidates judged
// by their closed-form leave-one-out (not `refitted`) scaled; the other candidates' unchanged.
std::vector<Eigen::MatrixXd> JudgedErrors(const std::vector<Eigen::MatrixXd>& err,
                                          const std::vector<FamilyModel>& full,
                                          const std::vector<char>& refitted,
                                          const ChoiceOptions& o) {
  std::vector<Eigen::MatrixXd> out = err;
  if (o.gp_loo_hyperparameter_penalty <= 0) return out;
  for (std::size_t c = 0; c < err.size(); ++c) {
    if (o.candidates[c].family != Family::kGaussianProcess || refitted[c]) continue;
    for (std::size_t k = 0; k < full[c].gps.size(); ++k) {
      const gp::Gp& g = full[c].gps[k];
      const double n = g.rows.empty() ? static_cast<double>(err[c].cols())
                                      : static_cast<double>(g.rows.size());
      const double lengths =
          o.candidates[c].isotropic ? 1.0 : static_cast<double>(g.theta.size()) - 2;
      const double p = lengths + 2;  // and the signal and noise sd
      const double f = std::sqrt(1 + o.gp_loo_hyperparameter_penalty * p / n);
      const auto kk = static_cast<Eigen::Index>(k);
      if (g.rows.empty()) out[c].row(kk) *= f;
      for (int r : g.rows) out[c](kk, r) *= f;
    }
  }
  return out;
}

// Per candidate and output the GpLogEvidence of the GPs of `full` (kBic: minus (q / 2) ln n, q
// their hyperparameters and mean coefficients), -infinity for the other candidates.
GpEvidence GpEvidenceOf(const ChoiceOptions& o, const std::vector<FamilyModel>& full, GpSlot slot) {
  GpEvidence ev(full.size());
  for (std::size_t c = 0; c < full.size(); ++c)
    for (int k = 0; k < Features::kCount; ++k) {
      ev[c][k] = -std::numeric_limits<double>::infinity();
      if (o.candidates[c].family != Family::kGaussianProcess ||
          static_cast<std::size_t>(k) >= full[c].gps.size())
        continue;
      const gp::Gp& g = full[c].gps[static_cast<std::size_t>(k)];
      const int d = g.InputCount();
      const double q = FittedHyperparameters(o.candidates[c], d) + gp::MeanSize(g.mean, d);
      ev[c][k] = GpLogEvidence(full[c], k);
      if (slot == GpSlot::kBic)
        ev[c][k] -= 0.5 * q * std::log(static_cast<double>(g.u.size()));
    }
  return ev;
}

// ChoiceOptions::gp_slot_large on a table of `rows` rows: GpEvidence of the GP candidates of
// `full` (fitted on all rows from few_rows on); empty where the held-out errors give the slot
// (below few_rows, or kHeldOut).
GpEvidence SlotEvidence(const ChoiceOptions& o, const std::vector<FamilyModel>& full, int rows) {
  if (rows < o.few_rows || o.gp_slot_large == GpSlot::kHeldOut) return {};
  return GpEvidenceOf(o, full, o.gp_slot_large);
}

}  // namespace

Choice ChooseFamily(const ProcessTable& table, const ChoiceOptions& given) {
  CheckTable(table);
  if (given.candidates.empty()) throw InputError("family choice: no candidates");
  const int rows = static_cast<int>(table.inputs.size());
  const int folds = std::min(given.folds, rows);
  if (folds < 2)
    throw InputError("family choice: folds " + std::to_string(given.folds) + ": must be >= 2");
  TableTransform used;
  const std::vector<int> constant = LeaveOutConstantInputs(table, &used);
  std::string rows_note;
  const ChoiceOptions options =
      ActiveCandidates(given, rows, folds, used.UsedInputCount(), &rows_note);
  const int nc = static_cast<int>(options.candidates.size());
  std::vector<Eigen::MatrixXd> err(static_cast<std::size_t>(nc),
                                   Eigen::MatrixXd(Features::kCount, rows));
  std::vector<double> ms(static_cast<std::size_t>(nc * folds));
  FitOptions fold_options = options.fit;
  fold_options.threads = 1;
  const FitOptions refit_options = RefitOptions(options, fold_options, rows);
  for (const Candidate& c : options.candidates) CheckRows(table, c, used.UsedInputCount());
  std::vector<FamilyModel> full(static_cast<std::size_t>(nc));  // closed-form LOO fits
  std::vector<char> calibrated(static_cast<std::size_t>(nc), 0);
  // A GP judged by K-fold refits from fixed starting points needs no full fit for its held-out
  // errors: it is fitted on all rows (and calibrated from `held`) only once chosen (`complete`
  // below); at 20 rows most GPs are not, and their full fits took a sixth of the choice's time.
  std::vector<char> refitted(static_cast<std::size_t>(nc), 0), pending = refitted;
  std::vector<HeldOuts> held(static_cast<std::size_t>(nc));
  // A network's refits, kept as its calibration's fold fits (FitNetwork); emptied below unless
  // every fold's was kept.
  std::vector<std::vector<nn::Model>> fold_networks(static_cast<std::size_t>(nc));
  std::vector<char> fold_kept(static_cast<std::size_t>(nc * folds), 0);
  for (int c = 0; c < nc; ++c)
    if (options.candidates[c].family == Family::kNetwork)
      fold_networks[static_cast<std::size_t>(c)].resize(static_cast<std::size_t>(folds));
  std::mutex progress_mutex;
  int done = 0;
  int steps = 1;  // a network's folds, every other candidate's fit (with its held-out errors), the end
  for (const Candidate& c : options.candidates) steps += c.family == Family::kNetwork ? folds : 1;
  ParallelFor(static_cast<std::size_t>(nc * folds), options.fit.threads, [&](std::size_t i) {
    const auto start = std::chrono::steady_clock::now();
    const int c = static_cast<int>(i) / folds, f = static_cast<int>(i) % folds;
    if (options.candidates[c].family == Family::kNetwork) {
      fold_kept[i] = FoldErrors(table, options.candidates[c], fold_options, folds, f, &err[c],
                                &fold_networks[static_cast<std::size_t>(c)][f]);
    } else if (f == 0) {  // held-out errors (and calibration) of the full fit or of refits
      full[c] = Unfitted(table, options.candidates[c]);
      const bool refit_small = options.candidates[c].family == Family::kGaussianProcess &&
                               !RefitsLowestGpOnly(options, rows);
      const bool honest = options.closed_form_loo && refit_small && rows < options.few_rows &&
                          rows - (rows + folds - 1) / folds >=
                              MinimumRows(options.candidates[c], used.UsedInputCount());
      const int held_folds = honest ? folds : HeldOutFolds(options, folds);
      calibrated[c] = held_folds == CalibrationFolds(options.fit, rows, full[c]);
      refitted[c] = held_folds > 0;
      pending[c] = refitted[c] && options.candidates[c].family == Family::kGaussianProcess;
      if (!pending[c]) FitOwnColumns(table, fold_options, &full[c]);
      const bool calibrate_now = calibrated[c] && !pending[c];
      err[c] = HeldOutErrors(table, pending[c] ? refit_options : fold_options, held_folds,
                             &full[c], calibrate_now, true, &held[c]);
    }
    ms[i] =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (!options.progress || (f > 0 && options.candidates[c].family != Family::kNetwork)) return;
    const std::lock_guard<std::mutex> lock(progress_mutex);
    options.progress(++done, steps, options.candidates[c].Name());
  });
  std::array<int, Features::kCount> only;
  only.fill(-1);
  if (RefitsLowestGpOnly(options, rows)) only = RefitLowestGp(table, options, folds, full, &err);
  const std::vector<Eigen::MatrixXd> judged = JudgedErrors(err, full, refitted, options);
  const Eigen::MatrixXd t = nn::TargetMatrix(table.targets);
  // An output whose targets are all equal has nothing to choose on: it stays out of the score
  // (its MSE over a zero variance would only be a huge number; TableWarnings names it).
  Eigen::ArrayXd weight = ((t.colwise() - t.rowwise().mean()).rowwise().squaredNorm() / rows)
                              .array().max(1e-300).inverse();
  for (int k : ConstantTargets(table)) weight(k) = 0;
  Choice choice;
  for (int c = 0; c < nc; ++c) {
    CvRow r;
    r.candidate = options.candidates[c];
    const Eigen::ArrayXd mse = judged[c].array().square().rowwise().mean();
    r.cv_rmse = mse.sqrt().matrix();
    r.score = (mse * weight).sum();
    for (int f = 0; f < folds; ++f) r.fit_ms += ms[c * folds + f];
    choice.table.push_back(r);
    for (int k = 0; k < Features::kCount; ++k) {
      const CvRow& best = choice.table[choice.chosen[k]];
      if (options.per_output ? r.cv_rmse(k) < best.cv_rmse(k) : r.score < best.score)
        choice.chosen[k] = c;
    }
  }
  const auto complete = [&](int c) {  // the full fit of a pending GP, calibrated as above
    if (!pending[c]) return;
    const auto start = std::chrono::steady_clock::now();
    FitOwnColumns(table, fold_options, &full[c]);
    if (calibrated[c]) CalibrateFrom(table, fold_options, folds, held[c], &full[c]);
    pending[c] = 0;
    choice.table[c].fit_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  };
  const GpEvidence ev = SlotEvidence(options, full, rows);
  std::array<Eigen::VectorXd, Features::kCount> stack;
  for (int k = 0; k < Features::kCount && options.per_output; ++k) {
    if (options.stack) {
      stack[k] = OutputStack(t, judged, options, k, folds, only[k], ev);
      Eigen::Index top = 0;
      stack[k].maxCoeff(&top);
      choice.chosen[k] = static_cast<int>(top);
      if ((stack[k].array() > 0).count() == 1) stack[k].resize(0);  // one candidate: no stack
    } else {
      std::vector<int> all(static_cast<std::size_t>(nc)), linear;
      for (int c = 0; c < nc; ++c) {
        all[c] = c;
        if (options.candidates[c].family == Family::kLinear) linear.push_back(c);
      }
      choice.chosen[k] = ChooseAmong(all, judged, options, k, only[k], ev);
      if (linear.empty()) continue;
      const int lin = ChooseAmong(linear, judged, options, k), c = choice.chosen[k];
      complete(c);
      choice.notes[k] =
          WhySetAside(table, options, full, c, lin, k, refitted[c] ? &err[c] : nullptr);
      if (!choice.notes[k].empty()) choice.chosen[k] = lin;
    }
  }
  for (int k = 0; k < Features::kCount; ++k) {
    complete(choice.chosen[k]);
    for (Eigen::Index c = 0; c < stack[k].size(); ++c)
      if (stack[k](c) > 0) complete(static_cast<int>(c));
  }
  for (int c = 0; c < nc; ++c)
    for (int f = 0; f < folds; ++f)
      if (!fold_kept[static_cast<std::size_t>(c * folds + f)])
        fold_networks[static_cast<std::size_t>(c)].clear();
  FitChosen(table, options, stack, full, calibrated, fold_networks, &choice);
  ScaleStackedSd(table, options, stack, err, &choice);
  if (options.progress) options.progress(steps, steps, "final fits and sd calibration");
  choice.warnings = TableWarnings(table, options, constant);
  choice.rows_note = rows_note;
  return choice;
}

std::vector<FamilyPrediction> PredictChoice(const Choice& choice,
                                            const std::vector<ProcessInputs>& inputs) {
  std::vector<std::vector<FamilyPrediction>> per_model;
  for (const FamilyModel& m : choice.models) per_model.push_back(PredictFamily(m, inputs));
  std::vector<FamilyPrediction> out(inputs.size());
  for (std::size_t q = 0; q < inputs.size(); ++q) {
    std::array<double, Features::kCount> mean{}, sd{};
    for (int k = 0; k < Features::kCount; ++k) {
      if (choice.weights[k].empty()) {
        const FamilyPrediction& p = per_model[choice.model_of_output[k]][q];
        mean[k] = p.mean.ToArray()[k];
        sd[k] = choice.sd_scale[k] * p.stddev.ToArray()[k];
        continue;
      }
      for (std::size_t j = 0; j < per_model.size(); ++j) {
        const double w = choice.weights[k][j];
        mean[k] += w * per_model[j][q].mean.ToArray()[k];
        sd[k] += w * per_model[j][q].stddev.ToArray()[k];
      }
      sd[k] *= choice.sd_scale[k];
    }
    out[q] = {Features::FromArray(mean), Features::FromArray(sd)};
  }
  return out;
}

std::string Choice::Describe() const {
  std::string s;
  for (int k = 0; k < Features::kCount; ++k) {
    s += (k ? ", " : "") + std::string(kTargetColumns[k]) + ": ";
    if (weights[k].empty()) {
      const bool fitted = static_cast<std::size_t>(model_of_output[k]) < models.size();
      s += fitted ? models[model_of_output[k]].OutputName(k) : table.at(chosen[k]).candidate.Name();
      continue;
    }
    std::string terms;
    const bool whole = std::count_if(weights[k].begin(), weights[k].end(),
                                     [](double w) { return w > 0; }) == 1;
    for (std::size_t j = 0; j < weights[k].size() && j < models.size(); ++j)
      if (weights[k][j] > 0)  // one candidate with all the weight: its name alone
        terms += (terms.empty() ? "" : " + ") +
                 (whole ? "" : FormatFixed(weights[k][j], 2) + " ") + models[j].OutputName(k);
    s += terms;
  }
  return s;
}

}  // namespace whirl::family
