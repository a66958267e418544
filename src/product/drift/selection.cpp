#include "drift/selection.h"

#include <algorithm>
#include <boost/math/distributions/fisher_f.hpp>
#include <cmath>
#include <functional>
#include <limits>

#include "core/error.h"
#include "core/numbers.h"

namespace whirl::drift {
namespace {

Eigen::VectorXd MinMaxNormalize(const Eigen::VectorXd& x) {
  const double lo = x.minCoeff(), hi = x.maxCoeff();
  if (!(hi > lo)) return Eigen::VectorXd::Zero(x.size());
  return (x.array() - lo) / (hi - lo);
}

// Relative margin (F - F_crit) / F_crit; +inf for an infinite F.
double Margin(const Partition& p) { return (p.f - p.f_critical) / p.f_critical; }

// Each class's sensor with the highest grade (ties: the first), in file order.
std::vector<int> BestPerClass(const std::vector<int>& labels, const Eigen::VectorXd& grades) {
  const int r = *std::max_element(labels.begin(), labels.end()) + 1;
  std::vector<int> best(static_cast<std::size_t>(r), -1);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    int& b = best[static_cast<std::size_t>(labels[i])];
    if (b < 0 || grades(static_cast<Eigen::Index>(i)) > grades(b)) b = static_cast<int>(i);
  }
  std::sort(best.begin(), best.end());
  return best;
}

// Picks the partition by the options' rule; returns -1 (every sensor a class) if none qualifies.
int ChoosePartition(const std::vector<Partition>& parts, const SelectionOptions& o,
                    std::string* message) {
  auto eligible = [&](const Partition& p) {
    return o.max_classes <= 0 || p.classes <= o.max_classes;
  };
  auto best_margin = [&]() {
    int best = -1;
    for (std::size_t i = 0; i < parts.size(); ++i)
      if (parts[i].has_f && eligible(parts[i]) &&
          (best < 0 || Margin(parts[i]) > Margin(parts[static_cast<std::size_t>(best)])))
        best = static_cast<int>(i);
    return best;
  };
  if (o.rule == ClassCountRule::kCrossValidated)
    throw InputError("class count 'cv' is chosen by fitting the model (drift::SelectSensorsForFit)");
  if (o.rule == ClassCountRule::kFixed) {
    for (std::size_t i = 0; i < parts.size(); ++i)
      if (parts[i].classes == o.fixed_classes) {
        *message = "fixed class count " + std::to_string(o.fixed_classes) + " (lambda " +
                   FormatSignificant(parts[i].lambda, 4) + ")";
        return static_cast<int>(i);
      }
    std::string have;
    for (const auto& p : parts) have += (have.empty() ? "" : ", ") + std::to_string(p.classes);
    throw InputError("--classes " + std::to_string(o.fixed_classes) +
                     ": no lambda-cut has that many classes (the cuts have " + have + ")");
  }
  if (o.rule == ClassCountRule::kFewestSignificant) {
    int best = -1;
    for (std::size_t i = 0; i < parts.size(); ++i)
      if (parts[i].significant() && eligible(parts[i]) &&
          (best < 0 || parts[i].classes < parts[static_cast<std::size_t>(best)].classes))
        best = static_cast<int>(i);
    if (best >= 0) {
      const Partition& p = parts[static_cast<std::size_t>(best)];
      *message = "fewest classes with a significant F: r = " + std::to_string(p.classes) +
                 " at lambda " + FormatSignificant(p.lambda, 4) + " (F " +
                 FormatSignificant(p.f, 4) + " > F_crit " + FormatSignificant(p.f_critical, 4) +
                 ")";
      return best;
    }
  }
  const int best = best_margin();
  if (best >= 0) {
    const Partition& p = parts[static_cast<std::size_t>(best)];
    *message = std::string(o.rule == ClassCountRule::kLargestMargin
                               ? "largest (F - F_crit) / F_crit"
                               : "no eligible partition has a significant F; fallback: largest "
                                 "(F - F_crit) / F_crit") +
               ": r = " + std::to_string(p.classes) + " at lambda " +
               FormatSignificant(p.lambda, 4) + " (F " + FormatSignificant(p.f, 4) + ", F_crit " +
               FormatSignificant(p.f_critical, 4) + ")";
    return best;
  }
  *message = "no partition with 1 < r < m (and r <= max classes): every sensor is its own class";
  return -1;
}

}  // namespace

std::string ToString(ClassCountRule r) {
  switch (r) {
    case ClassCountRule::kLargestMargin:
      return "margin";
    case ClassCountRule::kFixed:
      return "fixed";
    case ClassCountRule::kCrossValidated:
      return "cv";
    case ClassCountRule::kFewestSignificant:
      break;
  }
  return "fewest";
}

ClassCountRule ParseClassCountRule(const std::string& s) {
  if (s == "fewest") return ClassCountRule::kFewestSignificant;
  if (s == "margin") return ClassCountRule::kLargestMargin;
  if (s == "fixed") return ClassCountRule::kFixed;
  if (s == "cv") return ClassCountRule::kCrossValidated;
  throw InputError("class-count rule '" + s + "': must be fewest, margin, fixed or cv");
}

void SelectionOptions::Validate() const {
  if (!(alpha > 0 && alpha < 1))
    throw InputError("alpha " + FormatSignificant(alpha, 4) + ": must be in (0, 1)");
  if (!(rho > 0 && rho <= 1))
    throw InputError("rho " + FormatSignificant(rho, 4) + ": must be in (0, 1]");
  if (rule == ClassCountRule::kFixed && fixed_classes < 1)
    throw InputError("fixed class count " + std::to_string(fixed_classes) + ": must be >= 1");
  if (max_classes < 0)
    throw InputError("max classes " + std::to_string(max_classes) + ": must be >= 0");
}

std::vector<std::string> Selection::ChosenNames() const {
  std::vector<std::string> out;
  for (int i : chosen) out.push_back(sensor_names[static_cast<std::size_t>(i)]);
  return out;
}

Eigen::MatrixXd SimilarityMatrix(const Eigen::MatrixXd& series) {
  const Eigen::Index m = series.cols();
  Eigen::MatrixXd c = series.rowwise() - series.colwise().mean();
  const Eigen::VectorXd norm = c.colwise().norm();
  Eigen::MatrixXd r = Eigen::MatrixXd::Identity(m, m);
  for (Eigen::Index i = 0; i < m; ++i)
    for (Eigen::Index j = i + 1; j < m; ++j) {
      double v = 0;
      if (norm(i) > 0 && norm(j) > 0)
        v = std::min(1.0, std::abs(c.col(i).dot(c.col(j))) / (norm(i) * norm(j)));
      r(i, j) = r(j, i) = v;
    }
  return r;
}

Eigen::MatrixXd MaxMinCompose(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  Eigen::MatrixXd c(a.rows(), b.cols());
  for (Eigen::Index i = 0; i < a.rows(); ++i)
    for (Eigen::Index j = 0; j < b.cols(); ++j) {
      double v = 0;
      for (Eigen::Index k = 0; k < a.cols(); ++k) v = std::max(v, std::min(a(i, k), b(k, j)));
      c(i, j) = v;
    }
  return c;
}

Eigen::MatrixXd FuzzyEquivalence(const Eigen::MatrixXd& similarity, int* squarings) {
  Eigen::MatrixXd r = similarity;
  int n = 0;
  for (;;) {
    Eigen::MatrixXd next = MaxMinCompose(r, r);
    ++n;
    if (next == r) break;  // max and min only copy entries: exact comparison is safe
    r = std::move(next);
  }
  if (squarings) *squarings = n;
  return r;
}

std::vector<double> LambdaLevels(const Eigen::MatrixXd& r) {
  std::vector<double> levels;
  for (Eigen::Index i = 0; i < r.rows(); ++i)
    for (Eigen::Index j = i + 1; j < r.cols(); ++j) levels.push_back(r(i, j));
  std::sort(levels.begin(), levels.end(), std::greater<double>());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  return levels;
}

std::vector<int> LambdaCut(const Eigen::MatrixXd& r, double lambda) {
  const auto m = static_cast<int>(r.rows());
  std::vector<int> labels(static_cast<std::size_t>(m), -1);
  int next = 0;
  for (int i = 0; i < m; ++i) {
    if (labels[static_cast<std::size_t>(i)] >= 0) continue;
    for (int j = i; j < m; ++j)
      if (labels[static_cast<std::size_t>(j)] < 0 && (j == i || r(i, j) >= lambda))
        labels[static_cast<std::size_t>(j)] = next;
    ++next;
  }
  return labels;
}

Eigen::MatrixXd ZScore(const Eigen::MatrixXd& series) {
  Eigen::MatrixXd z = series.rowwise() - series.colwise().mean();
  for (Eigen::Index j = 0; j < z.cols(); ++j) {
    const double sd = std::sqrt(z.col(j).squaredNorm() / static_cast<double>(z.rows()));
    if (sd > 0)
      z.col(j) /= sd;
    else
      z.col(j).setZero();
  }
  return z;
}

double FStatistic(const Eigen::MatrixXd& z, const std::vector<int>& labels) {
  const auto m = static_cast<int>(z.cols());
  const int r = *std::max_element(labels.begin(), labels.end()) + 1;
  if (!(r > 1 && r < m))
    throw InputError("F statistic needs 1 < r < m (r = " + std::to_string(r) +
                     ", m = " + std::to_string(m) + ")");
  const Eigen::VectorXd mean = z.rowwise().mean();
  Eigen::MatrixXd class_sum = Eigen::MatrixXd::Zero(z.rows(), r);
  std::vector<int> n(static_cast<std::size_t>(r), 0);
  for (int i = 0; i < m; ++i) {
    class_sum.col(labels[static_cast<std::size_t>(i)]) += z.col(i);
    ++n[static_cast<std::size_t>(labels[static_cast<std::size_t>(i)])];
  }
  double between = 0, within = 0;
  for (int k = 0; k < r; ++k) {
    class_sum.col(k) /= n[static_cast<std::size_t>(k)];
    between += n[static_cast<std::size_t>(k)] * (class_sum.col(k) - mean).squaredNorm();
  }
  for (int i = 0; i < m; ++i)
    within += (z.col(i) - class_sum.col(labels[static_cast<std::size_t>(i)])).squaredNorm();
  const double num = between / (r - 1), den = within / (m - r);
  if (den <= 0) return std::numeric_limits<double>::infinity();
  return num / den;
}

double FCritical(int d1, int d2, double alpha) {
  if (d1 < 1 || d2 < 1 || !(alpha > 0 && alpha < 1))
    throw InputError("F critical value needs d1, d2 >= 1 and alpha in (0, 1)");
  const boost::math::fisher_f dist(d1, d2);
  return boost::math::quantile(boost::math::complement(dist, alpha));
}

Eigen::VectorXd GreyGrades(const Eigen::MatrixXd& series, const Eigen::VectorXd& error,
                           double rho) {
  const Eigen::VectorXd x0 = MinMaxNormalize(error);
  Eigen::MatrixXd d(series.rows(), series.cols());
  for (Eigen::Index i = 0; i < series.cols(); ++i)
    d.col(i) = (x0 - MinMaxNormalize(series.col(i))).cwiseAbs();
  const double dmin = d.minCoeff(), dmax = d.maxCoeff();
  if (!(dmax > 0)) return Eigen::VectorXd::Ones(series.cols());
  const Eigen::MatrixXd xi = (dmin + rho * dmax) / (d.array() + rho * dmax);
  return xi.colwise().mean().transpose();
}

namespace {

// The selection from its parts (conventions 3-7): the similarity matrix, the F statistic of a
// partition and the grades.
Selection SelectWith(Eigen::MatrixXd similarity,
                     const std::function<double(const std::vector<int>&)>& f_statistic,
                     Eigen::VectorXd grades, const std::vector<std::string>& sensor_names,
                     const SelectionOptions& options) {
  const auto m = static_cast<int>(similarity.rows());
  Selection s;
  s.sensor_names = sensor_names;
  s.similarity = std::move(similarity);
  s.equivalence = FuzzyEquivalence(s.similarity, &s.squarings);
  for (double lambda : LambdaLevels(s.equivalence)) {
    Partition p;
    p.lambda = lambda;
    p.labels = LambdaCut(s.equivalence, lambda);
    p.classes = *std::max_element(p.labels.begin(), p.labels.end()) + 1;
    p.has_f = p.classes > 1 && p.classes < m;
    if (p.has_f) {
      p.f = f_statistic(p.labels);
      p.f_critical = FCritical(p.classes - 1, m - p.classes, options.alpha);
    }
    s.partitions.push_back(std::move(p));
  }
  s.grades = std::move(grades);
  s.chosen_partition = ChoosePartition(s.partitions, options, &s.message);
  if (s.chosen_partition >= 0) {
    s.chosen =
        BestPerClass(s.partitions[static_cast<std::size_t>(s.chosen_partition)].labels, s.grades);
  } else {
    std::vector<int> order(static_cast<std::size_t>(m));
    for (int i = 0; i < m; ++i) order[static_cast<std::size_t>(i)] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return s.grades(a) > s.grades(b); });
    if (options.max_classes > 0 && options.max_classes < m)
      order.resize(static_cast<std::size_t>(options.max_classes));
    std::sort(order.begin(), order.end());
    s.chosen = order;
  }
  return s;
}

void CheckSelectionInputs(int m, Eigen::Index samples, bool sizes_agree) {
  if (m < 1 || samples < 3 || !sizes_agree)
    throw InputError("sensor selection needs at least 1 sensor and 3 samples (have " +
                     std::to_string(m) + " sensors, " + std::to_string(samples) + " samples)");
}

}  // namespace

Selection SelectSensors(const Eigen::MatrixXd& rises, const Eigen::VectorXd& error,
                        const std::vector<std::string>& sensor_names,
                        const SelectionOptions& options) {
  options.Validate();
  const auto m = static_cast<int>(rises.cols());
  CheckSelectionInputs(m, rises.rows(),
                       error.size() == rises.rows() && static_cast<int>(sensor_names.size()) == m);
  const Eigen::MatrixXd z = ZScore(rises);
  return SelectWith(
      SimilarityMatrix(rises), [&](const std::vector<int>& labels) { return FStatistic(z, labels); },
      GreyGrades(rises, error, options.rho), sensor_names, options);
}

void SelectionMoments::Add(const Eigen::MatrixXd& x) {
  if (x.rows() == 0) return;
  const Eigen::VectorXd m = x.colwise().mean().transpose();
  const Eigen::MatrixXd c = x.rowwise() - m.transpose();
  const Eigen::MatrixXd cross_b = c.transpose() * c;
  const Eigen::VectorXd max_b = x.cwiseAbs().colwise().maxCoeff().transpose();
  if (rows == 0) {
    rows = x.rows();
    mean = m;
    cross = cross_b;
    max_abs = max_b;
    return;
  }
  const double na = static_cast<double>(rows), nb = static_cast<double>(x.rows());
  const Eigen::VectorXd d = m - mean;
  cross += cross_b + d * d.transpose() * (na * nb / (na + nb));
  mean += d * (nb / (na + nb));
  max_abs = max_abs.cwiseMax(max_b);
  rows += x.rows();
}

double FStatisticFromGram(const Eigen::MatrixXd& g, const std::vector<int>& labels) {
  const auto m = static_cast<int>(g.rows());
  const int r = *std::max_element(labels.begin(), labels.end()) + 1;
  if (!(r > 1 && r < m))
    throw InputError("F statistic needs 1 < r < m (r = " + std::to_string(r) +
                     ", m = " + std::to_string(m) + ")");
  // S(k, l) = sum of g over the members of classes k and l; n_k the class sizes.
  Eigen::MatrixXd member = Eigen::MatrixXd::Zero(m, r);
  for (int i = 0; i < m; ++i) member(i, labels[static_cast<std::size_t>(i)]) = 1;
  const Eigen::MatrixXd sums = member.transpose() * g * member;
  const Eigen::VectorXd n = member.colwise().sum().transpose();
  const double all = sums.sum();
  double between = 0, within = g.trace();
  for (int k = 0; k < r; ++k) {
    const double to_all = sums.row(k).sum();
    // n_k |zbar_k - zbar|^2 = S_kk / n_k - 2 S_k. / m + n_k S.. / m^2
    between += sums(k, k) / n(k) - 2 * to_all / m + n(k) * all / (static_cast<double>(m) * m);
    within -= sums(k, k) / n(k);  // sum_i |z_i - zbar_k|^2 = sum_i g_ii - S_kk / n_k
  }
  const double num = between / (r - 1), den = within / (m - r);
  if (den <= 0) return std::numeric_limits<double>::infinity();
  return num / den;
}

void StackRuns(const std::vector<Run>& runs, const std::string& error_column,
               Eigen::MatrixXd* rises, Eigen::VectorXd* error) {
  if (runs.empty()) throw InputError("no run given");
  Eigen::Index total = 0;
  for (const Run& r : runs) {
    if (r.sensor_names != runs.front().sensor_names)
      throw InputError(r.source + ": its temperature columns differ from " + runs.front().source +
                       "'s (runs must log the same sensors)");
    r.ErrorIndex(error_column);
    total += r.samples();
  }
  rises->resize(total, runs.front().temperature_C.cols());
  error->resize(total);
  Eigen::Index at = 0;
  for (const Run& r : runs) {
    rises->middleRows(at, r.samples()) = r.Rises();
    error->segment(at, r.samples()) = r.error_um.col(r.ErrorIndex(error_column));
    at += r.samples();
  }
}

namespace {

// Convention 8 from the centred cross products `gram` and each column's largest |rise|.
SensorScreen ScreenFromGram(const Eigen::MatrixXd& gram, const Eigen::VectorXd& max_abs,
                            long long rows, const std::vector<std::string>& names,
                            const std::string& sources) {
  SensorScreen s;
  for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(names.size()); ++j) {
    const std::string& name = names[static_cast<std::size_t>(j)];
    if (rows == 0 || max_abs(j) == 0) {
      s.left_out.push_back(name + " is dead: its reading never moves in " + sources +
                           " (a stuck or disconnected sensor); left out");
      continue;
    }
    int copy_of = -1;
    for (const int i : s.usable) {
      const double norms = std::sqrt(gram(i, i) * gram(j, j));
      if (norms > 0 && std::abs(gram(i, j)) >= (1 - kDuplicateTolerance) * norms) copy_of = i;
      if (copy_of >= 0) break;
    }
    if (copy_of >= 0) {
      s.left_out.push_back(name + " moves exactly as " + names[static_cast<std::size_t>(copy_of)] +
                           " in " + sources + " (the same sensor twice?); left out");
      continue;
    }
    s.usable.push_back(static_cast<int>(j));
  }
  if (s.usable.empty())
    throw InputError(sources +
                     ": no usable temperature sensor: every _C column is dead (its "
                     "reading never moves) or a copy of another; check the logger");
  return s;
}

}  // namespace

SensorScreen ScreenSensors(const Eigen::MatrixXd& rises, const std::vector<std::string>& names,
                           const std::string& sources) {
  const Eigen::MatrixXd c = rises.rowwise() - rises.colwise().mean();
  const Eigen::MatrixXd gram = c.transpose() * c;  // centred cross products
  const Eigen::VectorXd max_abs = rises.rows() == 0
                                      ? Eigen::VectorXd::Zero(rises.cols())
                                      : Eigen::VectorXd(rises.cwiseAbs().colwise().maxCoeff().transpose());
  return ScreenFromGram(gram, max_abs, rises.rows(), names, sources);
}

SensorScreen ScreenSensors(const SelectionMoments& moments, const std::vector<std::string>& names,
                           const std::string& sources) {
  if (moments.rows == 0) {
    const auto m = static_cast<Eigen::Index>(names.size());
    return ScreenFromGram(Eigen::MatrixXd::Zero(m, m), Eigen::VectorXd::Zero(m), 0, names, sources);
  }
  return ScreenFromGram(moments.cross, moments.max_abs, moments.rows, names, sources);
}

std::string RunSources(const std::vector<Run>& runs) {
  std::string out;
  for (const Run& r : runs) out += (out.empty() ? "" : ", ") + r.source;
  return out;
}

Selection SelectSensors(const std::vector<Run>& runs, const std::string& error_column,
                        const SelectionOptions& options) {
  return SelectSensors(runs, error_column, options, nullptr);
}

Selection SelectSensors(const std::vector<Run>& runs, const std::string& error_column,
                        const SelectionOptions& options, const SelectionMoments* all_rows) {
  Eigen::MatrixXd rises;
  Eigen::VectorXd error;
  StackRuns(runs, error_column, &rises, &error);
  const std::vector<std::string>& all = runs.front().sensor_names;
  const SensorScreen screen = all_rows ? ScreenSensors(*all_rows, all, RunSources(runs))
                                       : ScreenSensors(rises, all, RunSources(runs));
  Eigen::MatrixXd kept(rises.rows(), static_cast<Eigen::Index>(screen.usable.size()));
  std::vector<std::string> names;
  for (std::size_t k = 0; k < screen.usable.size(); ++k) {
    kept.col(static_cast<Eigen::Index>(k)) = rises.col(screen.usable[k]);
    names.push_back(all[static_cast<std::size_t>(screen.usable[k])]);
  }
  Selection s;
  if (all_rows == nullptr) {
    s = SelectSensors(kept, error, names, options);
  } else {  // the similarity and the F test from every row; the grades from the runs
    options.Validate();
    const auto m = static_cast<Eigen::Index>(names.size());
    CheckSelectionInputs(static_cast<int>(m), all_rows->rows >= 3 ? kept.rows() : 0, true);
    Eigen::MatrixXd cross(m, m);
    for (Eigen::Index i = 0; i < m; ++i)
      for (Eigen::Index j = 0; j < m; ++j)
        cross(i, j) = all_rows->cross(screen.usable[static_cast<std::size_t>(i)],
                                      screen.usable[static_cast<std::size_t>(j)]);
    Eigen::MatrixXd similarity = Eigen::MatrixXd::Identity(m, m), z = Eigen::MatrixXd::Zero(m, m);
    for (Eigen::Index i = 0; i < m; ++i)
      for (Eigen::Index j = 0; j < m; ++j) {
        const double norms = std::sqrt(cross(i, i) * cross(j, j));
        if (!(norms > 0)) continue;
        z(i, j) = cross(i, j) / norms;  // z_i' z_j / n: a constant sensor's z is 0
        if (i != j) similarity(i, j) = std::min(1.0, std::abs(z(i, j)));
      }
    s = SelectWith(
        similarity, [&](const std::vector<int>& labels) { return FStatisticFromGram(z, labels); },
        GreyGrades(kept, error, options.rho), names, options);
  }
  s.left_out = screen.left_out;
  return s;
}

}  // namespace whirl::drift
