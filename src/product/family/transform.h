#pragma once
// Per-column transforms of a process table before a model is fitted, and the mapping of a
// prediction (mean and standard deviation) back to the column's own units.
//
// Why: the simulator's features follow power laws in the process inputs (plateau ~ raceway
// radius^1.97, speed^-1.7, lead^-0.99), and a model linear in ln x for ln y is such a power law;
// every process input and both features are strictly positive quantities (core/limits.h).
//   kIdentity: z = x.
//   kLog:      z = ln x, only for strictly positive columns (a value <= 0 is an InputError).
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

#include "core/process.h"

namespace whirl::family {

enum class ColumnTransform { kIdentity, kLog };
std::string ToString(ColumnTransform t);                     ///< "identity", "log"
ColumnTransform ParseColumnTransform(const std::string& s);  ///< inverse; InputError otherwise

/// One transform per input (kInputColumns order) and per output (kTargetColumns order).
struct TableTransform {
  std::array<ColumnTransform, ProcessInputs::kCount> inputs{};
  std::array<ColumnTransform, Features::kCount> outputs{};
  bool IsIdentity() const;
  std::string Describe() const;  ///< "log: all inputs and outputs" / "identity" / per column
};

/// kLog for every column (inputs and targets) whose values in `table` are all > 0, kIdentity for
/// the others.
TableTransform LogWherePositive(const ProcessTable& table);

/// z = g(x) for one value; InputError naming `column` if kLog and x <= 0 or x is not finite.
double Forward(ColumnTransform t, double x, const char* column);
/// g^-1(z).
double Inverse(ColumnTransform t, double z);
/// dg^-1/dz at z (1 for kIdentity, exp(z) for kLog).
double InverseDerivative(ColumnTransform t, double z);

/// Inputs (5 x Q) and targets (2 x Q), original units, mapped column by column (row i of the
/// matrix through inputs[i] / outputs[i]). InputError names the column and the sample.
Eigen::MatrixXd TransformInputs(const TableTransform& t, const Eigen::MatrixXd& x);
Eigen::MatrixXd TransformTargets(const TableTransform& t, const Eigen::MatrixXd& y);

/// Delta-method back-mapping of the header comment for output `k`.
struct MeanSd {
  double mean = 0, sd = 0;
};
MeanSd MapBack(ColumnTransform t, double mean_z, double sd_z);

void to_json(nlohmann::json& j, const TableTransform& t);
/// InputError naming the key unless "inputs" has 5 and "outputs" 2 known transform names.
void from_json(const nlohmann::json& j, TableTransform& t);

}  // namespace whirl::family
