#include "drift/report.h"

#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <sstream>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/decimate.h"
#include "core/error.h"
#include "core/html_page.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/plot_style.h"
#include "core/run_program.h"
#include "core/safe_text.h"
#include "drift/documents.h"

namespace whirl::drift {
namespace {

namespace fs = std::filesystem;

const char* kTerminal = "set terminal pngcairo size 1000,480 font 'Sans,10' noenhanced\n";

// Collects the files, renders the gnuplot scripts in the output directory's staging folder and
// commits everything with index.html all-or-nothing (core/output_dir.h).
class ReportWriter {
 public:
  ReportWriter(const fs::path& dir, std::string gnuplot)
      : out_(dir, "report directory"), gnuplot_(std::move(gnuplot)) {
    have_gnuplot_ = ProgramSucceeds({gnuplot_, "--version"});
    if (!have_gnuplot_)
      result_.warnings.push_back("'" + gnuplot_ +
                                 "' not found: plots skipped (install gnuplot-nox)");
  }
  void File(const std::string& name, const std::string& text) { out_.Add(name, text); }
  // Script `stem`.gp renders `stem`.png; returns the <img> tag (or a note when not rendered).
  std::string Plot(const std::string& stem, const std::string& body, const std::string& alt) {
    const std::string png = stem + ".png";
    File(stem + ".gp", "# gnuplot script written by whirl; re-run with: gnuplot " + stem + ".gp\n" +
                           kTerminal + "set output " + GnuplotString(png) + "\n" + body);
    if (have_gnuplot_) {
      // gnuplot never sees the output directory: it renders in the staging folder.
      const int rc = out_.RunInStaging({gnuplot_, stem + ".gp"}, "gnuplot.log", {png});
      const fs::path stage = out_.Staging();
      std::error_code ec;
      if (rc == 0 && fs::is_regular_file(stage / png, ec) && fs::file_size(stage / png, ec) > 0) {
        out_.AddStaged(png);
        return "<img src='" + HtmlEscape(png) + "' alt='" + HtmlEscape(alt) + "'>";
      }
      gnuplot_failed_ = true;
      result_.warnings.push_back("gnuplot failed on " + (out_.path() / (stem + ".gp")).string() +
                                 " (see gnuplot.log)");
    }
    return "<p>(plot not rendered: " + HtmlEscape(stem) + ".gp)</p>";
  }
  // A long per-sample CSV written to disk as it is formatted (never held whole): a file in the
  // staging folder, handed to Commit by Ready.
  std::unique_ptr<StreamedFile> Streamed(const std::string& name) {
    return std::make_unique<StreamedFile>(fs::absolute(out_.Staging()) / name);
  }
  void Ready(const std::string& name, StreamedFile* file) { out_.AddReady(name, file->Finish()); }
  const std::vector<std::string>& warnings() const { return result_.warnings; }
  DriftReportResult Finish(const std::string& html) {
    if (gnuplot_failed_) out_.AddProgramLog("gnuplot.log");
    File("index.html", html);
    result_.files = out_.Commit();
    result_.index_html = out_.path() / "index.html";
    return result_;
  }

 private:
  OutputDir out_;
  std::string gnuplot_;
  bool have_gnuplot_ = false, gnuplot_failed_ = false;
  DriftReportResult result_;
};

// The shared skeleton and stylesheet of every report (core/html_page.h).
std::string Head(const std::string& title, const std::vector<std::string>& provenance) {
  return HtmlPageBegin(title, provenance);
}

std::vector<std::string> Comments(const std::vector<std::string>& provenance,
                                  const std::string& what) {
  std::vector<std::string> c{what};
  for (const auto& p : provenance) c.push_back(p);
  return c;
}

std::string SelectionHtml(const Selection& s) {
  std::ostringstream h;
  h << "<h2>Sensitive points (Miao et al.)</h2>\n<p>" << HtmlEscape(s.message)
    << ". Chosen sensors: <b>";
  for (const auto& n : s.ChosenNames()) h << HtmlEscape(n) << " ";
  h << "</b></p>\n<table><tr><th>lambda</th><th>classes</th><th>F</th><th>F crit</th>"
       "<th>significant</th><th style='text-align:left'>partition</th></tr>\n";
  for (std::size_t i = 0; i < s.partitions.size(); ++i) {
    const Partition& p = s.partitions[i];
    std::string classes;
    for (int k = 0; k < p.classes; ++k) {
      classes += "{";
      for (std::size_t j = 0; j < p.labels.size(); ++j)
        if (p.labels[j] == k) classes += s.sensor_names[j] + " ";
      classes += "} ";
    }
    const bool chosen = static_cast<int>(i) == s.chosen_partition;
    h << "<tr" << (chosen ? " style='background:#dfd'" : "") << "><td>"
      << FormatDecimals(p.lambda, 4) << "</td><td>" << p.classes << "</td><td>"
      << (p.has_f ? FormatDecimals(p.f, 3) : "-") << "</td><td>"
      << (p.has_f ? FormatDecimals(p.f_critical, 3) : "-") << "</td><td>"
      << (p.has_f ? (p.significant() ? "yes" : "no") : "-") << "</td><td style='text-align:left'>"
      << HtmlEscape(classes) << "</td></tr>\n";
  }
  h << "</table>\n<p>Grey relational grades against the error (rho 0.5):</p><table><tr>";
  for (const auto& n : s.sensor_names) h << "<th>" << HtmlEscape(n) << "</th>";
  h << "</tr><tr>";
  for (Eigen::Index i = 0; i < s.grades.size(); ++i)
    h << "<td>" << FormatDecimals(s.grades(i), 4) << "</td>";
  h << "</tr></table>\n";
  return h.str();
}

// Similarity matrix and fuzzy equivalence as heat maps, with sensor names on the axes.
std::string SimilarityPlot(ReportWriter* w, const Selection& s) {
  std::ostringstream data;
  const Eigen::Index m = s.similarity.rows();
  for (Eigen::Index i = 0; i < m; ++i)
    for (Eigen::Index j = 0; j < m; ++j)
      data << i << " " << j << " " << FormatNumber(s.similarity(i, j)) << " "
           << FormatNumber(s.equivalence(i, j)) << "\n";
  w->File("similarity.dat",
          "# i j similarity equivalence (sensor indices as in the tics)\n" + data.str());
  std::string tics;
  for (Eigen::Index i = 0; i < m; ++i)
    tics += (i ? ", " : "") + GnuplotString(s.sensor_names[static_cast<std::size_t>(i)]) + " " +
            std::to_string(i);
  std::ostringstream gp;
  gp << "set multiplot layout 1,2\nset size ratio -1\nset cbrange [0:1]\nset xtics (" << tics
     << ") rotate by 90 right\nset bmargin 6\nset ytics (" << tics << ")\nset yrange [] reverse\n"
     << "set title 'similarity |Pearson r| of the rises'\nplot 'similarity.dat' using 1:2:3 with "
        "image notitle\n"
     << "set title 'fuzzy equivalence (lambda levels)'\nplot 'similarity.dat' using 1:2:4 with "
        "image notitle\n"
     << "unset multiplot\n";
  return w->Plot("similarity", gp.str(), "similarity and fuzzy equivalence matrices");
}

// The lambda-cuts as a step plot: class count against lambda, with F / F_crit where defined.
std::string LevelsPlot(ReportWriter* w, const Selection& s) {
  std::vector<std::vector<double>> rows;
  for (const Partition& p : s.partitions)
    rows.push_back({p.lambda, static_cast<double>(p.classes),
                    p.has_f && std::isfinite(p.f) ? p.f / p.f_critical : -1.0});
  w->File(
      "lambda_levels.csv",
      FormatCsv(
          {"lambda", "classes", "f_over_f_critical"}, rows,
          {"lambda-cuts of the fuzzy equivalence matrix; -1: no F (r = 1 or m, or F infinite)"}));
  std::ostringstream gp;
  gp << "set datafile separator ','\nset grid\nset key top left\nset xlabel 'lambda'\n"
     << "set ylabel 'classes r'\nset y2label 'F / F_crit'\nset y2tics\nset logscale y2\n"
     << "set title 'lambda levels: classes and F test (F / F_crit > 1: significant)'\n"
     << "plot 'lambda_levels.csv' using 1:2 with linespoints pt 5 lw 2 title 'classes at the cut', "
     << "'' using 1:($3 > 0 ? $3 : 1/0) axes x1y2 with points pt 7 title 'F / F_crit', "
     << "1 axes x1y2 with lines dt 2 lc rgb 'gray' notitle\n";
  return w->Plot("lambda_levels", gp.str(), "class count and F test per lambda level");
}

std::string StatsRow(const std::string& name, const ErrorStats& s) {
  return "<tr><td style='text-align:left'>" + HtmlEscape(name) + "</td><td>" +
         FormatDecimals(s.mae_um, 2) + "</td><td>" + FormatDecimals(s.rmse_um, 2) + "</td><td>" +
         FormatDecimals(s.std_um, 2) + "</td><td>" + FormatDecimals(s.max_abs_um, 2) +
         "</td></tr>\n";
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

std::string BaselinesHtml(const std::vector<ReportBaseline>& cells,
                          const std::vector<std::string>& notes) {
  std::ostringstream h;
  h << "<h2>Baselines</h2>\n<p>MAE um per run: the model, no compensation, a time-only warm-up "
       "(first order in the time since the run's start, no sensor, fitted on the model's "
       "training runs) and drift fit at its defaults redone on the previous run shown (the "
       "model's kind, inputs and zero); the strongest "
       "is named.</p>\n<table><tr><th style='text-align:left'>run</th><th>model</th><th>none</th>"
       "<th>time only</th><th>previous run</th><th>strongest</th></tr>\n";
  for (const ReportBaseline& c : cells) {
    const std::array<double, 4> v = BaselineValues(c);
    h << "<tr><td style='text-align:left'>" << HtmlEscape(c.run) << "</td>";
    for (int k = 0; k < 4; ++k)
      h << "<td>" << (std::isfinite(v[k]) ? FormatDecimals(v[k], 2) : "&ndash;") << "</td>";
    h << "<td>" << (c.strongest.empty() ? "&ndash;" : c.strongest) << "</td></tr>\n";
  }
  h << "</table>\n";
  for (const auto& n : notes) h << "<p><i>" << HtmlEscape(n) << "</i></p>\n";
  return h.str();
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

// The gnuplot script of a run's plot: measured and predicted (+- 1 sd) over time, the residual.
std::string RunPlotScript(const DriftModel& m, const PredictionSummary& p,
                          const std::string& plot_csv) {
  const std::string x = p.time_from_index ? "sample" : "time [h]";
  const std::string xcol = p.time_from_index ? "1" : "($1/60)";
  std::ostringstream gp;
  // The line looks of core/plot_style.h; the key right of the data, the panels aligned.
  gp << "set datafile separator ','\n" << GnuplotKeyOutsideRight() << "set grid\nset xlabel "
     << GnuplotString(x) << "\nset ylabel 'thermal error [um]'\nset multiplot layout 2,1\n"
     << "set title "
     << GnuplotString("run " + p.run + ": measured and predicted " + m.error_column)
     << "\nplot " << GnuplotString(plot_csv) << " using " << xcol
     << ":($2-$4):($2+$4) with filledcurves fs transparent solid 0.15 noborder lc rgb '"
     << FindSeriesStyle("prediction")->colour << "' title 'predicted +- 1 sd', '' using "
     << xcol << ":2 " << GnuplotWith("prediction") << " title 'predicted'";
  if (p.has_measured)
    gp << ", '' using " << xcol << ":5 " << GnuplotWith("measured") << " title 'measured'";
  gp << "\nset title 'residual (measured - predicted)'\nset ylabel 'residual [um]'\n";
  if (p.has_measured)
    gp << "plot " << GnuplotString(plot_csv) << " using " << xcol << ":6 "
       << GnuplotWith("residual") << " title 'residual'\n";
  else
    gp << "plot 0 notitle\n";
  gp << "unset multiplot\n";
  return gp.str();
}

// Run i under the model, in one pass: its per-sample CSV, the plot's rows and script, the plot's
// HTML into `plots`; returns the prediction's summary.
PredictionSummary ShowRun(ReportWriter* w, const ShownRuns& runs, std::size_t i,
                          const DriftModel& m, const std::vector<std::string>& provenance,
                          std::ostringstream* plots) {
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
  *plots << "<h3>" << HtmlEscape(p.run) << "</h3>\n";
  for (const auto& warn : p.warnings) *plots << "<p><i>" << HtmlEscape(warn) << "</i></p>\n";
  *plots << w->Plot(slug + "_prediction", RunPlotScript(m, p, plot_csv),
                    "measured and predicted error of " + p.run)
         << "\n";
  return p;
}

DriftReportResult ModelReport(const fs::path& dir, const FitReport& fit, const ShownRuns& runs,
                              const std::vector<std::string>& provenance,
                              const std::string& gnuplot) {
  ReportWriter w(dir, gnuplot);
  const DriftModel& m = fit.model;
  std::ostringstream h;
  h << Head("whirl: machine thermal drift of " + m.error_column, provenance);
  h << "<h2>Model</h2>\n<pre>" << HtmlEscape(FormatModel(m)) << "</pre>\n";
  if (!fit.candidates.empty()) h << "<pre>" << HtmlEscape(FormatCandidates(fit)) << "</pre>\n";
  if (fit.selected)
    h << SelectionHtml(fit.selection) << SimilarityPlot(&w, fit.selection) << "\n"
      << LevelsPlot(&w, fit.selection) << "\n";
  h << "<h2>Runs</h2>\n<table><tr><th style='text-align:left'>run</th><th>MAE um</th><th>RMSE "
       "um</th>"
       "<th>std um</th><th>max um</th></tr>\n";
  std::ostringstream plots;
  std::vector<PredictionSummary> preds;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const PredictionSummary& p = preds.emplace_back(ShowRun(&w, runs, i, m, provenance, &plots));
    if (p.has_measured)
      h << StatsRow(p.run + " (model)", p.residual)
        << StatsRow(p.run + " (no compensation)", p.none);
  }
  h << "</table>\n";
  std::vector<std::string> notes;
  const std::vector<ReportBaseline> baselines = Baselines(m, preds, runs, &notes);
  h << BaselinesHtml(baselines, notes);
  h << plots.str();
  for (const auto& warn : w.warnings()) h << "<p><i>" << HtmlEscape(warn) << "</i></p>\n";
  h << "</body></html>\n";
  DriftReportResult result = w.Finish(h.str());
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

DriftReportResult WriteHoldoutReport(const fs::path& dir, const Run& log, const HoldoutResult& r,
                                     const std::vector<std::string>& provenance,
                                     const std::string& gnuplot) {
  ReportWriter w(dir, gnuplot);
  std::ostringstream h;
  h << Head("whirl: chronological hold-out on " + log.name, provenance);
  h << "<p>Train rows [0, " << r.train_end << ") to " << FormatDecimals(r.train_end_min / 60, 1)
    << " h; test rows [" << r.train_end << ", " << r.test_end << ") to "
    << FormatDecimals(r.test_end_min / 60, 1) << " h. Models run from the log's first row.</p>\n";
  h << "<pre>" << HtmlEscape(FormatHoldout(r)) << "</pre>\n";
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
    std::ostringstream gp;
    // Each method in its look of core/plot_style.h; the key right of the data.
    gp << "set datafile separator ','\n" << GnuplotKeyOutsideRight()
       << "set grid\nset xlabel 'time [h]'\n"
       << "set arrow from " << r.train_end_min / 60 << ", graph 0 to " << r.train_end_min / 60
       << ", graph 1 nohead dt 2\nset multiplot layout 2,1\nset ylabel 'error [um]'\nset title "
       << GnuplotString(ch + ": measured and predicted (dashed line: end of training)") << "\nplot "
       << GnuplotString(slug + "_holdout.csv") << " using ($1/60):2 " << GnuplotWith("measured")
       << " title 'measured'";
    for (std::size_t c = 1; c < idx.size(); ++c)
      gp << ", '' using ($1/60):" << c + 3 << " " << GnuplotWith(r.rows_out[idx[c]].method)
         << " title " << GnuplotString(r.rows_out[idx[c]].method);
    gp << ", '' using ($1/60):2 " << GnuplotWith("measured") << " notitle";  // on top
    gp << "\nset title 'residual (measured - predicted)'\nset ylabel 'residual [um]'\nplot ";
    for (std::size_t c = 1; c < idx.size(); ++c)
      gp << (c > 1 ? ", " : "") << GnuplotString(slug + "_holdout.csv") << " using ($1/60):($2-$"
         << c + 3 << ") " << GnuplotWith(r.rows_out[idx[c]].method) << " title "
         << GnuplotString(r.rows_out[idx[c]].method);
    gp << "\nunset multiplot\n";
    h << "<h2>" << HtmlEscape(ch) << "</h2>\n"
      << w.Plot(slug + "_holdout", gp.str(), "hold-out of " + ch) << "\n";
  }
  for (const auto& warn : w.warnings()) h << "<p><i>" << HtmlEscape(warn) << "</i></p>\n";
  h << "</body></html>\n";
  return w.Finish(h.str());
}

}  // namespace whirl::drift
