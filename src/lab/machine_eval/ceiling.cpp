#include "machine_eval/ceiling.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "core/error.h"
#include "core/parallel.h"
#include "core/stats.h"
#include "core/random.h"
#include "machine/instruments.h"
#include "machine/truth.h"
#include "machine_eval/cut_scoring.h"
#include "machine_eval/shop_models.h"
#include "machine_eval/strategies.h"

namespace whirl::machine_eval {

namespace {

enum FeatureSet { kNone, kTime, kTimeDuty, kJoint, kAbsolute, kBlank, kContact, kSets };

constexpr const char* kContactColumn = "blank_contact_C";

const std::vector<double> kTimeLags = {20, 80, 320};
const std::vector<double> kSensorLags = {20, 80};

// First-order lag of column x (exact for x held over a step), starting at its first value.
Eigen::VectorXd CeilingLag(const Eigen::VectorXd& x, const std::vector<double>& t, double tau) {
  Eigen::VectorXd y(x.size());
  for (Eigen::Index k = 0; k < x.size(); ++k)
    y(k) = k == 0 ? x(0)
                  : y(k - 1) + (1 - std::exp(-(t[k] - t[k - 1]) / tau)) * (x(k - 1) - y(k - 1));
  return y;
}

// The feature matrix of a set on one (averaged) control log, samples x features.
Eigen::MatrixXd CeilingFeatures(int set, const drift::Run& log) {
  std::vector<Eigen::VectorXd> cols;
  const auto& t = log.time_min;
  const bool absolute = set == kAbsolute || set == kBlank || set == kContact;
  if (set == kTime || set == kTimeDuty || absolute) {
    std::vector<std::string> inputs = {"power_on"};
    if (set != kTime) inputs.insert(inputs.end(), {"ring_on", "cutting", "ring_load_pct",
                                                   "z_speed_mm_min"});
    for (const std::string& name : inputs) {
      Eigen::VectorXd x = log.other.col(log.OtherIndex(name));
      if (name == "power_on") x(0) = 0;  // the power-on row: the lag starts from 0
      for (double tau : kTimeLags) cols.push_back(CeilingLag(x, t, tau));
    }
  }
  if (set == kJoint || absolute)
    for (Eigen::Index s = 0; s < log.temperature_C.cols(); ++s) {
      if (log.sensor_names[static_cast<std::size_t>(s)] == kContactColumn) continue;
      Eigen::VectorXd x = log.temperature_C.col(s);
      x.array() -= set == kJoint ? x(0) : 20.0;
      cols.push_back(x);
      for (double tau : kSensorLags) cols.push_back(CeilingLag(x, t, tau));
    }
  Eigen::MatrixXd f(log.samples(), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t j = 0; j < cols.size(); ++j) f.col(static_cast<Eigen::Index>(j)) = cols[j];
  return f;
}

// One row of the 840D form: [1, x] for the offset, [1, x, B - 20] x (z_ref - z) / 1000.
struct DesignRow {
  Eigen::VectorXd x;
  double slope_arm = 0, blank_k = 0, target_um = 0;  // blank_k: B - 20 of the set
  int cut = 0;  // the training cut it belongs to (rows of a cut are consecutive)
};

struct CeilingModel {
  Eigen::VectorXd a, g;  // a: 1 + p, g: 1 + p (+ 1 for the blank)
  bool blank = false;
};

CeilingModel FitCeiling(const std::vector<DesignRow>& rows, bool blank) {
  const Eigen::Index p = rows.empty() ? 0 : rows.front().x.size();
  const Eigen::Index n = static_cast<Eigen::Index>(rows.size());
  const Eigen::Index q = 2 * (1 + p) + (blank ? 1 : 0);
  Eigen::MatrixXd X(n, q);
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const DesignRow& r = rows[static_cast<std::size_t>(i)];
    X(i, 0) = 1;
    X.block(i, 1, 1, p) = r.x.transpose();
    X(i, 1 + p) = r.slope_arm;
    X.block(i, 2 + p, 1, p) = r.x.transpose() * r.slope_arm;
    if (blank) X(i, q - 1) = r.blank_k * r.slope_arm;
    y(i) = r.target_um;
  }
  // Against the cut's first row: a lead holds only what changes along its cut (the level of m at
  // the cut start drops out), so the fit explains exactly that.
  for (Eigen::Index i = n - 1, first = n - 1; i >= 0; --i) {
    first = i;
    while (first > 0 && rows[static_cast<std::size_t>(first - 1)].cut ==
                            rows[static_cast<std::size_t>(i)].cut)
      --first;
    X.row(i) -= X.row(first);
    y(i) -= y(first);
  }
  Eigen::VectorXd scale = X.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < q; ++j) scale(j) = scale(j) > 0 ? scale(j) : 1;
  const Eigen::MatrixXd Xs = X * scale.cwiseInverse().asDiagonal();
  // Ridge 1e-8 by an augmented least-squares problem solved by QR (the normal equations square
  // the condition number of collinear temperature columns); the intercepts are not shrunk.
  Eigen::MatrixXd ridge = 1e-4 * Eigen::MatrixXd::Identity(q, q);
  ridge(0, 0) = ridge(1 + p, 1 + p) = 0;
  Eigen::MatrixXd aug(n + q, q);
  aug << Xs, ridge;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + q);
  rhs.head(n) = y;
  const Eigen::VectorXd beta =
      scale.cwiseInverse().asDiagonal() * aug.colPivHouseholderQr().solve(rhs);
  CeilingModel m;
  m.blank = blank;
  m.a = beta.head(1 + p);
  m.g = beta.segment(1 + p, 1 + p);
  if (blank) m.g.conservativeResize(2 + p), m.g(1 + p) = beta(q - 1);
  return m;
}

// The model held over a day's log; the blank term latched from the cut's true start temperature.
HeldSamples HoldCeiling(const CeilingModel& m, const drift::Run& log, const Eigen::MatrixXd& f,
                        double blank_c) {
  HeldSamples h;
  h.time_min = log.time_min;
  const Eigen::Index p = f.cols();
  for (Eigen::Index k = 0; k < f.rows(); ++k) {
    h.k0_um.push_back(m.a(0) + (p ? m.a.tail(p).dot(f.row(k).transpose()) : 0.0));
    h.slope_um_per_1000.push_back(m.g(0) + (p ? m.g.segment(1, p).dot(f.row(k).transpose()) : 0.0));
    if (m.blank) h.blank_slope_um_per_1000.push_back(m.g(1 + p) * (blank_c - 20));
  }
  return h;
}

// The day's control log as the evaluation's control has it.
drift::Run CeilingLog(const machine::MachineTimeline& tl, int day, const FieldProtocol& p) {
  return AverageSensors(machine::ControlLog(tl, day, MixSeed(tl.Day(day).seed, 0x63746c)),
                        p.sensor_average_min);
}

struct CutTruth {
  std::vector<machine::TruthSample> m;
  double start_min = 0, blank_c = 20;
  ElongationCurve curve;  // the machine's total along the cut, t_s from the cut start
};

CutTruth TruthOf(const machine::MachineTimeline& tl, const machine::CutRef& cut) {
  CutTruth c;
  const machine::Job& job = tl.Day(cut.day).jobs[static_cast<std::size_t>(cut.job)];
  c.start_min = cut.day * 1440.0 + job.cut_start_min;
  c.blank_c = machine::HallDuringCut(tl, cut).start_c;
  c.m = machine::TrueCutError(tl, cut);
  for (const machine::TruthSample& s : c.m) {
    c.curve.time_s.push_back(60.0 * (s.abs_min - c.start_min));
    c.curve.elongation_um.push_back(s.total_um());
  }
  return c;
}

bool HasContact(const drift::Run& log) {
  for (const auto& n : log.sensor_names)
    if (n == kContactColumn) return true;
  return false;
}

// The blank's temperature a set latches at the cut start: the truth (+blank) or the contact
// reading at the cut start's control sample (+contact); 20 otherwise.
double SetBlankC(int set, const CutTruth& c, const drift::Run& log) {
  if (set == kBlank) return c.blank_c;
  if (set != kContact || !HasContact(log)) return 20;
  const auto it = std::upper_bound(log.time_min.begin(), log.time_min.end(), c.start_min + 1e-9);
  const Eigen::Index k = std::max<Eigen::Index>(0, it - log.time_min.begin() - 1);
  return log.temperature_C(k, log.SensorIndex(kContactColumn));
}

// Training rows of every past production day's cuts, per feature set.
std::vector<std::vector<DesignRow>> TrainingRows(const machine::MachineTimeline& tl,
                                                 const FieldProtocol& p, double z_ref,
                                                 double step_min) {
  std::vector<std::vector<DesignRow>> rows(kSets);
  int cut = 0;
  for (const machine::DayPlan& plan : tl.days()) {
    if (plan.day >= 0 || plan.role != machine::DayRole::kHistory) continue;
    const drift::Run log = CeilingLog(tl, plan.day, p);
    std::vector<Eigen::MatrixXd> f;
    for (int s = 0; s < kSets; ++s) f.push_back(CeilingFeatures(s, log));
    for (int j = 0; j < static_cast<int>(plan.jobs.size()); ++j) {
      const CutTruth c = TruthOf(tl, {plan.day, j});
      double next = c.start_min;
      ++cut;
      for (const machine::TruthSample& s : c.m) {
        if (s.abs_min + 1e-9 < next) continue;
        next += step_min;
        const auto it = std::upper_bound(log.time_min.begin(), log.time_min.end(), s.abs_min + 1e-9);
        const Eigen::Index k = std::max<Eigen::Index>(0, it - log.time_min.begin() - 1);
        for (int set = 0; set < kSets; ++set)
          rows[static_cast<std::size_t>(set)].push_back(
              {f[static_cast<std::size_t>(set)].row(k).transpose(), (z_ref - s.z_mm) / 1000.0,
               SetBlankC(set, c, log) - 20, s.total_um(), cut});
      }
    }
  }
  return rows;
}

// The shop's record of the last `keep` past production days (and the calendar's tests).
ShopModels TrainShop(const machine::MachineTimeline& tl, const FieldProtocol& p,
                     const WorkpieceResidual& residual, std::uint64_t machine_seed, int keep,
                     double z_ref) {
  std::vector<int> history;
  for (const machine::DayPlan& plan : tl.days())
    if (plan.role == machine::DayRole::kHistory) history.push_back(plan.day);
  const std::set<int> kept(history.end() - std::min<std::ptrdiff_t>(keep, history.size()),
                           history.end());
  auto only_kept = [&](const machine::Job& j, const machine::CutRef& cut)
      -> std::function<double(double)> {
    if (!kept.count(cut.day)) return nullptr;
    return residual(j, cut);
  };
  drift::ShopRecord rec = FieldShopRecord(tl, p, only_kept, ShopRecordSeed(machine_seed));
  std::vector<drift::MeasurementRecord> records;
  for (auto& r : rec.records)
    if (r.kind == drift::MeasurementRecord::Kind::kProbe ||
        r.kind == drift::MeasurementRecord::Kind::kLaser || kept.count(r.day))
      records.push_back(std::move(r));
  rec.records = std::move(records);
  return FitShopModels(rec, z_ref, ScheduleInputs());
}

constexpr const char* kTrueBlankColumn = "blank_true_C";
constexpr double kExactLatchTauMin = 1e-3;  // a lag that follows its input within one sample

// The log with a column of the blank's TRUE temperature at the start of the next cut (of the
// day's cuts the first starting at or after the sample; the last one's after it): a grey box
// reading it through a lag of kExactLatchTauMin latches the exact value at each cut start.
drift::Run WithTrueBlank(drift::Run log, const machine::MachineTimeline& tl, int day) {
  const machine::DayPlan& plan = tl.Day(day);
  std::vector<std::pair<double, double>> starts;  // (abs min, degC), in cut-start order
  for (int j = 0; j < static_cast<int>(plan.jobs.size()); ++j)
    starts.push_back({day * 1440.0 + plan.jobs[static_cast<std::size_t>(j)].cut_start_min,
                      machine::HallDuringCut(tl, {day, j}).start_c});
  std::sort(starts.begin(), starts.end());
  Eigen::VectorXd col = Eigen::VectorXd::Constant(log.samples(), 20.0);
  for (int k = 0; k < log.samples(); ++k) {
    const double t = log.time_min[static_cast<std::size_t>(k)];
    for (const auto& [start, c] : starts) {
      col(k) = c;
      if (start >= t - 1e-9) break;
    }
  }
  log.sensor_names.push_back(kTrueBlankColumn);
  log.temperature_C.conservativeResize(Eigen::NoChange, log.temperature_C.cols() + 1);
  log.temperature_C.col(log.temperature_C.cols() - 1) = col;
  return log;
}

// The exact truth as a shop record: one lead record per cut of every past production day (a
// reading m(t, z) every step_min along the cut, sigma 1 um), on the ceiling's control logs with
// the true blank column (WithTrueBlank).
drift::ShopRecord TruthRecord(const machine::MachineTimeline& tl, const FieldProtocol& p,
                              double step_min) {
  drift::ShopRecord rec;
  for (const machine::DayPlan& plan : tl.days()) {
    if (plan.day >= 0 || plan.role != machine::DayRole::kHistory) continue;
    const int li = static_cast<int>(rec.day_logs.size());
    rec.day_logs.push_back(WithTrueBlank(CeilingLog(tl, plan.day, p), tl, plan.day));
    const drift::Run& log = rec.day_logs.back();
    for (int j = 0; j < static_cast<int>(plan.jobs.size()); ++j) {
      drift::MeasurementRecord r;
      r.kind = drift::MeasurementRecord::Kind::kLead;
      r.day = plan.day;
      r.log = li;
      r.name = "day" + std::to_string(plan.day) + "_truth_" + std::to_string(j);
      double next = -1e300;
      for (const machine::TruthSample& s : TruthOf(tl, {plan.day, j}).m) {
        if (s.abs_min + 1e-9 < next) continue;
        next = s.abs_min + step_min;
        const auto it =
            std::upper_bound(log.time_min.begin(), log.time_min.end(), s.abs_min + 1e-9);
        const int k = std::max(0, static_cast<int>(it - log.time_min.begin()) - 1);
        r.rows.push_back({k, s.abs_min, s.z_mm, s.total_um(), 1.0});
      }
      if (r.rows.size() > 1) rec.records.push_back(std::move(r));
    }
  }
  return rec;
}

// The record's last `keep` days (records and their logs kept as they are).
drift::ShopRecord LastDays(drift::ShopRecord rec, int keep) {
  std::set<int> days;
  for (const auto& r : rec.records) days.insert(r.day);
  std::set<int> kept(std::prev(days.end(), std::min<std::ptrdiff_t>(keep, days.size())),
                     days.end());
  std::vector<drift::MeasurementRecord> out;
  for (auto& r : rec.records)
    if (kept.count(r.day)) out.push_back(std::move(r));
  rec.records = std::move(out);
  return rec;
}

// The grey boxes of CeilingGreyColumns, trained on the truth record.
std::vector<drift::GreyBoxModel> GreyOnTruth(const drift::ShopRecord& truth, double z_ref,
                                             int last_days) {
  const drift::GreyBoxSpec field = FieldGreyBoxSpec(z_ref, false);
  const drift::GreyBoxOptions options = FieldGreyBoxOptions(false, false);
  drift::GreyBoxSpec exact = field;
  exact.blank_sensor = kTrueBlankColumn;
  drift::GreyBoxOptions exact_options = options;
  exact_options.blank_tau_grid = {kExactLatchTauMin};
  drift::GreyBoxSpec all = field;
  all.offset_sensors.clear();
  for (const std::string& s : truth.day_logs.front().sensor_names)
    if (s != kTrueBlankColumn && s != kContactColumn) all.offset_sensors.push_back(s);
  all.slope_sensors = all.offset_sensors;
  return {drift::FitGreyBox(truth, field, options), drift::FitGreyBox(truth, exact, exact_options),
          drift::FitGreyBox(truth, all, options),
          drift::FitGreyBox(LastDays(truth, last_days), field, options)};
}

// The grey box's blank estimate B [degC] latched at the cut start (its evaluator run from the
// log's first row to the latest sample at or before the start); NaN for a model with no input.
double LatchedBlankC(const drift::GreyBoxModel& m, const drift::Run& log, double start_min) {
  if (m.Inputs().empty()) return std::nan("");
  drift::GreyBoxEvaluator ev(m);
  const Eigen::MatrixXd u = drift::GreyBoxRawInputs(m, log);
  double b = 20;
  for (int k = 0;
       k < log.samples() && log.time_min[static_cast<std::size_t>(k)] <= start_min + 1e-9; ++k)
    b = ev.Step(log.time_min[static_cast<std::size_t>(k)], u.row(k).transpose()).blank_c;
  return b;
}

std::vector<CeilingCut> CeilingMachine(const machine::MachineScenario& scenario,
                                       const workpiece::WorkpieceModel& model,
                                       const compare::ExperienceRule& rule,
                                       const lead::IsoToleranceTable& iso, const CeilingOptions& o,
                                       std::uint64_t seed, int index) {
  const FieldEvalOptions& f = o.field;
  const machine::MachineWorld w =
      machine::BuildMachineWorld(f.machine, scenario, seed, index, f.calendar, f.timeline);
  const machine::MachineTimeline& tl = w.timeline;
  const double z_ref = tl.machine().config().z.fixed_end_mm;
  const auto rows = TrainingRows(tl, f.protocol, z_ref, o.row_step_min);
  std::vector<CeilingModel> models;
  for (int s = 0; s < kSets; ++s)
    models.push_back(FitCeiling(rows[static_cast<std::size_t>(s)], s == kBlank || s == kContact));
  const bool contact = f.machine.blank_contact_std_k >= 0;
  const ShopModels shop =
      TrainShop(tl, f.protocol, FieldHistoryResidual(tl, model, rule, iso, f.compare),
                w.machine_seed, o.estimator_past_days, z_ref);
  const std::vector<drift::GreyBoxModel> grey =
      o.grey_structure
          ? GreyOnTruth(TruthRecord(tl, f.protocol, o.row_step_min), z_ref, o.estimator_past_days)
          : std::vector<drift::GreyBoxModel>{};
  std::vector<CeilingCut> out;
  for (const machine::DayPlan& plan : tl.days()) {
    if (plan.day < 0) continue;
    const drift::Run log = CeilingLog(tl, plan.day, f.protocol);
    std::vector<Eigen::MatrixXd> feats;
    for (int s = 0; s < kSets; ++s) feats.push_back(CeilingFeatures(s, log));
    const HeldSamples est[] = {RunCausally(shop.warmup, log), RunCausally(shop.schedule, log),
                               RunCausally(shop.sensors, log), RunCausally(shop.grey, log)};
    const drift::Run blank_log = o.grey_structure ? WithTrueBlank(log, tl, plan.day) : log;
    std::vector<HeldSamples> grey_held;
    for (const drift::GreyBoxModel& g : grey) grey_held.push_back(RunCausally(g, blank_log));
    for (int j = 0; j < static_cast<int>(plan.jobs.size()); ++j) {
      const machine::Job& job = plan.jobs[static_cast<std::size_t>(j)];
      const CutTruth c = TruthOf(tl, {plan.day, j});
      const screw::Kinematics k = job.kinematics;
      auto z_of_t = [k](double t) {
        return k.thread_start_position_mm - k.axial_feed_mm_s * std::min(t, k.cutting_time_s);
      };
      auto total = [&](const compare::CompensationFunction& comp) {
        return detail::TotalOf(c.curve, comp, k.axial_feed_mm_s, job.screw, f.compare);
      };
      CeilingCut cut{index, plan.day, j, {}, {}, {}, {}};
      try {
        for (int s = 0; s < kSets; ++s)
          cut.ceiling_um.push_back(
              s == kContact && !contact
                  ? std::nan("")
                  : total(CausalMachineLine(HoldCeiling(models[static_cast<std::size_t>(s)], log,
                                                        feats[static_cast<std::size_t>(s)],
                                                        SetBlankC(s, c, log)),
                                            c.start_min, z_ref, z_of_t)));
        cut.estimator_um.push_back(total(compare::NoCompensation()));
        for (const HeldSamples& h : est)
          cut.estimator_um.push_back(total(CausalMachineLine(h, c.start_min, z_ref, z_of_t)));
        for (const HeldSamples& h : grey_held)
          cut.grey_um.push_back(total(CausalMachineLine(h, c.start_min, z_ref, z_of_t)));
        if (o.grey_structure)
          for (const drift::GreyBoxModel* g : {&shop.grey, &grey[0], &grey[1]})
            cut.blank_error_k.push_back(LatchedBlankC(*g, blank_log, c.start_min) - c.blank_c);
      } catch (const InputError&) {
        continue;  // a cut the lead metrics cannot score (too short a thread)
      }
      out.push_back(std::move(cut));
    }
  }
  return out;
}

/// The median of the finite values (NaN if there are none).
double CeilingMedian(const std::vector<double>& all) {
  std::vector<double> v;
  for (double x : all)
    if (std::isfinite(x)) v.push_back(x);
  return v.empty() ? std::nan("") : Median(std::move(v));
}

/// Per column j < columns: the median over the cuts of (cut.*field)[j].
std::vector<double> ColumnMedians(const std::vector<CeilingCut>& cuts,
                                  std::vector<double> CeilingCut::*field, std::size_t columns) {
  std::vector<double> out;
  for (std::size_t j = 0; j < columns; ++j) {
    std::vector<double> v;
    for (const CeilingCut& c : cuts) v.push_back((c.*field)[j]);
    out.push_back(CeilingMedian(v));
  }
  return out;
}

}  // namespace

std::vector<std::string> CeilingFeatureSets() {
  return {"none", "time", "time+duty", "joint", "absolute", "+blank", "+contact"};
}

std::vector<std::string> CeilingGreyColumns() {
  return {"grey truth", "grey truth blank", "grey truth all", "grey truth last"};
}

std::vector<std::string> CeilingBlankModels() { return {"shop", "truth", "truth blank"}; }

std::vector<std::string> CeilingEstimators() {
  return {"uncompensated", "warmup", "schedule", "sensors", "grey"};
}

CeilingScenario EvaluateCeiling(const machine::MachineScenario& scenario,
                                const workpiece::WorkpieceModel& model,
                                const compare::ExperienceRule& rule,
                                const lead::IsoToleranceTable& iso_table,
                                const CeilingOptions& o, int seeds,
                                const compare::EvaluateProgress& progress) {
  detail::CheckCount(seeds, 1, 20, "seeds");
  detail::CheckCount(o.estimator_past_days, 1, o.field.calendar.past_days, "estimator past days");
  if (!(o.row_step_min >= 0.1 && o.row_step_min <= 30))
    throw InputError("row step " + std::to_string(o.row_step_min) + " min: must be within 0.1..30");
  o.field.machine.Validate("field machine '" + o.field.machine.name + "'");
  CeilingScenario out;
  out.scenario = scenario.name;
  const std::size_t n = static_cast<std::size_t>(o.field.machines);
  for (int s = 0; s < seeds; ++s) {
    const std::uint64_t seed = o.field.seed + static_cast<std::uint64_t>(s);
    out.seeds.push_back(seed);
    std::vector<std::vector<CeilingCut>> per(n);
    ParallelFor(
        n, o.field.threads,
        [&](std::size_t i) {
          per[i] = CeilingMachine(scenario, model, rule, iso_table, o, seed, static_cast<int>(i));
        },
        [&](std::size_t done, std::size_t) {
          if (progress) progress(s * n + done, seeds * n);
        });
    for (auto& p : per) out.cuts.insert(out.cuts.end(), p.begin(), p.end());
  }
  out.ceiling_median_um =
      ColumnMedians(out.cuts, &CeilingCut::ceiling_um, CeilingFeatureSets().size());
  out.estimator_median_um =
      ColumnMedians(out.cuts, &CeilingCut::estimator_um, CeilingEstimators().size());
  if (!o.grey_structure) return out;
  out.grey_median_um = ColumnMedians(out.cuts, &CeilingCut::grey_um, CeilingGreyColumns().size());
  for (std::size_t j = 0; j < CeilingBlankModels().size(); ++j) {
    std::vector<double> v;
    for (const CeilingCut& c : out.cuts)
      if (std::isfinite(c.blank_error_k[j])) v.push_back(std::abs(c.blank_error_k[j]));
    std::sort(v.begin(), v.end());
    out.blank_error_median_k.push_back(CeilingMedian(v));
    out.blank_error_p95_k.push_back(
        v.empty() ? std::nan("")
                  : v[std::min(v.size() - 1, static_cast<std::size_t>(0.95 * v.size()))]);
  }
  return out;
}

namespace {

// One table cell of a median in um: " 4.2 |", or " - |" where there is none.
std::string TableCell(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, std::isfinite(v) ? " %.1f |" : " - |", v);
  return buf;
}

}  // namespace

std::string FormatCeilingTable(const std::vector<CeilingScenario>& rows) {
  std::string s = "| scenario | cuts |";
  for (const auto& c : CeilingFeatureSets()) s += " " + c + " |";
  for (const auto& c : CeilingEstimators()) s += " " + c + " |";
  s += " best sensor-free |\n|---|---|";
  for (std::size_t i = 0; i < CeilingFeatureSets().size() + CeilingEstimators().size() + 1; ++i)
    s += "---|";
  s += "\n";
  char buf[32];
  for (const CeilingScenario& r : rows) {
    s += "| " + r.scenario + " | " + std::to_string(r.cuts.size()) + " |";
    auto cell = [&](double v) { s += TableCell(v); };
    for (double v : r.ceiling_median_um) cell(v);
    for (double v : r.estimator_median_um) cell(v);
    std::snprintf(
        buf, sizeof buf, " %.1f |\n",
        std::min({r.estimator_median_um[0], r.estimator_median_um[1], r.estimator_median_um[2]}));
    s += buf;
  }
  return s;
}

std::string FormatGreyStructureTable(const std::vector<CeilingScenario>& rows) {
  std::string s = "| scenario | cuts | absolute | +blank |";
  for (const auto& c : CeilingGreyColumns()) s += " " + c + " |";
  s += " grey (shop) | structure gap | data gap |";
  for (const auto& b : CeilingBlankModels()) s += " |B - true| " + b + " (K) |";
  s += "\n|---|---|";
  for (std::size_t i = 0; i < CeilingGreyColumns().size() + CeilingBlankModels().size() + 5; ++i)
    s += "---|";
  s += "\n";
  char buf[64];
  const std::size_t absolute = 4, blank = 5, shop_grey = 4;  // CeilingFeatureSets / Estimators
  for (const CeilingScenario& r : rows) {
    if (r.grey_median_um.empty()) continue;
    s += "| " + r.scenario + " | " + std::to_string(r.cuts.size()) + " |";
    auto cell = [&](double v) { s += TableCell(v); };
    cell(r.ceiling_median_um[absolute]);
    cell(r.ceiling_median_um[blank]);
    for (double v : r.grey_median_um) cell(v);
    cell(r.estimator_median_um[shop_grey]);
    cell(r.grey_median_um[0] - r.ceiling_median_um[absolute]);
    cell(r.estimator_median_um[shop_grey] - r.grey_median_um[0]);
    for (std::size_t j = 0; j < r.blank_error_median_k.size(); ++j) {
      std::snprintf(buf, sizeof buf, " %.2f / %.2f |", r.blank_error_median_k[j],
                    r.blank_error_p95_k[j]);
      s += buf;
    }
    s += "\n";
  }
  return s;
}

}  // namespace whirl::machine_eval
