#pragma once
// The workpiece model as one of several families, chosen from the data by held-out error: least
// squares (on log columns a power law), the Gaussian process of gp/ and the trainbr network of
// nn/ (a fixed hidden size, or its evidence choice among sizes), each on identity or log columns
// (family/transform.h).
//
// Choice (ChooseFamily), per output by default: every candidate's held-out predictions of every
// row (ChoiceOptions::closed_form_loo: closed-form leave-one-out for linear fits, K-fold refits
// for GPs below ChoiceOptions::few_rows rows and for networks, row q held out in fold q % K,
// K = min(folds, rows), nothing fitted on the held-out rows), their squared errors, and
//   score = sum over outputs k of mean_i (t_ik - mean_-i,k)^2 / var_k,
// var_k = the population variance of output k over the whole table (both outputs weigh equally,
// as in the network's normalized errors). Per output, in three steps: a candidate after the first
// (the power law in the default list) takes part only if its squared held-out errors beat the
// first's by more than ChoiceOptions::leave_first_se standard errors of the paired differences
// (leave_first_se_large from ChoiceOptions::few_rows rows; BeatsFirst); of the GPs only the one
// with the lowest held-out error takes part (ChoiceOptions::lowest_gp; from few_rows rows the one
// of highest BIC of its marginal likelihood, ChoiceOptions::gp_slot_large); of those, the simplest
// within one standard error of the lowest error (ChoiceOptions::one_standard_error) is refitted
// on all rows with its noise calibration and returned with the table of held-out errors. Within the network family
// the hidden size may still be chosen by the evidence (MacKay 1992: comparable only within one
// family); across families only held-out errors are compared. How the default was chosen, on a
// benchmark of generator families split into a tuning and a confirmation part before tuning:
// docs/workpiece-model.md.
//
// Predictive sd, per output, in the candidate's transformed space, then mapped back by the delta
// method (family/transform.h):
//   linear:  sqrt(latent variance + s_k^2), s_k^2 by CoverageNoiseVariance from K-fold or the
//            exact closed-form leave-one-out residuals (family/linear.h);
//   network: nn::Predict (noise calibrated by nn's K-fold cross-validation, nn/model.h);
//   gp:      sqrt(latent variance + s_k^2), s_k^2 = the smallest level at which +-1 sd covers
//            68.27 % of cross-validated residuals (FitOptions::calibration_folds: K-fold
//            refits, or the closed-form leave-one-out of gp/gp.h with its latent variances;
//            CoverageNoiseVariance below): the network's rule (nn/model.h);
//   linear and gp, by default also: at least the level at which the closed-form leave-one-out
//            residuals are covered 68.27 % at +-1 sd and 95.45 % at +-2 sd
//            (FitOptions::calibrate_two_sd).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/process.h"
#include "family/linear.h"
#include "family/transform.h"
#include "gp/gp.h"
#include "nn/model.h"

namespace whirl::family {

enum class Family { kLinear, kNetwork, kGaussianProcess };

/// One candidate model. Name() (and ParseCandidate) spell it as
///   "linear/log" (least squares; on log columns a power law), "network-evidence/log",
///   "network-h6/identity", "gp-matern52-constant/log", "gp-se-linear/identity",
///   "gp-se-iso-constant/identity" (isotropic kernel).
struct Candidate {
  Family family = Family::kGaussianProcess;
  bool log = false;  ///< LogWherePositive of the table, else identity
  /// Network: hidden neurons (0 = linear 5-2 network), or kHiddenByEvidence for the highest log
  /// evidence among nn::DefaultTrainingOptions' sizes {0, 4, 6, 8}.
  int hidden = kHiddenByEvidence;
  gp::Kernel kernel = gp::Kernel::kMatern52;  ///< GP only
  gp::Mean mean = gp::Mean::kConstant;        ///< GP only
  bool isotropic = false;  ///< GP only: one length scale (gp::GpOptions::isotropic), "-iso"
  static constexpr int kHiddenByEvidence = -1;
  std::string Name() const;
};
/// Inverse of Candidate::Name(); InputError listing the accepted spellings otherwise.
Candidate ParseCandidate(const std::string& name);

/// How candidates are fitted.
struct FitOptions {
  std::uint64_t seed = 1;  ///< networks: restart r initializes with seed + r (nn/model.h)
  int network_restarts = 1;
  int network_noise_folds = 5;  ///< nn::ModelTrainOptions::noise_folds of the final network
  gp::GpOptions gp;             ///< the GP's options (kernel and mean come from the candidate)
  /// Noise calibration of linear and GP candidates: 0 = closed-form leave-one-out (for a GP at
  /// the full fit's hyperparameters); K > 0 = K-fold cross-validation (min(K, rows) folds, row
  /// q held out in fold q % K; a GP's hyperparameters refitted from the fixed starting points of
  /// gp::GpOptions, so that none has seen the held-out rows), the held-out residuals and latent
  /// variances in CoverageNoiseVariance (the network's rule, nn/model.h). K-fold is used only
  /// where every training split keeps MinimumRows rows (else leave-one-out: 8 and 9 rows for a
  /// linear fit in 5 inputs) and below loo_calibration_rows; a GP on a subset of the rows
  /// (gp::GpOptions::max_rows) is calibrated by the residuals of the rows it does not keep and
  /// the leave-one-out of those it keeps. Why K-fold at few rows: leave-one-out residuals come
  /// from fits on n - 1 rows and undercovered the simulator's hold-out tables
  /// (scripts/bench_peers.sh, 20 rows).
  int calibration_folds = 5;
  /// true: the noise level is at least the one at which the closed-form leave-one-out residuals
  /// (and their latent variances) are covered 68.27 % at +-1 sd and 95.45 % at +-2 sd
  /// (CoverageNoiseVariance with two_sd), besides the +-1 sd level of calibration_folds; false:
  /// the +-1 sd level alone. Why: a +-2 sd band is read as a 95 % interval, and with the +-1 sd
  /// rule alone it covered too few hold-out rows at +-2 sd on 20-row tables (residuals with
  /// heavier tails than a normal's). Why the leave-one-out residuals for the tail: at 20 rows
  /// 95.45 % means every row, and the K-fold refits (16 rows) have occasional bad folds that a
  /// maximum follows, which made +-1 sd far too wide (figures: docs/workpiece-history.md).
  bool calibrate_two_sd = true;
  /// From this many rows on, linear and GP candidates are calibrated by the closed-form
  /// leave-one-out alone (calibration_folds is used below it); 0 = never. At 70 rows and more
  /// the leave-one-out residuals of a GP are close to those of refits (10 rows per
  /// hyperparameter), and the refits cost a third of the fit time at 100 rows.
  int loo_calibration_rows = 70;
  int threads = 1;  ///< core/parallel.h; the result is the same for any count
};

/// A fitted candidate: the network (Family::kNetwork, in the transformed space), one least-squares
/// fit per output (Family::kLinear) or one GP per output (Family::kGaussianProcess), x and y in
/// the transformed space.
struct FamilyModel {
  Candidate candidate;
  TableTransform transform;
  nn::Model network;
  std::vector<gp::Gp> gps;
  std::vector<LinearModel> linears;
  std::string calibration;  ///< how the predictive sd was calibrated (provenance)
  /// Name() of the candidate for output k, saying when a log candidate keeps the output on its raw
  /// scale: "linear/log-inputs" (the log of the inputs only, LogExceptions).
  std::string OutputName(int k) const;
};

/// Fewest rows `c` can be fitted and judged on with `inputs` used inputs: a linear fit its
/// 1 + inputs coefficients and 2 more (a residual degree of freedom after the leave-one-out), a
/// GP its mean's coefficients and 2 more, a network 4.
int MinimumRows(const Candidate& c, int inputs);

/// Fits `candidate` on all rows of `table` (targets required, at least MinimumRows rows; the
/// InputError counts the table's rows); `calibrate` = false skips the noise calibration (the
/// cross-validation folds need only means). InputError on bad tables.
FamilyModel FitCandidate(const ProcessTable& table, const Candidate& candidate,
                         const FitOptions& options, bool calibrate = true);

struct FamilyPrediction {
  Features mean;    ///< original units (delta method: for a log output, the median)
  Features stddev;  ///< predictive sd (noise included), original units
};
std::vector<FamilyPrediction> PredictFamily(const FamilyModel& model,
                                            const std::vector<ProcessInputs>& inputs);

/// Noise calibration of a linear or GP candidate fitted on `table` (see the header comment).
void Calibrate(const ProcessTable& table, const FitOptions& options, FamilyModel* m);
/// Squared closed-form leave-one-out errors (2 x rows, original units: t_ik - g^-1(z_ik - r_ik)
/// with r the residual in the transformed space) of a linear or GP candidate fitted on `table`;
/// InputError for a network.
Eigen::MatrixXd LeaveOneOutSquaredErrors(const FamilyModel& m, const ProcessTable& table);

/// sigma^2 >= 0: the smallest level at which sqrt(sigma^2 + latent_variance[i]) >= |r_i| for at
/// least 68.27 % of the residuals (bisection; the coverage is monotone in sigma^2). The rule of
/// nn::CalibrateOutputNoise (nn/model.h). InputError if the sizes differ or are 0.
/// two_sd = true: the smallest level at which, in addition, sqrt(sigma^2 + latent_variance[i])
/// >= |r_i| / 2 for at least 95.45 % of the residuals (both shares of a normal distribution).
double CoverageNoiseVariance(const Eigen::VectorXd& residual,
                             const Eigen::VectorXd& latent_variance, bool two_sd = false);

/// Stacking weights (Breiman, "Stacked regressions", Machine Learning 24, 1996): the w >= 0 with
/// sum w = 1 that minimizes ||target - predictions w||^2, predictions (rows x candidates) being
/// the candidates' held-out predictions of target (rows). Exact: every support set is solved by
/// its equality-constrained least squares (KKT system) and the best feasible one is kept (up
/// to 12 candidates); ties go to the smaller support, then the earlier set. InputError if the
/// sizes disagree, there are no rows, or there are more than 12 candidates.
Eigen::VectorXd ConvexStackWeights(const Eigen::MatrixXd& predictions,
                                   const Eigen::VectorXd& target);

/// ChoiceOptions::stack for one output: the stacking weights shrunk toward the first candidate
/// (the power law by default), w = (1 - a) e_1 + a w*, w* = ConvexStackWeights(predictions,
/// target). The share a is 0 while the stack's nested held-out squared errors beat the first
/// candidate's by at most start_se standard errors of the paired differences, 1 from full_se on,
/// linear between (full_se <= start_se: a step at start_se). Nested: row q's stacked prediction
/// takes the weights fitted without the rows of its fold (row q in fold q % folds, folds =
/// min(folds, rows)), so that no row judges weights it helped to fit. InputError as
/// ConvexStackWeights, or if folds < 2.
struct ShrunkStack {
  Eigen::VectorXd weights;  ///< >= 0, sum 1
  double z = 0;             ///< the stack's lead over the first candidate, in standard errors
  double share = 0;         ///< a
};
ShrunkStack ShrunkStackWeights(const Eigen::MatrixXd& predictions, const Eigen::VectorXd& target,
                               int folds, double start_se, double full_se);

/// kappa > 0: the smallest factor at which kappa sd_i >= |r_i| for at least 68.27 % of the rows
/// and 2 kappa sd_i >= |r_i| for at least 95.45 % (the rule of CoverageNoiseVariance with
/// two_sd, as a factor on a given sd), clamped to [0.25, 4]. InputError if the sizes differ or
/// are 0, or an sd is not > 0.
double CoverageScale(const Eigen::VectorXd& residual, const Eigen::VectorXd& sd,
                     bool two_sd = true);

/// Choice::sd_scale of a stacked output: min(1, max(q1, q2 / 2)), q1 the smallest factor at
/// which kappa sd_i >= |r_i| for at least 68.27 % of the rows, q2 the smallest at which
/// kappa sd_i >= |r_i| for at least `two_share` of them (two_share = 0: q1 alone), clamped to
/// [0.25, 1]. The sd is only ever narrowed: the candidates' own sd is calibrated already, and
/// a combination errs less than its parts. InputError as CoverageScale, or if two_share is
/// outside [0, 1].
double StackSdScale(const Eigen::VectorXd& residual, const Eigen::VectorXd& sd, double two_share);

/// ChoiceOptions::one_standard_error for one output: squared_errors[c] holds candidate c's
/// squared held-out errors per row (candidates from the simplest); returns the first c with
/// mean(d) <= sd(d) / sqrt(n), d = squared_errors[c] - squared_errors[b], b the lowest mean,
/// whose mean is not above that of a simpler candidate (a candidate worse than a simpler one is
/// never preferred to it, even when its differences to b are noisier). InputError without
/// candidates.
int SimplestWithinOneStandardError(const std::vector<Eigen::VectorXd>& squared_errors);

/// ChoiceOptions::leave_first_se and leave_first_blocks: whether a candidate with squared held-out
/// errors `other` (per row) beats the first candidate (`first`) clearly: d = first - other has a
/// positive mean above z standard errors (sd(d) / sqrt(n)), and the rows split into `blocks`
/// blocks (row q in block q % blocks, the folds of the choice) give d a positive sum in at least
/// min(wins, blocks) of them. InputError if the sizes differ or are 0, or blocks < 1.
bool BeatsFirst(const Eigen::VectorXd& first, const Eigen::VectorXd& other, double z, int wins,
                int blocks, double row_share = 0);

/// How far apart two fits of output k are on the training rows, in sd of the output: the RMS over
/// the rows of table of (mean_a - mean_b) in the transformed space, divided by the population sd
/// of the transformed output (0 for a constant output). Both models must share their transform
/// (InputError naming both otherwise). ChoiceOptions::equivalence_sd uses it.
double FitDifferenceInSd(const FamilyModel& a, const FamilyModel& b, const ProcessTable& table,
                         int k);

/// Hyperparameters a GP candidate fits by maximum likelihood on `inputs` input columns: one
/// length scale per input (one if isotropic), the signal sd and the noise sd; 0 for other
/// families.
int FittedHyperparameters(const Candidate& c, int inputs = ProcessInputs::kCount);

/// ln p(y) of output k's GP in `m` at its fitted hyperparameters, as a density of the output in
/// its original units (the log marginal likelihood made comparable between a GP of ln y and a
/// GP of y): gp::LogMarginalLikelihood (of the standardized targets u) - n ln s - [log output]
/// sum_i ln y_i, n the GP's rows, s its target_scale (u = (z - shift) / s, z = ln y or y), and
/// ln y_i = shift + s u_i; the last sum is the Jacobian of the log transform. InputError if `m`
/// holds no GP for output k.
double GpLogEvidence(const FamilyModel& m, int k);

/// ChoiceOptions::gp_slot_large: how the one GP slot of lowest_gp is given from few_rows rows.
enum class GpSlot {
  kHeldOut,   ///< the GP of lowest held-out error (the default before the twelfth attempt)
  kEvidence,  ///< the GP of highest GpLogEvidence
  kBic,       ///< the GP of highest GpLogEvidence - (q / 2) ln n, q = its hyperparameters +
              ///< mean coefficients (Schwarz's BIC); the default
};

/// One row of the choice table./// One row of the choice table.
struct CvRow {
  Candidate candidate;
  Eigen::VectorXd cv_rmse;  ///< per output, original units
  double score = 0;         ///< see the header comment (dimensionless)
  double fit_ms = 0;        ///< wall time of the candidate's fold fits
};
void to_json(nlohmann::json& j, const CvRow& r);

struct ChoiceOptions {
  std::vector<Candidate> candidates = DefaultCandidates();
  int folds = 5;  ///< K of the cross-validation (min(K, rows))
  /// true: each output takes the candidate with the lowest cross-validated error of that output
  /// (mean_i (t_ik - mean_-i,k)^2; ties: the earlier candidate), so the two outputs may come
  /// from different families; false: one candidate for both, by the summed score.
  bool per_output = true;
  /// true: the one-standard-error rule (Breiman, Friedman, Olshen & Stone, "Classification and
  /// Regression Trees", 1984, section 3.4.3; Hastie, Tibshirani & Friedman, "The Elements of
  /// Statistical Learning", section 7.10), with `candidates` listed from the simplest: per
  /// output the first candidate c whose CV error exceeds the lowest one (candidate b) by at most
  /// one standard error of the paired differences, mean_i(d_i) <= sd(d) / sqrt(n) with
  /// d_i = e_ci^2 - e_bi^2 (squared held-out errors of row i). Why: at 20 rows the CV errors
  /// of several candidates differ by less than their noise, and the lowest of them is biased
  /// low (scripts/bench_peers.sh, simulator tables: the power law lost to a GP chosen by CV).
  /// Applies to per_output choices.
  bool one_standard_error = true;
  /// Held-out errors of linear and GP candidates, each fitted once on all rows:
  ///   true (default): linear candidates by their closed-form leave-one-out (family/linear.h,
  ///     exact); GP candidates below few_rows by K-fold refits whose hyperparameters are
  ///     refitted from gp::GpOptions' fixed starting points (none has seen the held-out rows),
  ///     from few_rows on by their closed-form leave-one-out (gp/gp.h, exact for the full fit's
  ///     hyperparameters, which have seen the held-out row);
  ///   false: K-fold refits for both (a GP's hyperparameters refitted from the fixed starts).
  /// Networks are always refitted per fold (from their initialization).
  /// Why refits for GPs at few rows: a GP's closed-form leave-one-out error is exact only for
  /// hyperparameters fitted with the held-out row (Cawley & Talbot, "On over-fitting in model
  /// selection and subsequent selection bias in performance evaluation", JMLR 11, 2010); on the
  /// tuning part of scripts/bench_peers.sh (20 rows) the default took GPs that lost to the power
  /// law on power-law tables and the refits brought it to the power law's
  /// (docs/workpiece-history.md).
  bool closed_form_loo = true;
  /// Few rows for a GP: fewer than kRowsPerHyperparameter rows per hyperparameter of the ARD
  /// kernel on the five inputs (7: 70 rows; the rule of thumb of 10, Harrell, "Regression
  /// Modeling Strategies", 2nd ed., section 4.4). Below it GP held-out errors come from refits
  /// (closed_form_loo); a table whose refit splits hold fewer rows than a linear fit needs
  /// (5 inputs: 8 rows, so tables of 8 and 9 rows) leaves the GP candidates out, and
  /// Choice::rows_note says so.
  int few_rows = 70;
  static constexpr int kRowsPerHyperparameter = 10;
  /// A cheaper path for the GP refits of tables of at least refit_lowest_gp_rows rows (0: never)
  /// below few_rows: every GP is fitted on all rows and ranked per output by its closed-form
  /// leave-one-out, and only the lowest of them (the only GP that lowest_gp lets into the
  /// choice) is judged by K-fold refits; the other GPs take no part in output k's choice.
  /// refit_iterations > 0: those refits start at the full fit's hyperparameters and stop after
  /// at most this many optimizer iterations (0: from GpOptions' fixed starting points, run to
  /// convergence); refit_folds > 0: that many folds for them (0: `folds`). Opt-in: with
  /// few_rows 101 and 2 or 4 warm iterations it lowered the 100-row test RMSE on the tuning part
  /// within the speed budget, and not on the confirmation part (docs/workpiece-history.md, "Eighth
  /// attempt"); refitting every GP from the fixed starts costs three times the budget.
  int refit_lowest_gp_rows = 0;
  int refit_iterations = 0;
  int refit_folds = 0;
  /// Subset of data for the hyperparameters of the GP refits (R&W section 8.3.2) on tables of
  /// at least fit.gp.single_start_rows rows below few_rows (0: GpOptions' own
  /// hyperparameter_rows; not the refits of refit_lowest_gp_rows): each K-fold refit that judges
  /// a GP takes its hyperparameters from at most this many of its rows
  /// (GpOptions::hyperparameter_rows, spread evenly) from one start, and its held-out
  /// predictions from all of them; the GP fitted on the whole table (once chosen) keeps
  /// GpOptions' settings. Opt-in: with few_rows 101, meant to pay for judging every
  /// GP at 100 rows by K-fold refits, it made the 100-row test RMSE worse on the tuning part at
  /// every subset within the time budget (docs/workpiece-history.md, "Ninth attempt").
  int refit_hyperparameter_rows = 0;
  /// The optimizer's tolerances for those refits (0: GpOptions' own; BfgsOptions'
  /// function_tolerance and gradient_tolerance, on the same tables as refit_hyperparameter_rows).
  /// Opt-in for the same reason (the same section).
  double refit_function_tolerance = 0, refit_gradient_tolerance = 0;
  /// Network candidates sit out of tables with more rows than this (0: never), and
  /// Choice::rows_note says so: their fold refits, final fit and noise folds grow with the rows
  /// (trainbr) and the default's fit time must stay within R brnn's (docs/workpiece-model.md,
  /// "Speed").
  int network_max_rows = 500;
  /// true: per output a convex combination of the candidates (ConvexStackWeights of their
  /// held-out predictions, original units) instead of one candidate; the one-standard-error rule
  /// is then not applied. Each candidate with a positive weight is refitted and calibrated on its
  /// own; the combination's sd is sum_c w_c sd_c (the sd of sum_c w_c e_c when the candidates'
  /// errors e_c are fully correlated, and an upper bound for any correlation, Minkowski: the
  /// noise of a new row, most of each sd, is common to every candidate) times Choice::sd_scale,
  /// the CoverageScale of the combination's held-out residuals. (sqrt(sum_c w_c sd_c^2), the
  /// looser bound of earlier versions, covered too many of the tuning part's test rows at +-1 sd
  /// on bent and stepped power laws; docs/workpiece-history.md.)
  /// The candidates that enter: the first, those that beat it by more than stack_gate_se
  /// standard errors (BeatsFirst), and of the GPs with lowest_gp only the lowest; the weights are
  /// shrunk toward the first (ShrunkStackWeights, stack_start_se / stack_full_se).
  /// The default since the fifth attempt (docs/workpiece-history.md, "Fifth attempt": on fresh
  /// seeds its test RMSE was lower than the hard choice's with fewer coverage cells outside the
  /// bands). false: the hard choice (one candidate per output by the one-standard-error rule and
  /// leave_first_se; `whirl train --choice hard`), the default before.
  bool stack = true;
  /// ChoiceOptions::stack shrunk toward the first candidate (ShrunkStackWeights): the stack
  /// gets no weight while its nested held-out errors beat the first's by at most stack_start_se
  /// standard errors, all of it from stack_full_se on (the _large pair from few_rows rows, where
  /// GPs are judged by their closed-form leave-one-out); stack_full_se < 0: the unshrunk stack.
  /// (0.5 and 1.5 with lowest_gp_per_scale met the rule on the seventh attempt's tuning part and
  /// not on its confirmation part: docs/workpiece-history.md, "Seventh attempt".)
  double stack_start_se = 1.0, stack_full_se = 2.0;
  double stack_start_se_large = 1.5, stack_full_se_large = 2.5;
  /// ChoiceOptions::stack: a candidate after the first enters the combination only if its own
  /// squared held-out errors beat the first's by more than stack_gate_se standard errors
  /// (stack_gate_se_large from few_rows rows; BeatsFirst, no blocks); 0: every candidate enters.
  double stack_gate_se = 1.0, stack_gate_se_large = 1.5;
  /// The held-out errors of each GP candidate judged by its closed-form leave-one-out (from
  /// few_rows rows), as the choice sees them (Choice::table, the stack's gate, weights and
  /// shrinkage, the hard choice), times sqrt(1 + gp_loo_hyperparameter_penalty p / n): p the GP's
  /// fitted hyperparameters (d length scales, or 1 if isotropic, plus the signal and noise sd),
  /// n the rows of its leave-one-out; 0: unscaled. The calibration and the stack's sd scale keep
  /// the unscaled errors. Why: that leave-one-out is exact for fixed hyperparameters, and these
  /// were fitted with the held-out row (Cawley & Talbot, JMLR 11, 2010); 2 is the in-sample
  /// optimism of p maximum-likelihood parameters, 2 sigma^2 p / n (Mallows' Cp, Akaike's AIC;
  /// Efron, "The estimation of prediction error: covariance penalties and cross-validation",
  /// JASA 2004), with sigma^2 about the leave-one-out MSE. Opt-in (docs/workpiece-history.md,
  /// "Tenth attempt").
  double gp_loo_hyperparameter_penalty = 0;
  /// ChoiceOptions::stack: true: an output that one candidate takes whole (Choice::weights
  /// empty) gets a Choice::sd_scale too, from that candidate's held-out residuals, as a
  /// combination's; false: its own sd, unscaled.
  /// ChoiceOptions::stack: the +-2 sd share of the held-out residuals that Choice::sd_scale must
  /// keep covered (StackSdScale); 0: the +-1 sd share alone.
  /// Why both (the sixth attempt, figures in docs/workpiece-history.md): each candidate's own
  /// calibration covers every held-out residual of a 20-row table at +-2 sd, and with
  /// heavy-tailed residuals its +-1 sd then covered more new rows than the 60-76 % band;
  /// narrowing the sd to the held-out +-1 sd share alone let +-2 sd fall below 90 %; keeping 95 %
  /// of the residuals (19 of 20) within +-2 sd holds both.
  bool stack_scale_single = true;
  double stack_sd_two_share = 0.95;
  /// Leaving the first candidate (the power law, by default): per output, a later candidate
  /// takes part in the choice only if its squared held-out errors beat the first's by more than
  /// leave_first_se standard errors of the paired differences (leave_first_se_large from
  /// few_rows rows on, where GPs are judged by their closed-form leave-one-out) and in at least
  /// leave_first_blocks of the `folds` blocks of rows (BeatsFirst); 0 and 0: every candidate
  /// takes part (the one-standard-error rule alone).
  /// Defaults (2 and 2.5, no blocks) chosen on the third attempt's tuning part of
  /// scripts/bench_peers.py: with 0 (the one-standard-error rule alone) a GP or the raw linear
  /// fit won the held-out comparison on power-law tables and lost on new rows; the larger margin from few_rows on answers the optimism of a GP's
  /// closed-form leave-one-out, whose hyperparameters have seen the held-out row
  /// (docs/workpiece-history.md, "Third attempt").
  double leave_first_se = 2.0;
  double leave_first_se_large = 2.5;
  int leave_first_blocks = 0;
  double leave_first_row_share = 0;
  /// true: per output only the GP candidate with the lowest held-out error takes part in the
  /// one-standard-error rule (in its place in the list); the others are left out. Why: the GPs
  /// differ in how they bend, not in a count of coefficients that orders them by simplicity.
  bool lowest_gp = true;
  /// With lowest_gp, below few_rows rows (where GPs are judged by refits): the lowest GP per
  /// column scale (one on log columns, one on raw columns) takes part instead of the lowest of
  /// all, and the stacking weights choose between them. From few_rows rows on (closed-form
  /// leave-one-out) the lowest of all, as without it. Opt-in: not the default
  /// (docs/workpiece-history.md, "Seventh attempt": on the tuning part alone it lowered the 20-row
  /// test RMSE, and with the shrinkage 0.5-1.5 did not hold on the confirmation part).
  bool lowest_gp_per_scale = false;
  /// The same per-scale rule from few_rows rows on (GPs judged by their closed-form
  /// leave-one-out); below few_rows lowest_gp_per_scale alone decides. Why: at 100 rows the
  /// log-column GP, whose leave-one-out is the most optimistic of the GPs, took the one slot on
  /// tables where the raw-column GP alone predicted better (docs/workpiece-history.md, "Tenth
  /// attempt: diagnosis"). Opt-in (the same document, "Eleventh attempt").
  bool lowest_gp_per_scale_large = false;
  /// With lowest_gp, from few_rows rows (GPs judged by their closed-form leave-one-out): which
  /// GP takes the one slot per output (GpSlot; kHeldOut: the lowest held-out error, as below
  /// few_rows). kEvidence and kBic rank every GP candidate by GpLogEvidence (kBic: minus
  /// (q / 2) ln n) and keep the highest; it still has to pass the gate (stack_gate_se_large,
  /// leave_first_se_large) to enter (if it does not and every candidate that did is a GP, the
  /// first candidate takes part alone); it overrides lowest_gp_per_scale_large. Why: the GPs'
  /// closed-form leave-one-out is optimistic, most for the log-column GP, which took the slot on
  /// tables where a raw-column GP predicted better; the marginal likelihood does not use the
  /// leave-one-out. kBic met the rule on a tuning and a confirmation part; kEvidence, which
  /// does not count the power-law mean's five extra maximized coefficients, gave the slot to
  /// the log-column GP still more often and lost (docs/workpiece-history.md, "Twelfth attempt").
  GpSlot gp_slot_large = GpSlot::kBic;
  /// Practical equivalence at few rows (per-output choices without `stack`; 0 disables it, the
  /// default since GP held-out errors at few rows come from refits, which it duplicates): if
  /// output k's choice is a GP fitted with fewer than kRowsPerHyperparameter rows per
  /// hyperparameter (FittedHyperparameters) that spends more degrees of freedom than the linear
  /// fit (gp::EffectiveDegreesOfFreedom above 1 + inputs) on a fit that differs from the linear
  /// candidate's on the same columns by less than equivalence_sd sd of the output
  /// (FitDifferenceInSd), the GP, refitted on `folds` folds from the fixed starting points, must
  /// beat the linear candidates' own choice by more than one standard error
  /// (SimplestWithinOneStandardError); else output k takes that linear candidate and
  /// Choice::notes says why. The refits need 8 rows in every training split.
  double equivalence_sd = 0;
  FitOptions fit;
  /// Called from the fitting threads (one at a time) after each candidate's fit or fold and after
  /// the final fits: `done` of `total` steps and what was just done. Empty: none.
  std::function<void(int done, int total, const std::string& step)> progress;
  /// From the simplest (ChoiceOptions::one_standard_error): linear/log (the power law),
  /// linear/identity, gp-matern52-linear/log (a GP whose mean is a power law: it is the power
  /// law when the data hold no more, R&W section 2.7), gp-matern52-constant/identity,
  /// gp-se-constant/identity (ARD: 7 hyperparameters; with lowest_gp only the GP with the lower
  /// held-out error takes part) and network-h2/identity (trainbr with 2 tanh units on the raw
  /// columns, R brnn's stopping rule: a logistic or saturating response in a direction of the
  /// inputs is one unit of it; up to network_max_rows rows). Why each, with the figures measured
  /// on the tuning parts of scripts/bench_peers.py: docs/workpiece-history.md (the power-law mean
  /// and the squared-exponential GP: "Third attempt"; the network: "Sixth attempt").
  static std::vector<Candidate> DefaultCandidates();
};

struct Choice {
  std::vector<CvRow> table;                    ///< in candidate order
  std::array<int, Features::kCount> chosen{};  ///< per output: index into table
  /// The chosen candidates refitted on all rows and calibrated: one per distinct candidate
  /// in `chosen` (output k is predicted by models[model_of_output[k]]).
  std::vector<FamilyModel> models;
  std::array<int, Features::kCount> model_of_output{};
  /// Stacked outputs (ChoiceOptions::stack): weights[k][j] = weight of models[j] in output k
  /// (>= 0, sum 1; model_of_output[k] and chosen[k] then name the largest weight); empty: output
  /// k is models[model_of_output[k]] alone (its sd times sd_scale[k]).
  std::array<std::vector<double>, Features::kCount> weights;
  /// Stacked outputs: the factor on the combination's sd sum_j w_j sd_j, StackSdScale of the
  /// combination's held-out residuals against that sd at the training rows (at most 1: the sum
  /// is an upper bound); with ChoiceOptions::stack_scale_single also the factor on a single
  /// candidate's sd (its own held-out residuals); 1 otherwise. Stored in the model file when a
  /// weight is or a factor is not 1.
  std::array<double, Features::kCount> sd_scale{1.0, 1.0};
  /// Per output, the GP that ChoiceOptions::equivalence_sd set aside and why; empty if none.
  /// Printed by `whirl train` (and in its --json), not stored in the model file.
  std::array<std::string, Features::kCount> notes;
  /// What the choice did about the table that the user should know: inputs left out because they
  /// are constant, columns a log candidate keeps on their raw scale (a value <= 0 or near zero,
  /// LogExceptions). Printed by `whirl train` as warnings (and in its --json), not stored.
  std::vector<std::string> warnings;
  /// Why some candidates sat out (ChoiceOptions::few_rows); empty if none did. Printed by
  /// `whirl train`, not stored.
  std::string rows_note;
  std::string Describe()
      const;  ///< "max_elongation_um: linear/log, settle_time_s: gp-se-constant/log"
};
/// The choice of the header comment. InputError if the table has no targets or fewer rows than a
/// candidate's MinimumRows (counting the table's rows), or if there are no candidates.
Choice ChooseFamily(const ProcessTable& table, const ChoiceOptions& options);
/// Output k from models[model_of_output[k]] (mean, and sd times sd_scale[k]), or for a stacked
/// output the weighted mean sum_j w_j mean_j and sd sd_scale[k] sum_j w_j sd_j
/// (ChoiceOptions::stack).
std::vector<FamilyPrediction> PredictChoice(const Choice& choice,
                                            const std::vector<ProcessInputs>& inputs);

// JSON (family_file.cpp), the part of the workpiece model file (workpiece/model.h) that holds a
// family choice. Doubles are written with round-trip precision, so a reloaded choice predicts
// bit-identically. from_json checks every key (names, sizes, finiteness, indices; a GP is
// refactorized) and throws InputError naming the key and the rule.
//   FamilyModel: {"candidate": Candidate::Name(), "transform", "calibration",
//                 "linears" | "gps" | "network": one fit per output (a network: nn/model.h)}
//   CvRow:       {"candidate", "cv_rmse" (per output, original units), "score"} (fit_ms is not
//                stored, so that the same table and seed give the same file byte for byte; files
//                of earlier versions that hold it load)
//   Choice:      {"describe": Describe(), "table": [CvRow], "chosen", "model_of_output",
//                 "models": [FamilyModel]}; the model of output k must be the candidate chosen
//                 for it.
void to_json(nlohmann::json& j, const FamilyModel& m);
void from_json(const nlohmann::json& j, FamilyModel& m);
void from_json(const nlohmann::json& j, CvRow& r);
void to_json(nlohmann::json& j, const Choice& c);
void from_json(const nlohmann::json& j, Choice& c);

}  // namespace whirl::family
