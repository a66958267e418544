#pragma once
// Temperature-sensitive points exactly as Miao, Gao, Dang and Miao, "Thermal error
// characteristics analysis of CNC machine tools" (Hefei University of Technology): fuzzy
// clustering of the sensors, the F statistic for the number of classes, and Deng's grey relational
// grade to pick one sensor per class. The paper's formulas did not survive in its text, so these
// are the project's conventions:
//
//  1. Rises: each run's temperatures minus its first row (Run::Rises); several runs are stacked
//     sample by sample (each relative to its own first row), so are their error series.
//  2. Similarity r_ij = |Pearson correlation| of the rise series of sensors i and j over all
//     samples; r_ii = 1; a constant sensor (zero variance) has r_ij = 0 for every j != i.
//  3. Fuzzy equivalence matrix: the transitive closure by repeated max-min squaring
//     R <- R o R, (A o B)_ij = max_k min(A_ik, B_kj), until R no longer changes (at most
//     ceil(log2 m) + 1 squarings). The result is reflexive, symmetric, max-min transitive and
//     idempotent (R o R = R).
//  4. Every distinct off-diagonal level lambda of R (descending) gives a partition, the lambda-cut:
//     i and j share a class iff R_ij >= lambda (an equivalence relation because R is one). The
//     cuts are nested: a lower lambda merges classes, never splits them.
//  5. F statistic of a partition into r classes, 1 < r < m (objects = the m sensors, features =
//     each sensor's z-scored rise series z_i, a vector over samples; a constant sensor's z is 0):
//        F = [sum_k n_k ||zbar_k - zbar||^2 / (r - 1)] / [sum_k sum_{i in k} ||z_i - zbar_k||^2
//            / (m - r)],
//     zbar_k the mean of class k's z_i, zbar the mean of all z_i. F = +inf when the denominator is
//     0 (every class is tight). Compared with the upper-alpha critical value of F(r - 1, m - r)
//     (Boost.Math fisher_f quantile at 1 - alpha). Partitions with r = 1 or r = m get no F.
//  6. Class count (SelectionOptions::rule): kFewestSignificant (the paper's choice, default): the
//     fewest classes whose F > F_crit; kLargestMargin: the largest (F - F_crit) / F_crit;
//     kFixed: the lambda-cut with exactly `fixed_classes` classes (InputError if none has it);
//     kCrossValidated: the class count whose chosen sensors predict the error best out of sample
//     (a static MLR, cross-validated over runs; decided by SelectSensorsForFit in drift/model.h,
//     which needs the regression; SelectSensors itself refuses this rule).
//     Only partitions with r <= max_classes (when > 0) are eligible. If no partition qualifies
//     (no F significant, or m < 3), the fallback is the eligible partition with the largest
//     margin, or, when there is none, every sensor is its own class (capped at max_classes by
//     grade); Selection::message says which.
//  7. Deng's grey relational grade (rho = 0.5) of each sensor's rise series x_i against the error
//     series x_0, each min-max normalized to [0, 1] over all samples (a constant series becomes 0):
//        d_i(k) = |x_0(k) - x_i(k)|, d_min = min_i min_k d_i(k), d_max = max_i max_k d_i(k),
//        xi_i(k) = (d_min + rho d_max) / (d_i(k) + rho d_max),  grade_i = mean_k xi_i(k)
//     (every grade is 1 when d_max = 0). In each class the sensor with the highest grade is
//     chosen (ties: the first in file order). Chosen sensors are listed in file order.
//  8. Before all this, on runs (and before a fit on given sensors, drift/model.h), sensors that
//     carry nothing of their own are left out, each named in a warning (ScreenSensors): a dead
//     sensor, whose rise is 0 in every sample of every run (a stuck or disconnected sensor, a
//     constant column), and a duplicate, whose rise series equals an earlier sensor's up to scale
//     and offset (|r| >= 1 - kDuplicateTolerance: the same sensor logged twice). Either would
//     make the regression rank-deficient. When no sensor is left, the runs are refused.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "drift/run_file.h"

namespace whirl::drift {

enum class ClassCountRule { kFewestSignificant, kLargestMargin, kFixed, kCrossValidated };
std::string ToString(ClassCountRule r);                    ///< "fewest", "margin", "fixed", "cv"
ClassCountRule ParseClassCountRule(const std::string& s);  ///< inverse; InputError otherwise

struct SelectionOptions {
  double alpha = 0.05;  ///< significance level of the F test, in (0, 1)
  ClassCountRule rule = ClassCountRule::kFewestSignificant;
  int fixed_classes = 0;  ///< class count for kFixed (>= 1)
  int max_classes = 0;    ///< at most this many classes (= chosen sensors); 0: no limit
  double rho = 0.5;       ///< distinguishing coefficient of the grey grade, in (0, 1]
  void Validate() const;  ///< InputError naming the option, its value and the rule
};

/// One lambda-cut of the fuzzy equivalence matrix.
struct Partition {
  double lambda = 0;        ///< the cut level
  std::vector<int> labels;  ///< class of each sensor, 0-based, numbered by first member
  int classes = 0;          ///< r
  bool has_f = false;       ///< 1 < r < m
  double f = 0;             ///< F statistic (convention 5)
  double f_critical = 0;    ///< F(r - 1, m - r) upper-alpha quantile
  bool significant() const { return has_f && f > f_critical; }
};

struct Selection {
  std::vector<std::string> sensor_names;  ///< every candidate, file order
  Eigen::MatrixXd similarity;             ///< r_ij (convention 2)
  Eigen::MatrixXd equivalence;            ///< transitive closure (convention 3)
  int squarings = 0;                      ///< max-min squarings until R stopped changing
  std::vector<Partition> partitions;      ///< one per distinct level, lambda descending
  int chosen_partition = -1;              ///< index into partitions; -1: every sensor a class
  Eigen::VectorXd grades;                 ///< grey relational grade per sensor (convention 7)
  std::vector<int> chosen;                ///< indices of the chosen sensors, file order
  std::string message;                    ///< how the class count was decided, with the numbers
  /// kCrossValidated: the cross-validated RMSE [um] of each candidate class count, ascending r.
  struct ClassCountScore {
    int classes = 0;
    double cv_rmse_um = 0;
  };
  std::vector<ClassCountScore> class_count_scores;
  /// Sensors left out before the selection (convention 8), one line each naming the sensor.
  std::vector<std::string> left_out;

  std::vector<std::string> ChosenNames() const;
};

/// r_ij of the columns of `series` (samples x sensors), convention 2.
Eigen::MatrixXd SimilarityMatrix(const Eigen::MatrixXd& series);
/// (A o B)_ij = max_k min(A_ik, B_kj).
Eigen::MatrixXd MaxMinCompose(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);
/// Transitive closure by repeated squaring (convention 3); `squarings` receives the count.
Eigen::MatrixXd FuzzyEquivalence(const Eigen::MatrixXd& similarity, int* squarings = nullptr);
/// Distinct off-diagonal values of `r`, descending (exact comparison).
std::vector<double> LambdaLevels(const Eigen::MatrixXd& r);
/// Class labels of the lambda-cut (convention 4), numbered by first member.
std::vector<int> LambdaCut(const Eigen::MatrixXd& r, double lambda);
/// Columns z-scored (mean 0, population std 1); a constant column becomes 0.
Eigen::MatrixXd ZScore(const Eigen::MatrixXd& series);
/// F statistic of convention 5 for the sensors (columns of z) labelled 0..r-1; needs 1 < r < m.
double FStatistic(const Eigen::MatrixXd& z, const std::vector<int>& labels);
/// Upper-alpha quantile of the F(d1, d2) distribution (Boost.Math).
double FCritical(int d1, int d2, double alpha);
/// Deng's grades of the columns of `series` against `error` (convention 7).
Eigen::VectorXd GreyGrades(const Eigen::MatrixXd& series, const Eigen::VectorXd& error,
                           double rho = 0.5);

/// Sums over the stacked rises of runs (convention 1) that are not held: the row count, the
/// mean, the centred cross products sum (x - mean)(x - mean)' and each sensor's largest |rise|,
/// merged block by block (Chan, Golub and LeVeque's pairwise update). They give the screen
/// (convention 8: dead = largest |rise| 0, duplicates by the centred cross products, as
/// ScreenSensors), the similarity r_ij (convention 2) and the F statistic (convention 5, through
/// z_i' z_j = n r_ij signed) over every row of a long log (drift/stream.h FitFiles).
struct SelectionMoments {
  long long rows = 0;
  Eigen::VectorXd mean;
  Eigen::MatrixXd cross;
  Eigen::VectorXd max_abs;
  /// Adds rows (samples x sensors) of rises.
  void Add(const Eigen::MatrixXd& rises);
};

/// The whole selection on stacked rises and errors (samples x sensors, samples).
Selection SelectSensors(const Eigen::MatrixXd& rises, const Eigen::VectorXd& error,
                        const std::vector<std::string>& sensor_names,
                        const SelectionOptions& options = {});
/// Same on runs (convention 1) for the error channel `error_column`; InputError if a run lacks
/// it or the runs' sensors differ.
Selection SelectSensors(const std::vector<Run>& runs, const std::string& error_column,
                        const SelectionOptions& options = {});
/// The same with the screen, the similarity and the F statistic from `all_rows` (the moments of
/// every row of the logs `runs` were thinned from, sensors in runs' order) and the grey grades
/// from `runs` (their min-max normalization too): what FitFiles runs on a thinned sample. Null:
/// SelectSensors(runs, ...).
Selection SelectSensors(const std::vector<Run>& runs, const std::string& error_column,
                        const SelectionOptions& options, const SelectionMoments* all_rows);

/// FStatistic from the columns' products z_i' z_j (`gram`, m x m) instead of the columns: the same
/// F (between and within sums of squares are quadratic forms in the z_i).
double FStatisticFromGram(const Eigen::MatrixXd& gram, const std::vector<int>& labels);

/// 1 - |r| below which two rise series count as one (convention 8).
inline constexpr double kDuplicateTolerance = 1e-12;

/// Convention 8 on stacked rises (samples x sensors, convention 1) named `names`.
struct SensorScreen {
  std::vector<int> usable;            ///< columns kept, in file order
  std::vector<std::string> left_out;  ///< one line per column left out: its name and why
};
/// InputError "<sources>: no usable temperature sensor: ..." when every column is left out
/// (`sources` names the run files).
SensorScreen ScreenSensors(const Eigen::MatrixXd& rises, const std::vector<std::string>& names,
                           const std::string& sources);
/// Convention 8 from moments (SelectionMoments) instead of the rises.
SensorScreen ScreenSensors(const SelectionMoments& moments, const std::vector<std::string>& names,
                           const std::string& sources);

/// "a.csv, b.csv": the files of the runs, for messages.
std::string RunSources(const std::vector<Run>& runs);

/// Rises and errors of several runs stacked (convention 1). Sensors must agree by name.
void StackRuns(const std::vector<Run>& runs, const std::string& error_column,
               Eigen::MatrixXd* rises, Eigen::VectorXd* error);

}  // namespace whirl::drift
