#include <gtest/gtest.h>

#include <random>

#include "core/csv.h"
#include "core/error.h"
#include "core/process.h"

namespace whirl {
namespace {

std::string ErrorOf(const std::string& text) {
  try {
    ParseCsv(text, "t.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Csv, ParsesHeaderRowsAndComments) {
  const CsvTable t = ParseCsv("# made by test\na,b\n1,2.5\n\n-3e-2, 4\n", "t.csv");
  ASSERT_EQ(t.header.size(), 2u);
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[1][0], -3e-2);
  EXPECT_EQ(t.rows[1][1], 4.0);
  EXPECT_EQ(t.line_numbers[1], 5);
  EXPECT_EQ(t.comments.at(0), "made by test");
}

TEST(Csv, ErrorsNameFileLineAndColumn) {
  EXPECT_NE(ErrorOf("a,b\n1,x\n").find("t.csv:2: column 2 ('b')"), std::string::npos);
  EXPECT_NE(ErrorOf("a,b\n1,nan\n").find("not finite"), std::string::npos);
  EXPECT_NE(ErrorOf("a,b\n1,inf\n").find("not finite"), std::string::npos);
  EXPECT_NE(ErrorOf("a,b\n1,2\n3\n").find("t.csv:3: expected 2 cells"), std::string::npos);
  EXPECT_NE(ErrorOf("a,a\n1,2\n").find("duplicated column 'a'"), std::string::npos);
  EXPECT_NE(ErrorOf("a,b\n").find("no data rows"), std::string::npos);
  EXPECT_NE(ErrorOf("").find("empty file"), std::string::npos);
  EXPECT_NE(ErrorOf("a,b\n1,2x\n").find("'2x' is not a number"), std::string::npos);
  EXPECT_NE(ErrorOf("a,b\n1,\n").find("empty cell"), std::string::npos);
}

TEST(Csv, FormatNumberRoundTripsRandomDoubles) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> e(-30, 30);
  for (int i = 0; i < 10000; ++i) {
    const double x = std::ldexp(u(rng), e(rng));
    EXPECT_EQ(std::strtod(FormatNumber(x).c_str(), nullptr), x);
  }
}

// User text in a header or comment that a spreadsheet would evaluate (OWASP CSV injection) is
// written with the apostrophe text marker, in every comma-separated piece; whirl's reader drops
// the marker again, so a column such as "-Z_um" survives a write and a read.
TEST(Csv, FormulaLikeNamesAreInertInSpreadsheetsAndRoundTrip) {
  const std::vector<std::string> header = {"x", "-Z_um", "=cmd|' /C calc'!A0", "@SUM(A1)_C"};
  const std::string text =
      FormatCsv(header, {{1, 2, 3, 4}}, {"whirl predict --input v,=SUM(1+1).csv", "gain -0.5"});
  EXPECT_NE(text.find("# whirl predict --input v,'=SUM(1+1).csv\n"), std::string::npos) << text;
  EXPECT_NE(text.find("# gain -0.5\n"), std::string::npos) << "a number is not a formula";
  EXPECT_NE(text.find("\nx,'-Z_um,'=cmd|' /C calc'!A0,'@SUM(A1)_C\n"), std::string::npos) << text;
  const CsvTable t = ParseCsv(text, "m");
  EXPECT_EQ(t.header, header);
  EXPECT_EQ(t.rows, (std::vector<std::vector<double>>{{1, 2, 3, 4}}));
  EXPECT_EQ(ParseCsv("-Z_um,+X_C\n1,2\n", "m").header, (std::vector<std::string>{"-Z_um", "+X_C"}))
      << "such names are read as they are";
}

TEST(Csv, FormatThenParseIsIdentity) {
  std::vector<std::vector<double>> rows = {{1.0 / 3, 2e-300}, {-7, 1e10}};
  const CsvTable t = ParseCsv(FormatCsv({"x", "y"}, rows, {"c"}), "m");
  EXPECT_EQ(t.rows, rows);
}

}  // namespace
}  // namespace whirl
