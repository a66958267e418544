#pragma once
// The page a process engineer opens after fitting a surface: one HTML file (index.html) with a
// colour map of the surface over the measured rectangle, contour lines, the measured points on
// top, the fit summary (method, condition number, residual and leave-one-out error), the choice
// between cubic and B-spline as a table with its reason and note, the 840D line per axis and the
// per-point table.
//
// Plot: gnuplot (Debian gnuplot-nox, pngcairo terminal, png when cairo is missing), run through
// core/run_program.h with an argument vector (never a shell); every user string that reaches the
// script goes through GnuplotString with noenhanced text, every one that reaches the page through
// HtmlEscape. Files in `dir`: surface_grid.dat (the map, x_mm y_mm error_um with a blank line
// between rows), points.csv (and points.dat for gnuplot), map.gp, map.png, index.html. `dir`
// follows core/output_dir.h's rule (new, empty or a whirl output; never a symbolic link); the page
// and its files are written all-or-nothing (gnuplot renders in the staging folder); if gnuplot is
// missing or fails the page is written without the picture and `warnings` says why.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "surface/choice.h"
#include "surface/line840d.h"
#include "surface/surface.h"

namespace whirl::surface {

struct SurfaceReportOptions {
  std::string title = "whirl: thermal error over the worktable";
  std::vector<std::string> provenance;  ///< lines under the title (command, input files)
  bool plots = true;
  std::string gnuplot_command = "gnuplot";
  int map_samples = 121;  ///< map grid points per direction (2..401)
  /// Files outside `dir` written in the same all-or-nothing step (e.g. the --out surface JSON).
  std::vector<std::pair<std::filesystem::path, std::string>> also_write;
};

struct SurfaceReportResult {
  std::filesystem::path index_html;
  std::vector<std::filesystem::path> files;
  bool plot_rendered = false;
  std::vector<std::string> warnings;
};

/// Writes the page into `dir` (created if missing) and `options.also_write`. `choice` and `lines`
/// may be empty.
SurfaceReportResult WriteSurfaceReport(const std::filesystem::path& dir, const SurfaceFit& fit,
                                       const MethodComparison* choice,
                                       const std::vector<AxisLine>& lines,
                                       const SurfaceReportOptions& options = {});

}  // namespace whirl::surface
