#include "surface/points.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace whirl::surface {
namespace {

std::string Where(const CsvTable& t, std::size_t row, const std::string& column) {
  return t.source + ":" + std::to_string(t.line_numbers[row]) + ": column '" + column + "'";
}

void CheckRowCount(const CsvTable& t) {
  if (t.rows.size() > kMaxPoints)
    throw InputError(t.source + ": " + std::to_string(t.rows.size()) +
                     " rows, more than the limit of " + std::to_string(kMaxPoints) + " points");
}

double Checked(const CsvTable& t, std::size_t row, const std::string& column, double limit) {
  const double v = t.rows[row][t.ColumnIndex(column)];
  if (std::abs(v) > limit)
    throw InputError(Where(t, row, column) + ": value " + FormatNumber(v) + " is beyond +-" +
                     FormatNumber(limit));
  return v;
}

}  // namespace

bool Bounds::Contains(double x_mm, double y_mm) const {
  return x_mm >= x_min_mm - kSamePositionMm && x_mm <= x_max_mm + kSamePositionMm &&
         y_mm >= y_min_mm - kSamePositionMm && y_mm <= y_max_mm + kSamePositionMm;
}

Bounds BoundsOf(const std::vector<SurfacePoint>& points) {
  if (points.empty()) throw InputError("no points: the bounding box of an empty set is undefined");
  Bounds b{points[0].x_mm, points[0].x_mm, points[0].y_mm, points[0].y_mm};
  for (const auto& p : points) {
    b.x_min_mm = std::min(b.x_min_mm, p.x_mm);
    b.x_max_mm = std::max(b.x_max_mm, p.x_mm);
    b.y_min_mm = std::min(b.y_min_mm, p.y_mm);
    b.y_max_mm = std::max(b.y_max_mm, p.y_mm);
  }
  return b;
}

std::vector<SurfacePoint> PointsFromTable(const CsvTable& t) {
  CheckRowCount(t);
  for (const char* c : {"x_mm", "y_mm", "error_um"}) (void)t.ColumnIndex(c);  // all present?
  std::vector<SurfacePoint> points;
  points.reserve(t.rows.size());
  for (std::size_t r = 0; r < t.rows.size(); ++r)
    points.push_back({Checked(t, r, "x_mm", kMaxCoordinateMm),
                      Checked(t, r, "y_mm", kMaxCoordinateMm),
                      Checked(t, r, "error_um", kMaxErrorUm)});
  return points;
}

std::vector<SurfacePoint> ReadSurfacePoints(const std::filesystem::path& path) {
  return PointsFromTable(ReadCsv(path));
}

std::vector<std::pair<double, double>> ReadPositions(const std::filesystem::path& path) {
  const CsvTable t = ReadCsv(path);
  CheckRowCount(t);
  std::vector<std::pair<double, double>> xy;
  for (std::size_t r = 0; r < t.rows.size(); ++r)
    xy.emplace_back(Checked(t, r, "x_mm", kMaxCoordinateMm),
                    Checked(t, r, "y_mm", kMaxCoordinateMm));
  return xy;
}

void CheckPosition(double x_mm, double y_mm, const std::string& where) {
  for (double v : {x_mm, y_mm})
    if (!std::isfinite(v) || std::abs(v) > kMaxCoordinateMm)
      throw InputError(where + ": position " + FormatNumber(v) +
                       " mm must be finite and within +-" + FormatNumber(kMaxCoordinateMm) + " mm");
}

std::size_t CountDistinctPositions(const std::vector<SurfacePoint>& points) {
  std::vector<std::pair<double, double>> xy;
  for (const auto& p : points) xy.emplace_back(p.x_mm, p.y_mm);
  std::sort(xy.begin(), xy.end());
  std::size_t distinct = 0;
  for (std::size_t i = 0; i < xy.size(); ++i) {
    bool seen = false;
    for (std::size_t k = i; k-- > 0 && xy[i].first - xy[k].first <= kSamePositionMm;)
      if (std::abs(xy[i].second - xy[k].second) <= kSamePositionMm) seen = true;
    distinct += seen ? 0 : 1;
  }
  return distinct;
}

std::string OneLine(std::string text) {
  for (char& ch : text)
    if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = ' ';
  return text;
}

std::string FormatPointsCsv(const std::vector<SurfacePoint>& points,
                            const std::vector<std::string>& comments) {
  std::vector<std::vector<double>> rows;
  for (const auto& p : points) rows.push_back({p.x_mm, p.y_mm, p.error_um});
  std::vector<std::string> lines;
  for (const auto& c : comments) lines.push_back(OneLine(c));
  return FormatCsv({"x_mm", "y_mm", "error_um"}, rows, lines);
}

}  // namespace whirl::surface
