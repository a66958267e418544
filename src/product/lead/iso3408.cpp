#include "lead/iso3408.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "core/csv.h"
#include "core/error.h"
#include "core/numbers.h"

namespace whirl::lead {
namespace {

constexpr IsoClass kOrder[] = {IsoClass::kP1, IsoClass::kP3, IsoClass::kP5, IsoClass::kT7,
                               IsoClass::kT10};

bool IsTransport(IsoClass c) { return c == IsoClass::kT7 || c == IsoClass::kT10; }

}  // namespace

std::string ToString(IsoClass c) {
  switch (c) {
    case IsoClass::kP1:
      return "P1";
    case IsoClass::kP3:
      return "P3";
    case IsoClass::kP5:
      return "P5";
    case IsoClass::kT7:
      return "T7";
    case IsoClass::kT10:
      return "T10";
    case IsoClass::kNone:
      return "none";
  }
  return "none";
}

IsoClass IsoClassFromString(const std::string& s) {
  for (IsoClass c : {IsoClass::kP1, IsoClass::kP3, IsoClass::kP5, IsoClass::kT7, IsoClass::kT10,
                     IsoClass::kNone})
    if (ToString(c) == s) return c;
  throw InputError("ISO class '" + s + "': must be one of P1, P3, P5, T7, T10, none");
}

IsoToleranceTable ReadIsoToleranceTable(const std::filesystem::path& path) {
  const CsvTable csv = ReadCsv(path);
  IsoToleranceTable table;
  table.source = csv.source;
  table.comments = csv.comments;
  const std::size_t c_class = csv.ColumnIndex("class"), c_min = csv.ColumnIndex("lu_min_mm"),
                    c_max = csv.ColumnIndex("lu_max_mm"), c_ep = csv.ColumnIndex("e_p_um"),
                    c_vu = csv.ColumnIndex("v_up_um"), c_v300 = csv.ColumnIndex("v_300p_um"),
                    c_v2pi = csv.ColumnIndex("v_2pi_p_um");
  const std::size_t c_flags[] = {
      csv.ColumnIndex("confirmed_e_p"), csv.ColumnIndex("confirmed_v_up"),
      csv.ColumnIndex("confirmed_v_300p"), csv.ColumnIndex("confirmed_v_2pi_p")};
  std::map<IsoClass, double> last_max;  // contiguity per class
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    const auto& row = csv.rows[i];
    const std::string where = csv.source + ":" + std::to_string(csv.line_numbers[i]) + ": ";
    auto fail = [&](std::size_t col, const std::string& rule) {
      throw InputError(where + "column '" + csv.header[col] + "' = " + FormatNumber(row[col]) +
                       ": " + rule);
    };
    IsoToleranceRow r;
    const double cls = row[c_class];
    if (cls == 1)
      r.iso_class = IsoClass::kP1;
    else if (cls == 3)
      r.iso_class = IsoClass::kP3;
    else if (cls == 5)
      r.iso_class = IsoClass::kP5;
    else if (cls == 7)
      r.iso_class = IsoClass::kT7;
    else if (cls == 10)
      r.iso_class = IsoClass::kT10;
    else
      fail(c_class, "class must be 1, 3, 5 (P1, P3, P5), 7 or 10 (T7, T10)");
    r.lu_min_mm = row[c_min];
    r.lu_max_mm = row[c_max];
    if (r.lu_min_mm < 0) fail(c_min, "must be >= 0");
    if (!(r.lu_max_mm > r.lu_min_mm)) fail(c_max, "must be greater than lu_min_mm");
    const auto it = last_max.find(r.iso_class);
    const double expected_min = it == last_max.end() ? 0.0 : it->second;
    if (r.lu_min_mm != expected_min)
      fail(c_min, "the l_u ranges of class " + ToString(r.iso_class) +
                      " must be contiguous from 0 in file order (expected " +
                      FormatNumber(expected_min) + ")");
    last_max[r.iso_class] = r.lu_max_mm;
    r.e_p_um = row[c_ep];
    r.v_up_um = row[c_vu];
    r.v_300p_um = row[c_v300];
    r.v_2pi_p_um = row[c_v2pi];
    for (std::size_t col : {c_ep, c_vu, c_v2pi})
      if (!(row[col] > 0 || row[col] == -1))
        fail(col, "a tolerance must be > 0, or -1 for 'not specified/derived'");
    if (!(r.v_300p_um > 0)) fail(c_v300, "v_300p must be > 0 for every class");
    if (!IsTransport(r.iso_class))
      for (std::size_t col : {c_ep, c_vu, c_v2pi})
        if (row[col] == -1) fail(col, "a P class needs every tolerance (no -1)");
    bool* flags[] = {&r.confirmed_e_p, &r.confirmed_v_up, &r.confirmed_v_300p,
                     &r.confirmed_v_2pi_p};
    for (int k = 0; k < 4; ++k) {
      const double f = row[c_flags[k]];
      if (f != 0 && f != 1) fail(c_flags[k], "a confirmation flag must be 0 or 1");
      *flags[k] = f == 1;
    }
    table.rows.push_back(r);
  }
  for (IsoClass c : kOrder)
    if (last_max.find(c) == last_max.end())
      throw InputError(csv.source + ": no row for class " + ToString(c) +
                       " (every class P1, P3, P5, T7, T10 needs at least one)");
  return table;
}

std::optional<IsoTolerances> IsoToleranceTable::Lookup(IsoClass c, double useful_travel_mm) const {
  for (const auto& r : rows) {
    if (r.iso_class != c) continue;
    const bool in = (r.lu_min_mm == 0 ? useful_travel_mm >= 0 : useful_travel_mm > r.lu_min_mm) &&
                    useful_travel_mm <= r.lu_max_mm;
    if (!in) continue;
    IsoTolerances t;
    t.iso_class = c;
    t.v_300p_um = r.v_300p_um;
    bool confirmed = r.confirmed_v_300p;
    if (r.e_p_um == -1) {
      t.e_p_um = useful_travel_mm / 300.0 * r.v_300p_um;  // ISO 3408-3 for classes 7 and 10
    } else {
      t.e_p_um = r.e_p_um;
      confirmed = confirmed && r.confirmed_e_p;
    }
    if (r.v_up_um != -1) {
      t.v_up_um = r.v_up_um;
      confirmed = confirmed && r.confirmed_v_up;
    }
    if (r.v_2pi_p_um != -1) {
      t.v_2pi_p_um = r.v_2pi_p_um;
      confirmed = confirmed && r.confirmed_v_2pi_p;
    }
    t.all_cells_confirmed = confirmed;
    return t;
  }
  return std::nullopt;
}

IsoVerdict EvaluateIsoClass(const LeadMetrics& m, const IsoToleranceTable& table) {
  IsoVerdict verdict;
  verdict.v_2pi_evaluated = m.v_2pi_um.has_value();
  std::string failures;
  for (IsoClass c : kOrder) {
    const auto tol = table.Lookup(c, m.useful_travel_mm);
    if (!tol) {
      failures += ToString(c) + " not tabulated for l_u " +
                  FormatDecimalsTrimmed(m.useful_travel_mm, 3) + " mm; ";
      continue;
    }
    std::vector<IsoCheck> checks;
    checks.push_back({"e_a", std::abs(m.e_a_um), tol->e_p_um, std::abs(m.e_a_um) <= tol->e_p_um});
    if (tol->v_up_um) checks.push_back({"v_u", m.v_u_um, *tol->v_up_um, m.v_u_um <= *tol->v_up_um});
    checks.push_back({"v_300", m.v_300_um, tol->v_300p_um, m.v_300_um <= tol->v_300p_um});
    if (tol->v_2pi_p_um && m.v_2pi_um)
      checks.push_back({"v_2pi", *m.v_2pi_um, *tol->v_2pi_p_um, *m.v_2pi_um <= *tol->v_2pi_p_um});
    const bool ok =
        std::all_of(checks.begin(), checks.end(), [](const IsoCheck& k) { return k.passed; });
    std::string detail;
    for (const auto& k : checks)
      detail += (detail.empty() ? "" : ", ") +
                std::string(k.metric == "e_a" ? "|e_a| " : k.metric + " ") +
                FormatDecimalsTrimmed(k.actual_um, 3) + (k.passed ? " <= " : " > ") +
                FormatDecimalsTrimmed(k.permitted_um, 3);
    verdict.checks = checks;
    if (ok) {
      verdict.reached = c;
      verdict.table_cells_confirmed = tol->all_cells_confirmed;
      verdict.message = ToString(c) + " at l_u " + FormatDecimalsTrimmed(m.useful_travel_mm, 3) +
                        " mm (" + detail + ")";
      if (!failures.empty()) verdict.message += "; " + failures.substr(0, failures.size() - 2);
      if (!verdict.v_2pi_evaluated) verdict.message += "; v_2pi not evaluated";
      return verdict;
    }
    failures += ToString(c) + " fails (" + detail + "); ";
  }
  verdict.reached = IsoClass::kNone;
  verdict.message = "no class reached: " + failures.substr(0, failures.size() - 2);
  return verdict;
}

void to_json(nlohmann::json& j, const IsoCheck& c) {
  j = nlohmann::json{{"metric", c.metric},
                     {"actual_um", c.actual_um},
                     {"permitted_um", c.permitted_um},
                     {"passed", c.passed}};
}

void to_json(nlohmann::json& j, const IsoVerdict& v) {
  j = nlohmann::json{{"reached", ToString(v.reached)},
                     {"checks", v.checks},
                     {"v_2pi_evaluated", v.v_2pi_evaluated},
                     {"table_cells_confirmed", v.table_cells_confirmed},
                     {"message", v.message}};
}

}  // namespace whirl::lead
