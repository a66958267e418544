#include "machine_eval/field_monitor.h"

#include <algorithm>
#include <cmath>

#include "machine_eval/shop_models.h"

namespace whirl::machine_eval {

ProbeMonitor MakeProbeMonitor(const drift::JointDriftModel& sensors,
                              const std::vector<drift::Run>& training_logs) {
  ProbeMonitor m;
  if (sensors.features() == 0 || training_logs.empty()) return m;
  const ShopControl control = ShopControlModels(sensors, training_logs);
  m.offset = control.offset;
  m.offset.residual_std_um = sensors.cv_rmse_um;
  m.active = control.ranged;
  return m;
}

namespace {

// The coefficients in force from a sample on.
struct Piece {
  Eigen::Index from = 0;
  Eigen::VectorXd b;
};

}  // namespace

MonitoredDay MonitorWithSetupChecks(const HeldSamples& held, const ProbeMonitor& monitor,
                                    const drift::Run& log,
                                    const std::vector<machine::Reading>& checks, double z_ref_mm,
                                    double probe_z_mm, double probe_sigma_um,
                                    const drift::MonitorOptions& options, MonitorState* state) {
  MonitoredDay out;
  out.held = held;
  if (!monitor.active || log.samples() == 0) return out;
  const drift::DriftModel& m = monitor.offset;
  const Eigen::MatrixXd x = drift::MonitorDesign(m, log, drift::ReferenceMode::kRunStart);
  const Eigen::MatrixXd dx = x.rowwise() - x.row(0);
  const Eigen::VectorXd trained = m.linear.coefficients;
  const bool carried = state && state->coefficients.size() == trained.size();
  Eigen::VectorXd b = carried ? state->coefficients : trained;
  Eigen::MatrixXd prior =
      carried ? state->covariance : Eigen::MatrixXd(options.prior_scale * m.linear.covariance);
  const double s = m.residual_std_um;
  const double r = s * s + 2 * probe_sigma_um * probe_sigma_um;
  const double threshold =
      options.threshold_um > 0 ? options.threshold_um : options.threshold_sigma * std::sqrt(r);
  const bool update = std::find(options.rules.begin(), options.rules.end(),
                                drift::UpdateRule::kBayes) != options.rules.end();
  const double w = (z_ref_mm - probe_z_mm) / 1000.0;
  std::vector<drift::Innovation> innovations;
  std::vector<Piece> pieces = {{0, b}};
  const Eigen::VectorXd column_scale = drift::TrainingColumnScale(m);
  drift::SeenBox seen_box;
  Eigen::Index seen = 0;
  for (std::size_t c = 1; c < checks.size(); ++c) {
    const double t = checks[c].abs_min;
    if (t < log.time_min.front()) continue;
    const auto i = static_cast<Eigen::Index>(held.IndexAt(t));
    for (; seen <= i; ++seen) seen_box.Add(x.row(seen));
    const double y = checks[c].value_um - checks[0].value_um -
                     held.slope_um_per_1000[static_cast<std::size_t>(i)] * w;
    const Eigen::RowVectorXd xi = dx.row(i);
    const double misfit = y - xi.dot(b);
    const Eigen::VectorXd d = drift::DriftScale(column_scale, seen_box);
    innovations.push_back(drift::CheckInnovation(xi, misfit, prior, r, d));
    ++out.checks;
    if (std::abs(misfit) <= threshold) continue;
    ++out.invalid;
    if (!update) continue;
    if (options.estimate_drift) drift::AddDriftVariance(innovations, d, &prior);
    b = drift::BayesUpdate(xi, Eigen::VectorXd::Constant(1, y), b, &prior, r);
    const auto from =
        std::lower_bound(log.time_min.begin(), log.time_min.end(), t - 1e-9) - log.time_min.begin();
    pieces.push_back({static_cast<Eigen::Index>(from), b});
    ++out.updates;
  }
  if (state) *state = {b, prior};
  std::size_t piece = 0;
  for (Eigen::Index k = 0; k < dx.rows(); ++k) {
    while (piece + 1 < pieces.size() && pieces[piece + 1].from <= k) ++piece;
    out.held.k0_um[static_cast<std::size_t>(k)] += dx.row(k).dot(pieces[piece].b - trained);
  }
  return out;
}

}  // namespace whirl::machine_eval
