// The streamed drift commands (drift/stream.h): prediction of a run file in blocks.
#include "drift/stream.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/numbers.h"

namespace whirl::drift {

PredictionSummary Summarize(const RunPrediction& p) {
  PredictionSummary s;
  s.run = p.run;
  s.samples = p.predicted_um.size();
  s.time_from_index = p.time_from_index;
  if (s.samples > 0) {
    s.predicted_min_um = p.predicted_um.minCoeff();
    s.predicted_max_um = p.predicted_um.maxCoeff();
  }
  s.has_measured = p.has_measured;
  if (p.has_measured) {
    s.residual = ComputeErrorStats(p.measured_um - p.predicted_um);
    s.none = ComputeErrorStats(p.measured_um);
  }
  s.outside_range_samples = p.outside_range_samples;
  s.beyond_trained_time_samples = p.beyond_trained_time_samples;
  s.warnings = p.warnings;
  return s;
}

PredictionSummary PredictFile(const DriftModel& model, const std::filesystem::path& path,
                              ReferenceMode reference,
                              const std::function<void(const PredictedSample&)>& sink,
                              const StreamProgress& progress, const RunScan* scanned) {
  const RunScan scan = scanned ? *scanned : ScanRun(path);
  RunReader reader(path, RunState::kUnknown, scan.time_from_index);
  const RunLayout& l = reader.layout();
  RunPredictor predictor(model, scan.time_from_index, l.source, reference);
  const InputColumns cols = ModelInputColumns(model, l.sensor_names, l.other_names, l.source);
  const auto& errors = l.error_names;
  const auto at = std::find(errors.begin(), errors.end(), model.error_column);
  PredictionSummary s;
  s.run = l.name;
  s.time_from_index = scan.time_from_index;
  s.has_measured = at != errors.end();
  const Eigen::Index e = at - errors.begin();
  if (model.zero.zero == ErrorZero::kFixed && !std::isfinite(model.zero.gauge_level_um))
    throw InputError(l.source + ": error zero 'fixed' needs a finite gauge level [um]");
  ErrorStatsAccumulator residual, none;
  double zero = NAN;  // the measured error's zero (ApplyErrorZero)
  s.predicted_min_um = std::numeric_limits<double>::infinity();
  s.predicted_max_um = -s.predicted_min_um;
  Eigen::VectorXd raw(static_cast<Eigen::Index>(cols.sensors.size() + cols.extras.size()));
  RunRows b;
  PredictedSample p;
  const std::string step = "predicting " + l.source;
  while (reader.Read(&b)) {
    for (int k = 0; k < b.count; ++k) {
      Eigen::Index c = 0;
      for (const int j : cols.sensors) raw(c++) = b.temperature_C(k, j);
      for (const int j : cols.extras) raw(c++) = b.other(k, j);
      p.index = b.first + k;
      p.time = b.time_min[static_cast<std::size_t>(k)];
      p.predicted_um = predictor.Step(p.time, raw);
      p.std_um = predictor.StdDev();
      s.predicted_min_um = std::min(s.predicted_min_um, p.predicted_um);
      s.predicted_max_um = std::max(s.predicted_max_um, p.predicted_um);
      p.has_measured = s.has_measured;
      if (s.has_measured) {
        const double v = b.error_um(k, e);
        if (std::isnan(zero))
          zero = model.zero.zero == ErrorZero::kRunStart ? v
                 : model.zero.zero == ErrorZero::kFixed  ? model.zero.gauge_level_um
                                                         : 0.0;
        p.measured_um = v - zero;
        residual.Add(p.measured_um - p.predicted_um);
        none.Add(p.measured_um);
      }
      if (sink) sink(p);
    }
    if (progress) progress(step, reader.rows(), reader.fraction_read());
  }
  if (reader.rows() != scan.rows)
    throw InputError(l.source + ": " + std::to_string(reader.rows()) + " rows, but " +
                     std::to_string(scan.rows) + " when it was scanned (did the file change?)");
  s.samples = reader.rows();
  if (s.has_measured) {
    s.residual = residual.Stats();
    s.none = none.Stats();
  }
  s.outside_range_samples = predictor.outside_range_samples();
  s.beyond_trained_time_samples = predictor.beyond_trained_time_samples();
  s.warnings = predictor.Warnings(s.run, s.samples, s.has_measured);
  return s;
}

namespace {

// One run file's evenly thinned sample (FitFiles' first pass): the rows of in-run index
// 0, s, 2s, ... with s the sampler's stride, and the step before each at full resolution.
struct SampledRun {
  RunLayout layout;
  std::vector<long long> index;
  std::vector<double> time, step;  // [min]; NaN: a missing time cell (the axis is decided later)
  std::vector<int> lines;
  std::vector<double> temps, errors, others;  // row-major
  long long rows = 0;
  bool missing = false;
  double first_time = NAN, previous_time = NAN;

  std::size_t kept() const { return index.size(); }

  // Keeps the entries whose index is a multiple of `stride`.
  void Thin(long long stride) {
    std::size_t out = 0;
    const auto width = [](const std::vector<double>& v, std::size_t n) { return n ? v.size() / n : 0; };
    const std::size_t n = kept();
    const std::size_t wt = width(temps, n), we = width(errors, n), wo = width(others, n);
    for (std::size_t i = 0; i < n; ++i) {
      if (index[i] % stride != 0) continue;
      index[out] = index[i];
      time[out] = time[i];
      step[out] = step[i];
      lines[out] = lines[i];
      std::copy_n(temps.begin() + static_cast<std::ptrdiff_t>(i * wt), wt,
                  temps.begin() + static_cast<std::ptrdiff_t>(out * wt));
      std::copy_n(errors.begin() + static_cast<std::ptrdiff_t>(i * we), we,
                  errors.begin() + static_cast<std::ptrdiff_t>(out * we));
      std::copy_n(others.begin() + static_cast<std::ptrdiff_t>(i * wo), wo,
                  others.begin() + static_cast<std::ptrdiff_t>(out * wo));
      ++out;
    }
    index.resize(out), time.resize(out), step.resize(out), lines.resize(out);
    temps.resize(out * wt), errors.resize(out * we), others.resize(out * wo);
  }

  bool time_from_index() const { return layout.time_column.empty() || missing; }

  // The sampled rows as a Run (times: the row index in the run without recorded time).
  Run ToRun() const {
    Run r = layout.EmptyRun();
    r.line_numbers = lines;
    r.time_from_index = time_from_index();
    r.time_min.resize(kept());
    for (std::size_t i = 0; i < kept(); ++i)
      r.time_min[i] = r.time_from_index ? static_cast<double>(index[i]) : time[i];
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    const auto n = static_cast<Eigen::Index>(kept());
    const auto matrix = [&](const std::vector<double>& v, std::size_t cols) {
      return Eigen::MatrixXd(Eigen::Map<const RowMajor>(v.data(), n, static_cast<Eigen::Index>(cols)));
    };
    r.temperature_C = matrix(temps, layout.sensor_names.size());
    r.error_um = matrix(errors, layout.error_names.size());
    r.other = matrix(others, layout.other_names.size());
    return r;
  }
};

// FitFiles' first pass: every file once, into the thinned sample and the rises' moments.
class Sampler {
 public:
  Sampler(const std::vector<RunFile>& files, const StreamProgress& progress)
      : files_(files), progress_(progress) {}

  void Run() {
    for (const RunFile& f : files_) ReadOne(f);
  }

  long long stride() const { return stride_; }
  long long rows() const {
    long long n = 0;
    for (const SampledRun& r : runs_) n += r.rows;
    return n;
  }
  long long kept() const { return kept_; }
  const std::vector<SampledRun>& runs() const { return runs_; }
  const SelectionMoments& moments() const { return moments_; }

  // The logs' sampling step: the median of the full-resolution steps before the sampled rows
  // (1 sample on runs without recorded time).
  double SamplingStep() const {
    std::vector<double> steps;
    for (const SampledRun& r : runs_)
      for (std::size_t i = 0; i < r.kept(); ++i)
        if (r.time_from_index())
          steps.push_back(1.0);
        else if (std::isfinite(r.step[i]))
          steps.push_back(r.step[i]);
    if (steps.empty()) return NAN;
    std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2),
                     steps.end());
    return steps[steps.size() / 2];
  }

 private:
  void ReadOne(const RunFile& f) {
    RunReader reader(f.path, f.state, std::nullopt);
    runs_.push_back(SampledRun{});
    SampledRun& r = runs_.back();
    r.layout = reader.layout();
    if (runs_.size() == 1) {
      // The sample's budget: kSearchSampleCells over the file's columns, within the row bounds.
      const auto cols = static_cast<long long>(r.layout.columns);
      capacity_ = std::clamp(kSearchSampleCells / std::max(1LL, cols), kMinSearchRows,
                             kMaxSearchRows);
    } else if (r.layout.sensor_names != runs_.front().layout.sensor_names) {
      throw InputError(r.layout.source + ": its temperature columns differ from " +
                       runs_.front().layout.source + "'s (runs must log the same sensors)");
    }
    const std::string step = "reading " + r.layout.source;
    RunRows b;
    Eigen::VectorXd first;
    while (reader.Read(&b)) {
      if (first.size() == 0) first = b.temperature_C.row(0).transpose();
      moments_.Add(b.temperature_C.rowwise() - first.transpose());
      for (int k = 0; k < b.count; ++k) Keep(r, b, k);
      r.rows = reader.rows();
      if (progress_) progress_(step, reader.rows(), reader.fraction_read());
    }
    r.missing = reader.time_missing();
  }

  void Keep(SampledRun& r, const RunRows& b, int k) {
    const long long i = b.first + k;
    const double t = b.time_min[static_cast<std::size_t>(k)];
    const double step = t - r.previous_time;
    r.previous_time = t;
    if (i % stride_ != 0) return;
    r.index.push_back(i);
    r.time.push_back(t);
    r.step.push_back(step);
    r.lines.push_back(b.line_numbers[static_cast<std::size_t>(k)]);
    for (Eigen::Index j = 0; j < b.temperature_C.cols(); ++j) r.temps.push_back(b.temperature_C(k, j));
    for (Eigen::Index j = 0; j < b.error_um.cols(); ++j) r.errors.push_back(b.error_um(k, j));
    for (Eigen::Index j = 0; j < b.other.cols(); ++j) r.others.push_back(b.other(k, j));
    if (++kept_ <= capacity_) return;
    stride_ *= 2;  // every other kept row of every run goes
    kept_ = 0;
    for (SampledRun& each : runs_) {
      each.Thin(stride_);
      kept_ += static_cast<long long>(each.kept());
    }
  }

  const std::vector<RunFile>& files_;
  const StreamProgress& progress_;
  std::vector<SampledRun> runs_;
  SelectionMoments moments_;
  long long stride_ = 1, kept_ = 0, capacity_ = kMaxSearchRows;
};

// The chosen model's features of one run row by row (BuildFeatures' recursion, streamed): the
// inputs' rises (or values), their first-order lags, then the elapsed-time terms.
class FeatureStream {
 public:
  FeatureStream(const DriftModel& m, const RunLayout& l) : m_(m) {
    cols_ = ModelInputColumns(m, l.sensor_names, l.other_names, l.source);
    per_ = 1 + static_cast<Eigen::Index>(m.time_constants.size());
    const auto inputs = static_cast<Eigen::Index>(cols_.sensors.size() + cols_.extras.size());
    f_.resize(inputs * per_ + static_cast<Eigen::Index>(m.elapsed_time_constants.size()));
    u_.resize(inputs);
    ref_.resize(static_cast<Eigen::Index>(cols_.sensors.size()));
    a_.resize(m.time_constants.size());
  }

  const Eigen::VectorXd& Step(double t, const RunRows& b, int k) {
    Eigen::Index c = 0;
    for (const int j : cols_.sensors) u_(c++) = b.temperature_C(k, j);
    for (const int j : cols_.extras) u_(c++) = b.other(k, j);
    if (!started_) ref_ = u_.head(ref_.size()), t0_ = t;
    u_.head(ref_.size()) -= ref_;  // rises from the run's first row
    for (std::size_t l = 0; l < a_.size(); ++l)
      a_[l] = started_ ? 1.0 - std::exp(-(t - last_) / m_.time_constants[l]) : 1.0;
    for (Eigen::Index i = 0; i < u_.size(); ++i) {
      f_(i * per_) = u_(i);
      for (std::size_t l = 0; l < a_.size(); ++l) {
        double& y = f_(i * per_ + 1 + static_cast<Eigen::Index>(l));
        y = started_ ? y + a_[l] * (u_(i) - y) : u_(i);
      }
    }
    const auto ne = static_cast<Eigen::Index>(m_.elapsed_time_constants.size());
    for (Eigen::Index l = 0; l < ne; ++l)
      f_(f_.size() - ne + l) =
          1.0 - std::exp(-(t - t0_) / m_.elapsed_time_constants[static_cast<std::size_t>(l)]);
    started_ = true;
    last_ = t;
    return f_;
  }

 private:
  const DriftModel& m_;
  InputColumns cols_;
  Eigen::Index per_ = 1;
  Eigen::VectorXd f_, u_, ref_;
  std::vector<double> a_;
  bool started_ = false;
  double last_ = 0, t0_ = 0;
};

// FitFiles' second pass: the chosen model refitted on every row of the files.
void RefitOnAllRows(const std::vector<RunFile>& files, const std::vector<SampledRun>& sampled,
                    const std::string& error_column, const StreamProgress& progress,
                    FitReport* rep) {
  DriftModel& m = rep->model;
  const auto nf = static_cast<int>(m.features.size());
  StreamingLeastSquares ls(nf);
  ErrorStatsAccumulator y_stats, residual;  // the network's R^2 and residual std
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(nf, std::numeric_limits<double>::infinity());
  Eigen::VectorXd hi = -lo;
  const bool network = m.kind == ModelKind::kNetwork;
  long long total = 0;
  for (std::size_t i = 0; i < files.size(); ++i) {
    RunReader reader(files[i].path, files[i].state, sampled[i].time_from_index());
    const RunLayout& l = reader.layout();
    FeatureStream features(m, l);
    const int e = l.ErrorIndex(error_column);
    double zero = NAN;
    RunRows b;
    const std::string step = "fitting the chosen model on every row of " + l.source;
    while (reader.Read(&b)) {
      for (int k = 0; k < b.count; ++k) {
        const Eigen::VectorXd& f = features.Step(b.time_min[static_cast<std::size_t>(k)], b, k);
        const double v = b.error_um(k, e);
        if (std::isnan(zero))
          zero = m.zero.zero == ErrorZero::kFixed ? m.zero.gauge_level_um : v;  // run-start
        const double y = v - zero;
        lo = lo.cwiseMin(f);
        hi = hi.cwiseMax(f);
        if (network) {
          const double fitted =
              m.target_scaling.Reverse(m.network.Forward(m.input_scaling.Apply(f)))(0, 0);
          residual.Add(y - fitted);
          y_stats.Add(y);
        } else {
          ls.Add(f, y);
        }
      }
      if (progress) progress(step, reader.rows(), reader.fraction_read());
    }
    if (reader.rows() != sampled[i].rows)
      throw InputError(l.source + ": " + std::to_string(reader.rows()) + " rows, but " +
                       std::to_string(sampled[i].rows) +
                       " in the first pass (did the file change while it was read?)");
    total += reader.rows();
  }
  m.feature_min = lo;
  m.feature_max = hi;
  m.training_samples = static_cast<int>(std::min<long long>(total, std::numeric_limits<int>::max()));
  if (network) {
    const ErrorStats r = residual.Stats(), y = y_stats.Stats();
    m.residual_std_um = r.rmse_um;
    const double tss = y.std_um * y.std_um;
    m.r_squared = tss > 0 ? 1.0 - r.rmse_um * r.rmse_um / tss : 1.0;
    return;
  }
  try {
    m.linear = ls.Fit();
  } catch (const InputError& err) {
    std::string names, sources;
    for (const Feature& f : m.features) names += (names.empty() ? "" : ", ") + f.Name(m.time_unit);
    for (const RunFile& f : files) sources += (sources.empty() ? "" : ", ") + f.path.string();
    throw InputError(sources + ": model of " + error_column + " on " + names + ": " + err.what());
  }
  m.residual_std_um = m.linear.residual_std_um;
  m.r_squared = m.linear.r_squared;
}

}  // namespace

FitReport FitFiles(const std::vector<RunFile>& files, const std::string& error_column,
                   const FitOptions& o, const StreamProgress& progress) {
  o.Validate();
  if (files.empty()) throw InputError("fit: no training run");
  Sampler sampler(files, progress);
  sampler.Run();
  std::vector<Run> runs;
  for (const SampledRun& r : sampler.runs()) runs.push_back(r.ToRun());
  if (sampler.stride() == 1) return FitDriftModel(runs, error_column, o);  // nothing thinned
  FitOptions thinned = o;
  thinned.sampling_step = sampler.SamplingStep();
  thinned.all_rows = std::make_shared<const SelectionMoments>(sampler.moments());
  if (progress) progress("searching on the thinned sample", sampler.kept(), NAN);
  FitReport rep = FitDriftModel(runs, error_column, thinned);
  runs.clear();
  if (rep.blended) {  // a blend of two fits is not one least-squares fit: kept as searched
    rep.model.notes.push_back("a blend (drift/fit.h FitOptions::dynamic_share): coefficients, "
                              "residual std, R^2 and ranges from the evenly thinned sample of " +
                              std::to_string(sampler.kept()) + " of " +
                              std::to_string(sampler.rows()) + " rows");
    return rep;
  }
  RefitOnAllRows(files, sampler.runs(), error_column, progress, &rep);
  rep.model.notes.push_back(
      "search (selection, candidates, time constants) on an evenly thinned sample: " +
      std::to_string(sampler.kept()) + " of " + std::to_string(sampler.rows()) +
      " rows (every " + std::to_string(sampler.stride()) +
      "th row of each run from its first; the selection's screen, similarity and F test from "
      "every row); coefficients, residual std, R^2 and ranges from all " +
      std::to_string(sampler.rows()) + " rows");
  return rep;
}

}  // namespace whirl::drift
