#pragma once
// Per-point models over the worktable (the method's first step): the thermal error is measured at P
// points of the table, each point gets its own model from its sensitive temperatures, and at any
// moment the P predictions become the points of a surface (surface.h).
//
// Position-tagged run files: the drift module's run-file format (drift/run_file.h:
// time_s or time_min, temperatures *_C, errors *_um), where each error column is one measured
// point of the table. Its position comes either
//   (a) from the column name: <name>_x<X>_y<Y>_um, X and Y in mm (optional '-', digits, optional
//       '.' and digits), e.g. p3_x400_y250_um or e_x-50.5_y0_um; or
//   (b) from a manifest, JSON {"schema": "whirl.surface_manifest", "schema_version": 1,
//       "points": [{"column": "e1_um", "x_mm": 0, "y_mm": 0}, ...]}, which wins over (a) and may
//       name a subset of the columns.
// Rules (InputError): at least one point; columns end in _um and exist in the run; no column
// twice; positions finite and within kMaxCoordinateMm; at most kMaxPoints points.
//
// The model of one point is a function (PointModelFn): given the error column, it fits the model
// on the training data it holds and returns the predicted error (um) at every sample of the target
// run. The library does not fix the model: drift_adapter.h wires Miao et al.'s sensitive points and
// MLR (src/product/drift) into it; tests use closed-form stand-ins.
#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "surface/points.h"

namespace whirl::surface {

struct PointColumn {
  std::string column;  ///< error column of the run, e.g. "p3_x400_y250_um"
  double x_mm = 0, y_mm = 0;
};

/// (X, Y) from a name <name>_x<X>_y<Y>_um; nullopt if the name does not follow the pattern.
std::optional<std::pair<double, double>> PositionFromColumnName(const std::string& column);

/// The position-tagged error columns of a header (every *_um column that follows the pattern);
/// InputError if none does. `source` names the file in messages.
std::vector<PointColumn> PointColumnsFromHeader(const std::vector<std::string>& header,
                                                const std::string& source);

/// Reads a manifest and checks it against the run's header.
std::vector<PointColumn> ReadPointManifest(const std::filesystem::path& path,
                                           const std::vector<std::string>& header);

/// Fits one point's model and predicts its error at every target sample, um.
using PointModelFn = std::function<std::vector<double>(const std::string& error_column)>;

struct PointPredictions {
  std::vector<PointColumn> points;
  Eigen::MatrixXd predicted_um;  ///< target samples x points
};

/// Runs `model` for every point (in parallel on up to `threads` threads, core/parallel.h; the
/// result does not depend on the thread count). InputError if a model returns a different number
/// of samples than the others or a non-finite value (naming the column and the sample).
PointPredictions PredictAllPoints(const std::vector<PointColumn>& points, const PointModelFn& model,
                                  int threads = 1);

/// The surface's input at one target sample: the P predicted errors at their positions.
std::vector<SurfacePoint> PointsAtSample(const PointPredictions& p, std::size_t sample);

/// CSV of every point's prediction per sample: <time_header>,<column 1>,... (um), with '#' lines.
std::string FormatPointPredictionsCsv(const PointPredictions& p, const std::vector<double>& times,
                                      const std::string& time_header,
                                      const std::vector<std::string>& comments);

/// Index of the sample whose time is nearest to `time` (ties: the earlier); InputError if empty.
std::size_t NearestSample(const std::vector<double>& times, double time);

}  // namespace whirl::surface
