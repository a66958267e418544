#pragma once
// Measured (or predicted) thermal errors at points of the worktable at one moment: the input of
// both surface models (surface.h).
//
// Points CSV: a header row with the columns x_mm, y_mm, error_um (other columns are ignored),
// then one row per point; '#' lines are provenance comments (core/csv.h).
//   x_mm, y_mm  position of the point on the table (any fixed machine frame), mm
//   error_um    thermal error at that point at that moment, um
// Limits (resource and physical): at most kMaxPoints rows, |x|, |y| <= kMaxCoordinateMm,
// |error| <= kMaxErrorUm. Every violation is an InputError naming file, line, column and rule.
#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/csv.h"

namespace whirl::surface {

inline constexpr std::size_t kMaxPoints = 10000;    ///< rows of a points file
inline constexpr double kMaxCoordinateMm = 100000;  ///< |x_mm|, |y_mm| (a 100 m table)
inline constexpr double kMaxErrorUm = 100000;       ///< |error_um| (0.1 m)
/// Two coordinates closer than this are the same grid line / the same position, mm.
inline constexpr double kSamePositionMm = 1e-6;

struct SurfacePoint {
  double x_mm = 0;      ///< table X, mm
  double y_mm = 0;      ///< table Y, mm
  double error_um = 0;  ///< thermal error, um
};

/// Axis-aligned bounding box of the measured points, mm.
struct Bounds {
  double x_min_mm = 0, x_max_mm = 0, y_min_mm = 0, y_max_mm = 0;
  /// True when (x, y) lies in the box (boundary included, kSamePositionMm slack).
  bool Contains(double x_mm, double y_mm) const;
};
Bounds BoundsOf(const std::vector<SurfacePoint>& points);

/// Points from a parsed table (columns x_mm, y_mm, error_um); limits as above.
std::vector<SurfacePoint> PointsFromTable(const CsvTable& table);
/// Reads a points CSV.
std::vector<SurfacePoint> ReadSurfacePoints(const std::filesystem::path& path);

/// Query positions for prediction: a CSV with columns x_mm, y_mm (at most kMaxPoints rows).
std::vector<std::pair<double, double>> ReadPositions(const std::filesystem::path& path);

/// Checks one position given on the command line or in a file: finite, within kMaxCoordinateMm.
/// `where` names it in the message.
void CheckPosition(double x_mm, double y_mm, const std::string& where);

/// Number of distinct positions (coordinates equal within kSamePositionMm are one position).
std::size_t CountDistinctPositions(const std::vector<SurfacePoint>& points);

/// `text` on one line: every control character (newline, CR, tab, ...) becomes a space, so a user
/// string (a path) cannot end a '#' comment line of a CSV and start a data row.
std::string OneLine(std::string text);

/// CSV text x_mm,y_mm,error_um with '#' comment lines (each through OneLine).
std::string FormatPointsCsv(const std::vector<SurfacePoint>& points,
                            const std::vector<std::string>& comments = {});

}  // namespace whirl::surface
