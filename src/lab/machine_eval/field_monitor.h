#pragma once
// both_shop_monitor of the field table: the sensor model trained from shop measurements
// (field_eval.h machine_shop) kept valid on the test day by the probe checks a shop takes anyway
// at every set-up (the machine stands while the next blank is chucked; field_history.h
// SetupCheckTimes), with the recalibration of drift/monitor.h in its default form: a Bayesian
// update of the coefficients (Bishop, "Pattern Recognition and Machine Learning", eqs.
// 3.50-3.51; drift::BayesUpdate) after a drift covariance estimated from the day's checks
// (Ljung and Soderstrom, "Theory and Practice of Recursive Identification", ch. 6; Mehra, "On
// the identification of variances and adaptive Kalman filtering", 1970; drift::DriftVarianceMle).
// One probe position cannot tell the offset K0 from the slope G, so only the offset channel is
// updated; G stays as trained. Every figure is measured in the project's simulator only.
//
// Per test day, causal (what the control has at each sample):
//   * x_i = [1 f_i]: the offset channel's design row at log sample i (drift/monitor.h
//     MonitorDesign on the control's log from power-on, features as rises since power-on);
//   * the probe reads the check ring at probe_z at power-on (t_0) and at each later set-up start
//     t_k: r_k = m(t_k, probe_z) + zero + N(0, sigma^2) (machine/instruments.h). The record's zero
//     is unknown, so a check is the change since power-on less the trained slope's part there,
//       y_k = r_k - r_0 - G(i_k) (z_ref - probe_z) / 1000,  i_k = the latest sample <= t_k,
//     compared with the model's change since power-on (x_(i_k) - x_0)' b;
//   * validity and update as MonitorRun's defaults (drift::MonitorOptions): a check is invalid
//     when |y_k - (x_(i_k) - x_0)' b| > threshold_sigma sqrt(s^2 + 2 sigma^2) (s: the trained
//     model's grouped CV RMSE, drift/joint.h; two readings per check); every check's misfit joins
//     the drift estimate; an invalid check adds q^2 D^-2 to the prior covariance (q^2 by maximum
//     likelihood over the day's checks so far; D = 1 for the intercept, per feature the larger of
//     its range over the training day logs and over samples 0..i_k) and updates b from that check
//     alone (refit_samples 0). The prior starts at the trained covariance of the offset
//     coefficients (prior_scale x Cov, drift/joint.h), the day's first b at the trained one;
//   * an update made at t_k applies from the first sample at or after t_k:
//       K0_mon(i) = K0(i) + (x_i - x_0)' (b(i) - b_trained),
//     b(i) = the coefficients after every check with t_k <= time_i. So the value held at sample i
//     depends only on log samples <= i and on checks taken by time_i;
//   * the control keeps b and the covariance overnight: each test day starts from the previous
//     test day's final ones (as drift/monitor.h MonitorWeek); q^2 is estimated per day.
#include <Eigen/Core>
#include <vector>

#include "drift/joint.h"
#include "drift/monitor.h"
#include "drift/run_file.h"
#include "machine/instruments.h"
#include "machine_eval/strategies.h"

namespace whirl::machine_eval {

/// What the monitor takes from training: the sensor model's offset channel as a linear drift
/// model (drift/joint.h ToDriftModels) with the trained CV RMSE as its residual std and, as its
/// feature range, the features' range over the training day logs.
struct ProbeMonitor {
  drift::DriftModel offset;
  bool active = false;  ///< false: the sensor model has no feature (nothing to update)
};

/// From the trained sensor model and the day logs it was trained on (drift::ShopRecord).
ProbeMonitor MakeProbeMonitor(const drift::JointDriftModel& sensors,
                              const std::vector<drift::Run>& training_logs);

/// What the control keeps from one test day to the next (drift/monitor.h MonitorWeek: each day
/// starts from the previous day's final coefficients and Bayes covariance): empty = the trained
/// coefficients and prior_scale x their covariance.
struct MonitorState {
  Eigen::VectorXd coefficients;
  Eigen::MatrixXd covariance;
};

struct MonitoredDay {
  HeldSamples held;  ///< the sensor model's samples with K0 updated (G as trained)
  int checks = 0, invalid = 0, updates = 0;
};

/// The monitored samples of one test day (header comment). `held`: the sensor model run
/// causally on `log` (RunCausally, same rows); `checks`: the probe readings, power-on first
/// (abs_min ascending); options: threshold_sigma, threshold_um, prior_scale and estimate_drift
/// are read; the update is made only when options.rules holds bayes (else the model stays as
/// trained: the switch tests use). `state` (optional, in and out): the coefficients and
/// covariance the day starts from (carried from the previous test day), replaced by the day's
/// final ones. An inactive monitor: `held` as given.
MonitoredDay MonitorWithSetupChecks(const HeldSamples& held, const ProbeMonitor& monitor,
                                    const drift::Run& log,
                                    const std::vector<machine::Reading>& checks, double z_ref_mm,
                                    double probe_z_mm, double probe_sigma_um,
                                    const drift::MonitorOptions& options,
                                    MonitorState* state = nullptr);

}  // namespace whirl::machine_eval
