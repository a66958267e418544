#include "drift/report.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <sstream>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/decimate.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/plot_style.h"
#include "core/report_render.h"
#include "core/safe_text.h"
#include "drift/documents.h"
#include "drift/load_box.h"

namespace whirl::drift {
namespace {

namespace fs = std::filesystem;

// Collects the files and commits them with the rendered page all-or-nothing
// (core/output_dir.h); the page and its figures are rendered by core/report_render.h.
class ReportWriter {
 public:
  ReportWriter(const fs::path& dir, std::string gnuplot)
      : out_(dir, "report directory"), gnuplot_(std::move(gnuplot)) {}
  void File(const std::string& name, const std::string& text) { out_.Add(name, text); }
  // A long per-sample CSV written to disk as it is formatted (never held whole): a file in the
  // staging folder, handed to Commit by Ready.
  std::unique_ptr<StreamedFile> Streamed(const std::string& name) {
    return std::make_unique<StreamedFile>(fs::absolute(out_.Staging()) / name);
  }
  void Ready(const std::string& name, StreamedFile* file) { out_.AddReady(name, file->Finish()); }
  DriftReportResult Finish(const report::Document& doc) {
    report::RenderOptions o;
    o.gnuplot = gnuplot_;
    result_.warnings = report::RenderReport(doc, out_, o).warnings;
    result_.files = out_.Commit();
    result_.index_html = out_.path() / "index.html";
    return result_;
  }

 private:
  OutputDir out_;
  std::string gnuplot_;
  DriftReportResult result_;
};

std::vector<std::string> Comments(const std::vector<std::string>& provenance,
                                  const std::string& what) {
  std::vector<std::string> c{what};
  for (const auto& p : provenance) c.push_back(p);
  return c;
}

using report::Cell;
using report::Col;
using report::SeriesKind;
using report::Text;

// The model: what it predicts from what, its zero and training, and its coefficients as a table.
void AddModel(const DriftModel& m, report::Document* doc) {
  std::vector<std::string> inputs = m.sensors;
  inputs.insert(inputs.end(), m.extra_inputs.begin(), m.extra_inputs.end());
  if (!m.elapsed_time_constants.empty()) inputs.push_back("elapsed time");
  std::string on;
  for (const auto& i : inputs) on += (on.empty() ? "" : ", ") + i;
  const auto numbers = [](const std::vector<double>& v) {
    std::string out;
    for (double x : v) out += (out.empty() ? "" : ", ") + MessageNumber(x);
    return out;
  };
  std::string text = ToString(m.kind) + " model of " + m.error_column + " on " + on +
                     ". Error zero: " + ToString(m.zero.zero) +
                     (m.zero.zero == ErrorZero::kFixed
                          ? " (gauge level " + FormatDecimals(m.zero.gauge_level_um, 3) + " um)"
                          : std::string()) +
                     "; sensors: " + m.selection + ".";
  if (!m.time_constants.empty())
    text += " Lag time constants: " + numbers(m.time_constants) + " " + m.time_unit + ".";
  if (!m.elapsed_time_constants.empty())
    text += " Elapsed-time constants: " + numbers(m.elapsed_time_constants) + " " + m.time_unit +
            ".";
  std::string runs;
  for (const auto& r : m.training_runs) runs += (runs.empty() ? "" : ", ") + r;
  text += " Training: R^2 " + FormatDecimals(m.r_squared, 4) + ", residual std " +
          FormatDecimals(m.residual_std_um, 3) + " um, " + std::to_string(m.training_samples) +
          " samples of " + runs + " (state " + ToString(m.state) + ").";
  doc->Add(report::Heading{2, "Model", ""}).Say(text);
  for (const auto& n : m.notes) doc->Say(n, report::Tone::kSmall);
  if (m.kind == ModelKind::kNetwork) {
    doc->Say("Network " + std::to_string(m.network.layer_sizes[0]) + "-" +
             std::to_string(m.network.layer_sizes[1]) + "-1 (no coefficients to show).");
    return;
  }
  report::Table t;
  t.header = {"feature", "coefficient", "std error", "VIF"};
  t.rows.push_back({"intercept [um]", FormatDecimals(m.linear.coefficients(0), 4),
                    FormatDecimals(m.linear.standard_errors(0), 4), ""});
  for (std::size_t i = 0; i < m.features.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    t.rows.push_back({m.features[i].Name(m.time_unit) + " [" + CoefficientUnit(m, m.features[i]) +
                          "]",
                      FormatDecimals(m.linear.coefficients(k + 1), 4),
                      FormatDecimals(m.linear.standard_errors(k + 1), 4),
                      FormatSignificant(m.linear.vif(k), 4)});
  }
  doc->Add(t);
}

// The candidates of the fit's choice (validation RMSE per candidate), as a table.
void AddCandidates(const FitReport& fit, report::Document* doc) {
  if (fit.candidates.empty()) return;
  report::Table t;
  t.header = {"candidate", "parameters", "validation RMSE [um]", "folds", "RMSE per fold [um]"};
  for (const auto& c : fit.candidates) {
    std::string folds;
    for (double f : c.fold_rmse_um)
      folds += (folds.empty() ? "" : " ") + FormatDecimalsOr(std::isfinite(f) ? f : NAN, 3, "-");
    Cell per(folds);
    per.left = true;
    t.rows.push_back({c.name, std::to_string(c.parameters),
                      FormatDecimalsOr(std::isfinite(c.cv_rmse_um) ? c.cv_rmse_um : NAN, 3, "-"),
                      std::to_string(c.folds), per});
  }
  t.caption = "candidates (validation RMSE, the whole fit redone in every fold): " + fit.chosen;
  doc->Add(t);
}

void AddSelection(const Selection& s, report::Document* doc) {
  std::string chosen;
  for (const auto& n : s.ChosenNames()) chosen += (chosen.empty() ? "" : ", ") + n;
  doc->Add(report::Heading{2, "Sensitive points (Miao et al.)", ""});
  doc->Add(report::Paragraph{{Text(s.message + ". Chosen sensors: "), report::Bold(chosen)}});
  report::Table t;
  t.header = {"lambda", "classes", "F", "F crit", "significant", "partition"};
  for (std::size_t i = 0; i < s.partitions.size(); ++i) {
    const Partition& p = s.partitions[i];
    std::string classes;
    for (int k = 0; k < p.classes; ++k) {
      classes += "{";
      for (std::size_t j = 0; j < p.labels.size(); ++j)
        if (p.labels[j] == k) classes += s.sensor_names[j] + " ";
      classes += "} ";
    }
    if (static_cast<int>(i) == s.chosen_partition) t.highlight.push_back(t.rows.size());
    Cell part(classes);
    part.left = true;
    t.rows.push_back({FormatDecimals(p.lambda, 4), std::to_string(p.classes),
                      p.has_f ? FormatDecimals(p.f, 3) : "-",
                      p.has_f ? FormatDecimals(p.f_critical, 3) : "-",
                      p.has_f ? (p.significant() ? "yes" : "no") : "-", part});
  }
  t.caption = "The chosen partition in bold.";
  doc->Add(t);
  // One row per sensor (a column per sensor ran off the page).
  report::Table g;
  g.header = {"sensor", "grey relational grade against the error (rho 0.5)", "chosen"};
  const std::vector<std::string> names = s.ChosenNames();
  for (Eigen::Index i = 0; i < s.grades.size(); ++i) {
    const std::string& n = s.sensor_names[static_cast<std::size_t>(i)];
    const bool is = std::find(names.begin(), names.end(), n) != names.end();
    if (is) g.highlight.push_back(g.rows.size());
    g.rows.push_back({n, FormatDecimals(s.grades(i), 4), is ? "yes" : ""});
  }
  doc->Add(g);
}

// Similarity matrix and fuzzy equivalence as heat maps, with sensor names on the axes.
report::Figure SimilarityFigure(ReportWriter* w, const Selection& s) {
  std::ostringstream data;
  const Eigen::Index m = s.similarity.rows();
  for (Eigen::Index i = 0; i < m; ++i)
    for (Eigen::Index j = 0; j < m; ++j)
      data << i << " " << j << " " << FormatNumber(s.similarity(i, j)) << " "
           << FormatNumber(s.equivalence(i, j)) << "\n";
  w->File("similarity.dat",
          "# i j similarity equivalence (sensor indices as in the tics)\n" + data.str());
  report::Figure f;
  f.stem = "similarity";
  f.alt = "similarity and fuzzy equivalence matrices";
  f.columns = 2;
  for (const auto& [title, column] :
       {std::pair<const char*, int>{"similarity |Pearson r| of the rises", 3},
        {"fuzzy equivalence (lambda levels)", 4}}) {
    report::Panel p;
    p.title = title;
    p.equal_axes = true;
    p.y_reversed = true;
    p.tic_names = s.sensor_names;
    p.series.push_back(
        {"similarity.dat", -1, {Col(1), Col(2), Col(column)}, SeriesKind::kImage, "", "", 1.5, false, ""});
    f.panels.push_back(std::move(p));
  }
  return f;
}

// The lambda-cuts as a step plot: class count against lambda, with F / F_crit where defined.
report::Figure LevelsFigure(ReportWriter* w, const Selection& s) {
  std::vector<std::vector<double>> rows;
  for (const Partition& p : s.partitions)
    rows.push_back({p.lambda, static_cast<double>(p.classes),
                    p.has_f && std::isfinite(p.f) ? p.f / p.f_critical : -1.0});
  w->File(
      "lambda_levels.csv",
      FormatCsv(
          {"lambda", "classes", "f_over_f_critical"}, rows,
          {"lambda-cuts of the fuzzy equivalence matrix; -1: no F (r = 1 or m, or F infinite)"}));
  report::Panel p;
  p.title = "lambda levels: classes and F test (F / F_crit > 1: significant)";
  p.xlabel = "lambda";
  p.ylabel = "classes r";
  p.y2label = "F / F_crit";
  p.y2_log = true;
  p.y2_marks = {1};
  p.series.push_back({"lambda_levels.csv", -1, {Col(1), Col(2)}, SeriesKind::kLinePoints, "",
                      "#1f77b4", 2, false, "classes at the cut"});
  p.series.push_back({"lambda_levels.csv", -1, {Col(1), Col(3)}, SeriesKind::kPoints, "",
                      "#d62728", 1.5, true, "F / F_crit (where defined)"});
  report::Figure f;
  f.stem = "lambda_levels";
  f.alt = "class count and F test per lambda level";
  f.panels = {p};
  return f;
}

std::vector<Cell> StatsRow(const std::string& name, const ErrorStats& s) {
  return {name, FormatDecimals(s.mae_um, 2), FormatDecimals(s.rmse_um, 2),
          FormatDecimals(s.std_um, 2), FormatDecimals(s.max_abs_um, 2)};
}


using SampleSink = std::function<void(const PredictedSample&)>;

// The x range of a run's samples (its first and last time [min], or sample index) and its axis.
struct RunAxis {
  double first = 0, last = 0;
  bool time_from_index = false;
};

// Where a model report's runs come from: files streamed block by block, or runs in memory. Per
// run its name and time axis, its prediction under any model sample by sample, and fits on some
// of the runs (the baselines' models).
class ShownRuns {
 public:
  virtual ~ShownRuns() = default;
  virtual std::size_t size() const = 0;
  virtual const std::string& Name(std::size_t i) const = 0;
  virtual RunAxis Axis(std::size_t i) const = 0;
  // PredictRun's samples in order into `sink` (optional) and their summary.
  virtual PredictionSummary Predict(const DriftModel& m, std::size_t i,
                                    const SampleSink& sink) const = 0;
  // The model drift fit makes on the runs `which` (InputError as FitDriftModel).
  virtual DriftModel Fit(const std::vector<std::size_t>& which, const std::string& error,
                         const FitOptions& o) const = 0;
};

class RunsInMemory final : public ShownRuns {
 public:
  explicit RunsInMemory(const std::vector<Run>& runs) : runs_(runs) {}
  std::size_t size() const override { return runs_.size(); }
  const std::string& Name(std::size_t i) const override { return runs_[i].name; }
  RunAxis Axis(std::size_t i) const override {
    const std::vector<double>& t = runs_[i].time_min;
    return {t.empty() ? 0.0 : t.front(), t.empty() ? 0.0 : t.back(), runs_[i].time_from_index};
  }
  PredictionSummary Predict(const DriftModel& m, std::size_t i,
                            const SampleSink& sink) const override {
    const RunPrediction p = PredictRun(m, runs_[i]);
    PredictedSample s;
    s.has_measured = p.has_measured;
    for (Eigen::Index k = 0; sink && k < p.predicted_um.size(); ++k) {
      s.index = k;
      s.time = p.time[static_cast<std::size_t>(k)];
      s.predicted_um = p.predicted_um(k);
      s.std_um = p.std_um(k);
      if (p.has_measured) s.measured_um = p.measured_um(k);
      sink(s);
    }
    return Summarize(p);
  }
  DriftModel Fit(const std::vector<std::size_t>& which, const std::string& error,
                 const FitOptions& o) const override {
    std::vector<Run> chosen;
    for (const std::size_t i : which) chosen.push_back(runs_[i]);
    return FitDriftModel(chosen, error, o).model;
  }

 private:
  const std::vector<Run>& runs_;
};

// The runs as files: each scanned once (its rows and time axis), every pass streamed.
class RunsInFiles final : public ShownRuns {
 public:
  RunsInFiles(const std::vector<RunFile>& files, const StreamProgress& progress)
      : files_(files), progress_(progress) {
    for (const RunFile& f : files) {
      scans_.push_back(ScanRun(f.path));
      names_.push_back(RunReader(f.path, f.state, scans_.back().time_from_index).layout().name);
    }
  }
  std::size_t size() const override { return files_.size(); }
  const std::string& Name(std::size_t i) const override { return names_[i]; }
  RunAxis Axis(std::size_t i) const override {
    return {scans_[i].first_time, scans_[i].last_time, scans_[i].time_from_index};
  }
  PredictionSummary Predict(const DriftModel& m, std::size_t i,
                            const SampleSink& sink) const override {
    return PredictFile(m, files_[i].path, ReferenceMode::kRunStart, sink, progress_, &scans_[i]);
  }
  DriftModel Fit(const std::vector<std::size_t>& which, const std::string& error,
                 const FitOptions& o) const override {
    std::vector<RunFile> chosen;
    for (const std::size_t i : which) chosen.push_back(files_[i]);
    return FitFiles(chosen, error, o, progress_).model;
  }

 private:
  const std::vector<RunFile>& files_;
  const StreamProgress& progress_;
  std::vector<RunScan> scans_;
  std::vector<std::string> names_;
};

// The model's training runs among the runs shown (all of them, in the model's order), or empty.
std::vector<std::size_t> TrainingRunsShown(const DriftModel& m, const ShownRuns& runs) {
  std::vector<std::size_t> found;
  for (const std::string& name : m.training_runs)
    for (std::size_t i = 0; i < runs.size(); ++i)
      if (runs.Name(i) == name) {
        found.push_back(i);
        break;
      }
  return found.size() == m.training_runs.size() ? found : std::vector<std::size_t>{};
}

constexpr const char* kBaselineNames[] = {"model", "none", "time only", kPreviousRunBaseline};

std::array<double, 4> BaselineValues(const ReportBaseline& c) {
  return {c.model_mae_um, c.none_mae_um, c.time_only_mae_um, c.previous_run_mae_um};
}

// The name of the smallest finite MAE, or "" when there is none.
std::string Strongest(const ReportBaseline& c) {
  const std::array<double, 4> v = BaselineValues(c);
  int best = -1;
  for (int k = 0; k < 4; ++k)
    if (std::isfinite(v[k]) && (best < 0 || v[k] < v[best])) best = k;
  return best < 0 ? "" : kBaselineNames[best];
}

// A baseline's MAE on run i: one more pass, its samples never kept.
double BaselineMae(const DriftModel& b, const ShownRuns& runs, std::size_t i) {
  const PredictionSummary s = runs.Predict(b, i, {});
  return s.has_measured ? s.residual.mae_um : NAN;
}

// Per run shown: the model (its pass, `preds`) against no compensation, a time-only warm-up
// fitted on the model's training runs (first order in time since the run's start,
// drift/regression.h FitWarmUp), and drift fit at its defaults redone on the previous run shown
// (drift/fit.h PreviousRunOptions). A baseline that cannot be fitted (the training runs are not
// shown, too few samples) stays empty and the notes say why.
std::vector<ReportBaseline> Baselines(const DriftModel& m,
                                      const std::vector<PredictionSummary>& preds,
                                      const ShownRuns& runs, std::vector<std::string>* notes) {
  std::vector<ReportBaseline> cells(runs.size());
  DriftModel time;
  bool have_time = false;
  const std::vector<std::size_t> training = TrainingRunsShown(m, runs);
  if (training.empty()) {
    notes->push_back("time only: not fitted (the model's training runs are not among the runs shown)");
  } else {
    try {
      FitOptions t;
      t.kind = ModelKind::kMlr;
      t.candidates = Candidates::kTime;
      t.zero = m.zero;
      time = runs.Fit(training, m.error_column, t);
      have_time = true;
    } catch (const InputError& e) {
      notes->push_back(std::string("time only: not fitted: ") + e.what());
    }
  }
  for (std::size_t i = 0; i < runs.size(); ++i) {
    ReportBaseline& c = cells[i];
    c.run = runs.Name(i);
    if (!preds[i].has_measured) continue;
    c.model_mae_um = preds[i].residual.mae_um;
    c.none_mae_um = preds[i].none.mae_um;
    if (have_time) c.time_only_mae_um = BaselineMae(time, runs, i);
    if (i > 0) {
      try {
        c.previous_run_mae_um = BaselineMae(
            runs.Fit({i - 1}, m.error_column, PreviousRunOptions(m)), runs, i);
      } catch (const InputError& e) {
        notes->push_back(std::string(kPreviousRunBaseline) + ": no refit on " +
                         runs.Name(i - 1) + ": " + e.what());
      }
    }
    c.strongest = Strongest(c);
  }
  return cells;
}

void AddBaselines(const std::vector<ReportBaseline>& cells, const std::vector<std::string>& notes,
                  report::Document* doc) {
  doc->Add(report::Heading{2, "Baselines", ""});
  doc->Say("MAE um per run: the model, no compensation, a time-only warm-up (first order in the "
           "time since the run's start, no sensor, fitted on the model's training runs) and drift "
           "fit at its defaults redone on the previous run shown (the model's kind, inputs and "
           "zero); the strongest is named.");
  report::Table t;
  t.header = {"run", "model [um]", "none [um]", "time only [um]", "previous run [um]",
              "strongest"};
  for (const ReportBaseline& c : cells) {
    std::vector<Cell> row{c.run};
    for (double v : BaselineValues(c))
      row.push_back(std::isfinite(v) ? FormatDecimals(v, 2) : "-");
    row.push_back(c.strongest.empty() ? "-" : c.strongest);
    t.rows.push_back(std::move(row));
  }
  doc->Add(t);
  for (const auto& n : notes) doc->Say(n, report::Tone::kSmall);
}

// The model's pass over one run: every sample goes into the per-sample CSV (written as it is
// formatted, through a 1 MiB buffer) and into the plot's M4 decimation (core/decimate.h: the
// extremes of predicted, measured and residual per pixel column, the std carried along), so
// neither grows in memory with the run.
class RunPass {
 public:
  RunPass(ReportWriter* w, const std::string& csv_name, const RunAxis& axis,
          std::vector<std::string> comments)
      : file_(w->Streamed(csv_name)), axis_(axis), comments_(std::move(comments)) {}

  void Add(const PredictedSample& p) {
    if (!plot_) Start(p.has_measured);
    AppendPredictionRow(p.time, p.predicted_um, p.std_um,
                        p.has_measured ? &p.measured_um : nullptr, &rows_);
    if (rows_.size() >= (1u << 20)) {
      file_->Append(rows_);
      rows_.clear();
    }
    const std::array<double, 4> v =
        p.has_measured
            ? std::array<double, 4>{p.predicted_um, p.measured_um, p.measured_um - p.predicted_um,
                                    p.std_um}
            : std::array<double, 4>{p.predicted_um, p.std_um, 0, 0};
    plot_->Add(p.index, p.time, v.data());
  }

  // Ends the per-sample CSV (handed to the writer as `name`) and returns the plot's rows as CSV.
  std::string Finish(ReportWriter* w, const std::string& name, bool has_measured,
                     const std::vector<std::string>& plot_comments) {
    if (!plot_) Start(has_measured);
    file_->Append(rows_);
    w->Ready(name, file_.get());
    std::string out = PredictionCsvHeader(axis_.time_from_index, measured_, plot_comments);
    plot_->Finish();
    const std::vector<double>& x = plot_->x();
    const std::vector<double>& v = plot_->values();
    const std::size_t width = measured_ ? 4 : 2;
    for (std::size_t k = 0; k < x.size(); ++k) {
      const double* row = v.data() + k * width;
      AppendPredictionRow(x[k], row[0], row[width - 1], measured_ ? row + 1 : nullptr, &out);
    }
    return out;
  }

 private:
  void Start(bool has_measured) {
    measured_ = has_measured;
    rows_ = PredictionCsvHeader(axis_.time_from_index, has_measured, comments_);
    plot_ = std::make_unique<M4Decimator>(has_measured ? 3 : 1, axis_.first, axis_.last,
                                          kPlotColumns, 1);
  }

  std::unique_ptr<StreamedFile> file_;
  RunAxis axis_;
  std::vector<std::string> comments_;
  std::string rows_;
  bool measured_ = false;
  std::unique_ptr<M4Decimator> plot_;
};

// The run's figure: measured and predicted error with the prediction's +-1 sd band, and the
// residual below (columns of <slug>_plot.csv: PredictionCsvHeader).
report::Figure RunFigure(const PredictionSummary& p, const std::string& plot_csv,
                         const std::string& error_column, const std::string& slug) {
  const double per = p.time_from_index ? 1.0 : 60.0;
  report::Panel top, bottom;
  top.title = "run " + p.run + ": measured and predicted " + error_column;
  top.ylabel = "thermal error [um]";
  bottom.title = "residual (measured - predicted)";
  bottom.ylabel = "residual [um]";
  for (report::Panel* x : {&top, &bottom}) x->xlabel = p.time_from_index ? "sample" : "time [h]";
  report::Column low = Col(2), high = Col(2);
  low.minus = 4;
  high.plus = 4;
  top.series.push_back({plot_csv, -1, {Col(1, per), low, high}, SeriesKind::kBand, "prediction", "",
                        1.5, false, "predicted +- 1 sd"});
  top.series.push_back({plot_csv, -1, {Col(1, per), Col(2)}, SeriesKind::kLine, "prediction", "",
                        1.5, false, "predicted"});
  if (p.has_measured) {
    top.series.push_back({plot_csv, -1, {Col(1, per), Col(5)}, SeriesKind::kLine, "measured", "",
                          1.5, false, "measured"});
    bottom.series.push_back({plot_csv, -1, {Col(1, per), Col(6)}, SeriesKind::kLine, "residual",
                             "", 1.5, false, "residual"});
  }
  report::Figure f;
  f.stem = slug + "_prediction";
  f.alt = "measured and predicted error of " + p.run;
  f.panels = {top, bottom};
  return f;
}

// Run i under the model, in one pass: its per-sample CSV, the plot's rows, its heading, warnings
// and figure into `plots`; returns the prediction's summary.
PredictionSummary ShowRun(ReportWriter* w, const ShownRuns& runs, std::size_t i,
                          const DriftModel& m, const std::vector<std::string>& provenance,
                          std::vector<report::Block>* plots) {
  const std::string& name = runs.Name(i);
  const std::string slug = Slug(name);
  RunPass pass(w, slug + "_prediction.csv", runs.Axis(i),
               Comments(provenance, "prediction of " + name));
  const PredictionSummary p =
      runs.Predict(m, i, [&pass](const PredictedSample& s) { pass.Add(s); });
  // gnuplot reads the plot's rows only (M4: at most a few thousand whatever the run's length).
  const std::string plot_csv = slug + "_plot.csv";
  w->File(plot_csv, pass.Finish(w, slug + "_prediction.csv", p.has_measured,
                                Comments(provenance, "rows of the plot of " + name +
                                                         " (M4 decimation of the prediction "
                                                         "per pixel column; all rows: " +
                                                         slug + "_prediction.csv)")));
  plots->push_back(report::MakeBlock(report::Heading{3, p.run, ""}));
  for (const auto& warn : p.warnings)
    plots->push_back(report::MakeBlock(report::Paragraph{{Text(warn)}, report::Tone::kWarn}));
  plots->push_back(report::MakeBlock(RunFigure(p, plot_csv, m.error_column, slug)));
  return p;
}

// The model report of `runs`: the load box, the baselines (is the model worth loading?), the model
// and its choice, then per run its statistics and figure. Each run is one pass under the model;
// each baseline one more pass (Baselines).
DriftReportResult ModelReport(const fs::path& dir, const FitReport& fit, const ShownRuns& runs,
                              const std::vector<std::string>& provenance,
                              const std::string& gnuplot) {
  ReportWriter w(dir, gnuplot);
  const DriftModel& m = fit.model;
  report::Table stats;
  stats.header = {"run", "MAE [um]", "RMSE [um]", "std [um]", "max [um]"};
  std::vector<report::Block> plots;
  std::vector<PredictionSummary> preds;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const PredictionSummary& p = preds.emplace_back(ShowRun(&w, runs, i, m, provenance, &plots));
    if (!p.has_measured) continue;
    stats.rows.push_back(StatsRow(p.run + " (model)", p.residual));
    stats.rows.push_back(StatsRow(p.run + " (no compensation)", p.none));
  }
  report::Document doc;
  doc.title = "whirl: machine thermal drift of " + m.error_column;
  doc.provenance = provenance;
  std::vector<std::string> inputs = m.sensors;
  inputs.insert(inputs.end(), m.extra_inputs.begin(), m.extra_inputs.end());
  doc.Add(DriftLoadBox(ToString(m.kind), m.error_column, inputs));
  std::vector<std::string> notes;
  const std::vector<ReportBaseline> baselines = Baselines(m, preds, runs, &notes);
  AddBaselines(baselines, notes, &doc);  // the summary first: is the model worth loading?
  AddModel(m, &doc);
  AddCandidates(fit, &doc);
  if (fit.selected) {
    AddSelection(fit.selection, &doc);
    doc.Add(SimilarityFigure(&w, fit.selection)).Add(LevelsFigure(&w, fit.selection));
  }
  doc.Add(report::Heading{2, "Runs", ""}).Add(stats).Add(plots);
  DriftReportResult result = w.Finish(doc);
  result.baselines = baselines;
  result.baseline_notes = notes;
  result.predictions = std::move(preds);
  return result;
}

}  // namespace

DriftReportResult WriteModelReport(const fs::path& dir, const FitReport& fit,
                                   const std::vector<Run>& runs,
                                   const std::vector<std::string>& provenance,
                                   const std::string& gnuplot) {
  return ModelReport(dir, fit, RunsInMemory(runs), provenance, gnuplot);
}

DriftReportResult WriteModelReport(const fs::path& dir, const FitReport& fit,
                                   const std::vector<RunFile>& runs,
                                   const std::vector<std::string>& provenance,
                                   const std::string& gnuplot, const StreamProgress& progress) {
  return ModelReport(dir, fit, RunsInFiles(runs, progress), provenance, gnuplot);
}

namespace {

// The hold-out's table: per channel and method the test and train errors and the inputs; the
// strongest method of each channel bold.
report::Table HoldoutTable(const HoldoutResult& r) {
  report::Table t;
  t.series_rows = true;
  t.header = {"method", "channel", "test MAE [um]", "test RMSE [um]", "test max [um]",
              "train MAE [um]", "inputs (lags)"};
  const auto strongest = r.Strongest();
  for (const auto& row : r.rows_out) {
    std::string inputs;
    if (row.inputs.size() > 6) {
      inputs = std::to_string(row.inputs.size()) + " sensors";
    } else {
      for (const auto& i : row.inputs) inputs += (inputs.empty() ? "" : ", ") + i;
    }
    if (!row.time_constants.empty()) {
      std::string lags;
      for (double l : row.time_constants) lags += (lags.empty() ? "" : ", ") + MessageNumber(l);
      inputs += " (" + lags + (r.time_from_index ? " samples)" : " min)");
    }
    for (const auto& [ch, method] : strongest)
      if (ch == row.channel && method == row.method) t.highlight.push_back(t.rows.size());
    Cell in(inputs);
    in.left = true;
    t.rows.push_back({row.method, row.channel, FormatDecimals(row.test.mae_um, 2),
                      FormatDecimals(row.test.rmse_um, 2), FormatDecimals(row.test.max_abs_um, 2),
                      FormatDecimals(row.train.mae_um, 2), in});
  }
  t.caption = "Errors from zero '" + ToString(r.zero.zero) +
              "'; time = sensor-free warm-up in time since the log's start; bold: the strongest "
              "(lowest test MAE) of each channel.";
  return t;
}

// The method (among idx[0..c)) whose prediction equals idx[c]'s on every row, or "".
std::string SameAs(const HoldoutResult& r, const std::vector<std::size_t>& idx, std::size_t c) {
  const Eigen::VectorXd& v = r.predictions[idx[c]].predicted_um;
  for (std::size_t e = 0; e < c; ++e) {
    const Eigen::VectorXd& u = r.predictions[idx[e]].predicted_um;
    if (u.size() == v.size() && v.size() > 0 &&
        (u - v).cwiseAbs().maxCoeff() <= 1e-9 * (1 + v.cwiseAbs().maxCoeff()))
      return r.rows_out[idx[e]].method;
  }
  return "";
}

// A method's +-1 sd band in <slug>_holdout_band.csv: its name and the file's columns (low, high).
struct Band {
  std::string method;
  int low = 0, high = 0;
};

// One channel's figure: measured and every method's prediction over the log prefix (the end of
// training dashed), each with its +-1 sd band (`bands`), the residuals below. A method whose
// prediction equals an earlier one's is drawn with open circles and its legend says so, so
// coinciding lines stay distinguishable.
report::Figure HoldoutFigure(const HoldoutResult& r, const std::vector<std::size_t>& idx,
                             const std::string& ch, const std::string& csv, const std::string& slug,
                             const std::vector<Band>& bands) {
  report::Panel top, bottom;
  top.title = ch + ": measured and predicted (dashed line: end of training)";
  top.ylabel = "error [um]";
  bottom.title = "residual (measured - predicted)";
  bottom.ylabel = "residual [um]";
  for (report::Panel* p : {&top, &bottom}) {
    p->xlabel = "time [h]";
    p->x_marks = {r.train_end_min / 60};
  }
  for (const Band& b : bands)
    top.series.push_back({slug + "_holdout_band.csv",
                          -1,
                          {Col(1, 60), Col(b.low), Col(b.high)},
                          SeriesKind::kBand,
                          b.method,
                          "",
                          1.5,
                          false,
                          b.method + " +- 1 sd"});
  top.series.push_back({csv, -1, {Col(1, 60), Col(2)}, SeriesKind::kLine, "measured", "", 1.5,
                        false, "measured"});
  for (std::size_t c = 0; c < idx.size(); ++c) {
    const std::string method = r.rows_out[idx[c]].method;
    const std::string same = SameAs(r, idx, c);
    const std::string title = method + (same.empty() ? "" : " (the same as " + same + ")");
    report::Column residual = Col(2);
    residual.minus = static_cast<int>(c) + 3;
    report::Series line{csv, -1, {Col(1, 60), Col(static_cast<int>(c) + 3)}, SeriesKind::kLine,
                        method, "", 1.5, false, title};
    line.markers = !same.empty();
    top.series.push_back(line);
    line.columns = {Col(1, 60), residual};
    bottom.series.push_back(line);
  }
  top.series.push_back(
      {csv, -1, {Col(1, 60), Col(2)}, SeriesKind::kLine, "measured", "", 1.5, false, ""});  // on top
  report::Figure f;
  f.stem = slug + "_holdout";
  f.alt = "hold-out of " + ch;
  f.height_px = 640;
  f.panels = {top, bottom};
  return f;
}

// <slug>_holdout_band.csv: every method's prediction -+ its sd per row (its predictive sd where
// the model gives one, else its training residual std; none has no band); returns the bands.
std::vector<Band> AddBands(const HoldoutResult& r, const std::vector<std::size_t>& idx,
                           const std::string& ch, const std::string& slug,
                           const std::vector<std::string>& provenance, ReportWriter* w) {
  std::vector<Band> bands;
  std::vector<std::string> header{"time_min"};
  std::vector<Eigen::VectorXd> sd;
  std::vector<std::size_t> shown;
  for (std::size_t i : idx) {
    const RunPrediction& p = r.predictions[i];
    const std::string& method = r.rows_out[i].method;
    Eigen::VectorXd s =
        p.std_um.size() == p.predicted_um.size() && p.std_um.size() > 0 && p.std_um.maxCoeff() > 0
            ? p.std_um
            : Eigen::VectorXd::Constant(p.predicted_um.size(),
                                        i < r.models.size() ? r.models[i].residual_std_um : 0.0);
    if (method == "none" || s.size() == 0 || !(s.maxCoeff() > 0)) continue;
    const int low = static_cast<int>(header.size()) + 1;
    bands.push_back({method, low, low + 1});
    header.push_back(method + "_minus_1sd_um");
    header.push_back(method + "_plus_1sd_um");
    sd.push_back(std::move(s));
    shown.push_back(i);
  }
  if (bands.empty()) return bands;
  std::vector<std::vector<double>> rows;
  const RunPrediction& first = r.predictions[shown.front()];
  for (Eigen::Index k = 0; k < first.predicted_um.size(); ++k) {
    std::vector<double> row{first.time[static_cast<std::size_t>(k)]};
    for (std::size_t j = 0; j < shown.size(); ++j) {
      const double y = r.predictions[shown[j]].predicted_um(k);
      row.push_back(y - sd[j](k));
      row.push_back(y + sd[j](k));
    }
    rows.push_back(std::move(row));
  }
  w->File(slug + "_holdout_band.csv",
          FormatCsv(header, rows,
                    Comments(provenance, "+-1 sd band of each method on " + ch +
                                             " (its predictive sd, or its training residual "
                                             "std where the model gives none)")));
  return bands;
}

// The load box of the first channel's strongest method (the model drift fit would hand on).
report::Box HoldoutBox(const HoldoutResult& r) {
  const auto strongest = r.Strongest();
  for (std::size_t i = 0; i < r.rows_out.size() && i < r.models.size(); ++i)
    if (!strongest.empty() && r.rows_out[i].channel == strongest.front().first &&
        r.rows_out[i].method == strongest.front().second) {
      const DriftModel& m = r.models[i];
      std::vector<std::string> inputs = m.sensors;
      inputs.insert(inputs.end(), m.extra_inputs.begin(), m.extra_inputs.end());
      return DriftLoadBox(ToString(m.kind) + ", the strongest here: " + r.rows_out[i].method,
                          r.rows_out[i].channel, inputs);
    }
  return DriftLoadBox("no model", r.rows_out.empty() ? "" : r.rows_out.front().channel, {});
}

}  // namespace

DriftReportResult WriteHoldoutReport(const fs::path& dir, const Run& log, const HoldoutResult& r,
                                     const std::vector<std::string>& provenance,
                                     const std::string& gnuplot) {
  ReportWriter w(dir, gnuplot);
  report::Document doc;
  doc.title = "whirl: chronological hold-out on " + log.name;
  doc.provenance = provenance;
  doc.Say("Train rows [0, " + std::to_string(r.train_end) + ") to " +
          FormatDecimals(r.train_end_min / 60, 1) + " h; test rows [" +
          std::to_string(r.train_end) + ", " + std::to_string(r.test_end) + ") to " +
          FormatDecimals(r.test_end_min / 60, 1) + " h. Models run from the log's first row.");
  doc.Add(HoldoutBox(r)).Add(HoldoutTable(r));
  for (const auto& warn : r.warnings) doc.Say(warn, report::Tone::kWarn);
  std::vector<std::string> channels;
  for (const auto& row : r.rows_out)
    if (channels.empty() || channels.back() != row.channel) channels.push_back(row.channel);
  for (const std::string& ch : channels) {
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < r.rows_out.size(); ++i)
      if (r.rows_out[i].channel == ch) idx.push_back(i);
    std::vector<std::string> header{"time_min", "measured_um"};
    for (std::size_t i : idx) header.push_back(r.rows_out[i].method + "_um");
    std::vector<std::vector<double>> rows;
    const RunPrediction& first = r.predictions[idx.front()];
    for (Eigen::Index k = 0; k < first.measured_um.size(); ++k) {
      std::vector<double> row{first.time[static_cast<std::size_t>(k)], first.measured_um(k)};
      for (std::size_t i : idx) row.push_back(r.predictions[i].predicted_um(k));
      rows.push_back(std::move(row));
    }
    const std::string slug = Slug(ch);
    w.File(slug + "_holdout.csv",
           FormatCsv(header, rows, Comments(provenance, "hold-out of " + ch)));
    const std::vector<Band> bands = AddBands(r, idx, ch, slug, provenance, &w);
    doc.Add(report::Heading{2, ch, ""})
        .Add(HoldoutFigure(r, idx, ch, slug + "_holdout.csv", slug, bands));
    if (!bands.empty())
      doc.Say(
          "Shaded: each method's prediction +- 1 sd, the sd its model predicts where it gives "
          "one, else its residual std on the training rows (never from the test rows).",
          report::Tone::kSmall);
  }
  return w.Finish(doc);
}

}  // namespace whirl::drift
