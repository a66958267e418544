#include "drift/report.h"

#include <array>
#include <cmath>
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
  // A long per-sample CSV written to disk as it is formatted (never held whole): the
  // prediction's rows through a 1 MiB buffer into the staging folder, renamed into place by Commit.
  void PredictionFile(const std::string& name, const RunPrediction& p,
                      const std::vector<std::string>& comments) {
    StreamedFile file(fs::absolute(out_.Staging()) / name);
    std::string rows = PredictionCsvHeader(p.time_from_index, p.has_measured, comments);
    for (Eigen::Index k = 0; k < p.predicted_um.size(); ++k) {
      AppendPredictionRow(p.time[static_cast<std::size_t>(k)], p.predicted_um(k), p.std_um(k),
                          p.has_measured ? &p.measured_um(k) : nullptr, &rows);
      if (rows.size() < (1u << 20)) continue;
      file.Append(rows);
      rows.clear();
    }
    file.Append(rows);
    out_.AddReady(name, file.Finish());
  }
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


// The model's training runs among the runs shown (all of them, in the model's order), or empty.
std::vector<Run> TrainingRunsShown(const DriftModel& m, const std::vector<Run>& runs) {
  std::vector<Run> found;
  for (const std::string& name : m.training_runs)
    for (const Run& r : runs)
      if (r.name == name) {
        found.push_back(r);
        break;
      }
  return found.size() == m.training_runs.size() ? found : std::vector<Run>{};
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

double BaselineMae(const DriftModel& b, const Run& run) {
  const RunPrediction p = PredictRun(b, run);
  return p.has_measured ? ComputeErrorStats(p.measured_um - p.predicted_um).mae_um : NAN;
}

// Per run shown: the model against no compensation, a time-only warm-up fitted on the model's
// training runs (first order in time since the run's start, drift/regression.h FitWarmUp), and
// drift fit at its defaults redone on the previous run shown (drift/fit.h PreviousRunOptions). A baseline that cannot be fitted (the
// training runs are not shown, too few samples) stays empty and the notes say why.
std::vector<ReportBaseline> Baselines(const DriftModel& m, const std::vector<RunPrediction>& preds,
                                     const std::vector<Run>& runs, std::vector<std::string>* notes) {
  std::vector<ReportBaseline> cells(runs.size());
  DriftModel time;
  bool have_time = false;
  const std::vector<Run> training = TrainingRunsShown(m, runs);
  if (training.empty()) {
    notes->push_back("time only: not fitted (the model's training runs are not among the runs shown)");
  } else {
    try {
      FitOptions t;
      t.kind = ModelKind::kMlr;
      t.candidates = Candidates::kTime;
      t.zero = m.zero;
      time = FitDriftModel(training, m.error_column, t).model;
      have_time = true;
    } catch (const InputError& e) {
      notes->push_back(std::string("time only: not fitted: ") + e.what());
    }
  }
  for (std::size_t i = 0; i < runs.size(); ++i) {
    ReportBaseline& c = cells[i];
    c.run = runs[i].name;
    if (!preds[i].has_measured) continue;
    c.model_mae_um = ComputeErrorStats(preds[i].measured_um - preds[i].predicted_um).mae_um;
    c.none_mae_um = ComputeErrorStats(preds[i].measured_um).mae_um;
    if (have_time) c.time_only_mae_um = BaselineMae(time, runs[i]);
    if (i > 0) {
      try {
        c.previous_run_mae_um = BaselineMae(
            FitDriftModel({runs[i - 1]}, m.error_column, PreviousRunOptions(m)).model, runs[i]);
      } catch (const InputError& e) {
        notes->push_back(std::string(kPreviousRunBaseline) + ": no refit on " + runs[i - 1].name +
                         ": " + e.what());
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

// The rows of a prediction a plot needs (core/decimate.h, M4 on predicted, measured and
// residual): the CSV gnuplot reads, whatever the run's length.
std::string PlotCsv(const RunPrediction& p, const std::vector<std::string>& comments) {
  const auto n = static_cast<std::size_t>(p.predicted_um.size());
  std::vector<std::vector<double>> series(p.has_measured ? 3 : 1, std::vector<double>(n));
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    series[0][k] = p.predicted_um(i);
    if (!p.has_measured) continue;
    series[1][k] = p.measured_um(i);
    series[2][k] = p.measured_um(i) - p.predicted_um(i);
  }
  std::string out = PredictionCsvHeader(p.time_from_index, p.has_measured, comments);
  for (const std::size_t k : M4Rows(p.time, series)) {
    const auto i = static_cast<Eigen::Index>(k);
    AppendPredictionRow(p.time[k], p.predicted_um(i), p.std_um(i),
                        p.has_measured ? &p.measured_um(i) : nullptr, &out);
  }
  return out;
}

}  // namespace

DriftReportResult WriteModelReport(const fs::path& dir, const FitReport& fit,
                                   const std::vector<Run>& runs,
                                   const std::vector<std::string>& provenance,
                                   const std::string& gnuplot) {
  std::vector<RunPrediction> preds;
  for (const Run& r : runs) preds.push_back(PredictRun(fit.model, r));  // all inputs checked first
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
  for (const RunPrediction& p : preds) {
    const std::string slug = Slug(p.run);
    w.PredictionFile(slug + "_prediction.csv", p, Comments(provenance, "prediction of " + p.run));
    if (p.has_measured) {
      h << StatsRow(p.run + " (model)", ComputeErrorStats(p.measured_um - p.predicted_um))
        << StatsRow(p.run + " (no compensation)", ComputeErrorStats(p.measured_um));
    }
    // gnuplot reads the plot's rows only (M4: at most a few thousand whatever the run's length).
    const std::string plot_csv = slug + "_plot.csv";
    w.File(plot_csv, PlotCsv(p, Comments(provenance, "rows of the plot of " + p.run +
                                                         " (M4 decimation of the prediction "
                                                         "per pixel column; all rows: " +
                                                         slug + "_prediction.csv)")));
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
    plots << "<h3>" << HtmlEscape(p.run) << "</h3>\n";
    for (const auto& warn : p.warnings) plots << "<p><i>" << HtmlEscape(warn) << "</i></p>\n";
    plots << w.Plot(slug + "_prediction", gp.str(), "measured and predicted error of " + p.run)
          << "\n";
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
  return result;
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
