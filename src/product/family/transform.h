#pragma once
// Per-column transforms of a process table before a model is fitted, and the mapping of a
// prediction (mean and standard deviation) back to the column's own units.
//
// Why: the simulator's features follow power laws in the process inputs (plateau ~ raceway
// radius^1.97, speed^-1.7, lead^-0.99), and a model linear in ln x for ln y is such a power law;
// every process input and both features are strictly positive quantities (core/limits.h).
//   kIdentity: z = x.
//   kLog:      z = ln x, only for strictly positive columns (a value <= 0 is an InputError).
// A log is considered for every column, and not taken for a column that holds a value <= 0 or a
// value near zero (below kNearZeroShare times the column's median, where one row would dominate
// the fit on a log scale); LogExceptions names those rows so that a warning can say so.
// An input that is constant in the training table is left out (TableTransform::input_used): a
// fit cannot learn its effect, and a model that kept it would extrapolate in it at any other
// value; its transformed value is 0 for every row and the linear and GP fits do not see it.
// Back-mapping of a prediction with mean m and standard deviation s in the transformed space,
// by the delta method (first-order Taylor expansion of the inverse g^-1 about m; e.g. Casella &
// Berger, "Statistical Inference", 2nd ed., section 5.5.4):
//   mean = g^-1(m),  sd = |dg^-1/dz (m)| s;   for kLog: mean = exp(m), sd = exp(m) s.
// For kLog, exp(m) is the median of the log-normal predictive distribution (its mean is
// exp(m + s^2 / 2)); the delta-method sd agrees with the log-normal's sd,
// exp(m) sqrt(exp(s^2) - 1) exp(s^2 / 2), to first order in s (tested against Monte Carlo).
#include <Eigen/Core>
#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/process.h"

namespace whirl::family {

enum class ColumnTransform { kIdentity, kLog };
std::string ToString(ColumnTransform t);                     ///< "identity", "log"
ColumnTransform ParseColumnTransform(const std::string& s);  ///< inverse; InputError otherwise

/// One transform per input (kInputColumns order) and per output (kTargetColumns order), and the
/// inputs the model uses.
struct TableTransform {
  std::array<ColumnTransform, ProcessInputs::kCount> inputs{};
  std::array<ColumnTransform, Features::kCount> outputs{};
  /// false: the input is left out (constant in the training table): transformed to 0.
  std::array<bool, ProcessInputs::kCount> input_used{true, true, true, true, true};
  bool IsIdentity() const;  ///< every column kIdentity (left-out inputs do not count)
  int UsedInputCount() const;
  /// "log of every input and output" / "identity" / per column, and the inputs left out.
  std::string Describe() const;
};

/// A log-scale column value that is not near zero: at least this share of the column's median.
inline constexpr double kNearZeroShare = 1e-3;

/// Why a column considered for a log stays on its raw scale: its first offending row.
struct LogException {
  bool input = false;  ///< an input column (else a target)
  int column = 0;      ///< index into kInputColumns or kTargetColumns
  int row = 0;         ///< 0-based row of the table
  double value = 0;
  double median = 0;  ///< of the column
  std::string Describe(const ProcessTable& table) const;  ///< "max_elongation_um = 0 (line 9)..."
};
/// The columns of `table` that LogWherePositive keeps on their raw scale, in column order.
std::vector<LogException> LogExceptions(const ProcessTable& table);

/// kLog for every column (inputs and targets) of `table` without a LogException, kIdentity for
/// the others; inputs left out as by LeaveOutConstantInputs.
TableTransform LogWherePositive(const ProcessTable& table);

/// Marks every input whose values in `table` are all equal (relative spread below 1e-12) as left
/// out of `t`, and returns their indices.
std::vector<int> LeaveOutConstantInputs(const ProcessTable& table, TableTransform* t);

/// The target columns of `table` whose values are all equal (the same rule): nothing to learn
/// there; the choice leaves them out of its score (ChooseFamily) and `whirl train` warns.
std::vector<int> ConstantTargets(const ProcessTable& table);

/// z = g(x) for one value; InputError naming `column` if kLog and x <= 0 or x is not finite.
double Forward(ColumnTransform t, double x, const char* column);
/// g^-1(z).
double Inverse(ColumnTransform t, double z);
/// dg^-1/dz at z (1 for kIdentity, exp(z) for kLog).
double InverseDerivative(ColumnTransform t, double z);

/// Inputs (5 x Q) and targets (2 x Q), original units, mapped column by column (row i of the
/// matrix through inputs[i] / outputs[i]; a left-out input to 0). InputError names the column
/// and the sample.
Eigen::MatrixXd TransformInputs(const TableTransform& t, const Eigen::MatrixXd& x);
Eigen::MatrixXd TransformTargets(const TableTransform& t, const Eigen::MatrixXd& y);
/// The rows of the used inputs of z (5 x Q, transformed): UsedInputCount() x Q.
Eigen::MatrixXd UsedInputRows(const TableTransform& t, const Eigen::MatrixXd& z);

/// Delta-method back-mapping of the header comment for output `k`.
struct MeanSd {
  double mean = 0, sd = 0;
};
MeanSd MapBack(ColumnTransform t, double mean_z, double sd_z);

/// {"inputs": names, "outputs": names} and, when an input is left out, "inputs_used": booleans.
void to_json(nlohmann::json& j, const TableTransform& t);
/// InputError naming the key unless "inputs" has 5 and "outputs" 2 known transform names and
/// "inputs_used" (optional, default all true) 5 booleans with at least one true.
void from_json(const nlohmann::json& j, TableTransform& t);

}  // namespace whirl::family
