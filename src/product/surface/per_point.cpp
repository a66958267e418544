#include "surface/per_point.h"

#include <cmath>
#include <regex>
#include <set>

#include "core/csv.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/parallel.h"

namespace whirl::surface {
namespace {

bool EndsWithUm(const std::string& s) {
  return s.size() > 3 && s.compare(s.size() - 3, 3, "_um") == 0;
}

void CheckPoints(const std::vector<PointColumn>& points, const std::string& source) {
  if (points.empty()) throw InputError(source + ": no position-tagged error column");
  if (points.size() > kMaxPoints)
    throw InputError(source + ": " + std::to_string(points.size()) +
                     " points, more than the limit of " + std::to_string(kMaxPoints));
  std::set<std::string> seen;
  for (const auto& p : points) {
    if (!seen.insert(p.column).second)
      throw InputError(source + ": column '" + p.column + "' is given twice");
    CheckPosition(p.x_mm, p.y_mm, source + ": column '" + p.column + "'");
  }
}

}  // namespace

std::optional<std::pair<double, double>> PositionFromColumnName(const std::string& column) {
  static const std::regex kPattern(R"(^.+_x(-?[0-9]+(?:\.[0-9]+)?)_y(-?[0-9]+(?:\.[0-9]+)?)_um$)");
  std::smatch m;
  if (!std::regex_match(column, m, kPattern)) return std::nullopt;
  return std::make_pair(std::stod(m[1].str()), std::stod(m[2].str()));
}

std::vector<PointColumn> PointColumnsFromHeader(const std::vector<std::string>& header,
                                                const std::string& source) {
  std::vector<PointColumn> points;
  for (const auto& h : header)
    if (const auto xy = PositionFromColumnName(h)) points.push_back({h, xy->first, xy->second});
  if (points.empty())
    throw InputError(source +
                     ": no error column names its position (<name>_x<X>_y<Y>_um, mm); give a "
                     "manifest (surface/per_point.h)");
  CheckPoints(points, source);
  return points;
}

std::vector<PointColumn> ReadPointManifest(const std::filesystem::path& path,
                                           const std::vector<std::string>& header) {
  const std::string what = "manifest '" + path.string() + "'";
  const nlohmann::json j = ReadJsonFile(path);
  RejectUnknownKeys(j, {"schema", "schema_version", "points", "provenance"}, what);
  RequireSchema(j, "whirl.surface_manifest", 1, what);
  if (!j.contains("points") || !j.at("points").is_array())
    throw InputError(what + ": 'points' must be an array");
  std::set<std::string> have(header.begin(), header.end());
  std::vector<PointColumn> points;
  for (std::size_t k = 0; k < j.at("points").size(); ++k) {
    const auto& p = j.at("points")[k];
    const std::string where = what + " point " + std::to_string(k + 1);
    RejectUnknownKeys(p, {"column", "x_mm", "y_mm"}, where);
    const std::string column = RequireString(p, "column", where);
    if (!EndsWithUm(column))
      throw InputError(where + ": column '" + column + "' is not an error column (*_um)");
    if (!have.count(column)) throw InputError(where + ": the run has no column '" + column + "'");
    points.push_back({column, RequireNumber(p, "x_mm", where), RequireNumber(p, "y_mm", where)});
  }
  CheckPoints(points, what);
  return points;
}

PointPredictions PredictAllPoints(const std::vector<PointColumn>& points, const PointModelFn& model,
                                  int threads) {
  CheckPoints(points, "per-point models");
  std::vector<std::vector<double>> out(points.size());
  ParallelFor(points.size(), threads, [&](std::size_t k) { out[k] = model(points[k].column); });
  PointPredictions p;
  p.points = points;
  const std::size_t n = out[0].size();
  p.predicted_um.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(points.size()));
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (out[k].size() != n)
      throw InputError("per-point model of '" + points[k].column + "' returned " +
                       std::to_string(out[k].size()) + " samples, the others " + std::to_string(n));
    for (std::size_t s = 0; s < n; ++s) {
      if (!std::isfinite(out[k][s]))
        throw InputError("per-point model of '" + points[k].column +
                         "' predicted a non-finite error at sample " + std::to_string(s + 1));
      p.predicted_um(static_cast<Eigen::Index>(s), static_cast<Eigen::Index>(k)) = out[k][s];
    }
  }
  return p;
}

std::vector<SurfacePoint> PointsAtSample(const PointPredictions& p, std::size_t sample) {
  if (sample >= static_cast<std::size_t>(p.predicted_um.rows()))
    throw InputError("sample " + std::to_string(sample + 1) + " is beyond the " +
                     std::to_string(p.predicted_um.rows()) + " predicted samples");
  std::vector<SurfacePoint> out;
  for (std::size_t k = 0; k < p.points.size(); ++k)
    out.push_back(
        {p.points[k].x_mm, p.points[k].y_mm,
         p.predicted_um(static_cast<Eigen::Index>(sample), static_cast<Eigen::Index>(k))});
  return out;
}

std::string FormatPointPredictionsCsv(const PointPredictions& p, const std::vector<double>& times,
                                      const std::string& time_header,
                                      const std::vector<std::string>& comments) {
  if (times.size() != static_cast<std::size_t>(p.predicted_um.rows()))
    throw InputError("per-point predictions: " + std::to_string(times.size()) + " times for " +
                     std::to_string(p.predicted_um.rows()) + " samples");
  std::vector<std::string> header{time_header};
  for (const auto& pc : p.points) header.push_back(pc.column);
  std::vector<std::vector<double>> rows;
  for (Eigen::Index r = 0; r < p.predicted_um.rows(); ++r) {
    rows.push_back({times[static_cast<std::size_t>(r)]});
    for (Eigen::Index c = 0; c < p.predicted_um.cols(); ++c)
      rows.back().push_back(p.predicted_um(r, c));
  }
  std::vector<std::string> lines;
  for (const auto& c : comments) lines.push_back(OneLine(c));
  return FormatCsv(header, rows, lines);
}

std::size_t NearestSample(const std::vector<double>& times, double time) {
  if (times.empty()) throw InputError("no samples to pick a time from");
  if (!std::isfinite(time))
    throw InputError("time " + FormatNumber(time) + ": must be a finite number");
  std::size_t best = 0;
  for (std::size_t k = 1; k < times.size(); ++k)
    if (std::abs(times[k] - time) < std::abs(times[best] - time)) best = k;
  return best;
}

}  // namespace whirl::surface
