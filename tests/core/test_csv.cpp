#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <regex>

#include "core/csv.h"
#include "core/error.h"
#include "core/process.h"

namespace whirl {
namespace {

std::string CsvErrorOf(const std::string& text) {
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
  EXPECT_NE(CsvErrorOf("a,b\n1,x\n").find("t.csv:2: column 2 ('b')"), std::string::npos);
  EXPECT_NE(CsvErrorOf("a,b\n1,nan\n").find("not finite"), std::string::npos);
  EXPECT_NE(CsvErrorOf("a,b\n1,inf\n").find("not finite"), std::string::npos);
  EXPECT_NE(CsvErrorOf("a,b\n1,2\n3\n").find("t.csv:3: expected 2 cells"), std::string::npos);
  EXPECT_NE(CsvErrorOf("a,a\n1,2\n").find("duplicated column 'a'"), std::string::npos);
  EXPECT_NE(CsvErrorOf("a,b\n").find("no data rows"), std::string::npos);
  EXPECT_NE(CsvErrorOf("").find("empty file"), std::string::npos);
  EXPECT_NE(CsvErrorOf("a,b\n1,2x\n").find("'2x' is not a number"), std::string::npos);
  EXPECT_NE(CsvErrorOf("a,b\n1,\n").find("empty cell"), std::string::npos);
}

// A spreadsheet's semicolon or tab export (a decimal comma locale): named as such at the header,
// not as "column 1 ('a;b'): '1;2' is not a number".
TEST(Csv, SemicolonOrTabSeparatedFilesAreNamedAtTheHeader) {
  for (const std::string text : {"a;b\n1;2\n", "a;b\n1;2,5\n", "a\tb\n1\t2\n"}) {
    const std::string e = CsvErrorOf(text);
    EXPECT_NE(e.find("t.csv:1: the header is one column"), std::string::npos) << e;
    EXPECT_NE(e.find("comma-separated"), std::string::npos) << e;
  }
  const std::string semicolon = CsvErrorOf("a;b\n1;2\n");
  EXPECT_NE(semicolon.find("';'"), std::string::npos) << semicolon;
  // One named column is still one column.
  EXPECT_NE(CsvErrorOf("a\nx\n").find("'x' is not a number"), std::string::npos);
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

// Spreadsheet programs start a CSV with a UTF-8 byte-order mark: it must neither become part of
// the first column's name nor turn a first '#' comment into the header.
TEST(Csv, ByteOrderMarkIsSkipped) {
  const CsvTable t = ParseCsv("\xEF\xBB\xBFtime_min,a_C\n0,20\n", "t.csv");
  EXPECT_EQ(t.header, (std::vector<std::string>{"time_min", "a_C"}));
  EXPECT_TRUE(t.HasColumn("time_min"));
  const CsvTable c = ParseCsv("\xEF\xBB\xBF# provenance\nx,y\n1,2\n", "t.csv");
  EXPECT_EQ(c.comments, (std::vector<std::string>{"provenance"}));
  EXPECT_EQ(c.header, (std::vector<std::string>{"x", "y"}));
  EXPECT_EQ(c.header_line, 2);
  EXPECT_NE(CsvErrorOf("a,b\n1,\xEF\xBB\xBF"
                    "2\n")
                .find("t.csv:2: column 2"),
            std::string::npos)
      << "a mark inside the text is not skipped";
}

// Bytes that are not UTF-8, anywhere: refused naming the file, line, column and character, so a
// column name can never carry them on into JSON output.
TEST(Csv, InvalidUtf8IsRefusedWithLineAndColumn) {
  EXPECT_NE(
      CsvErrorOf("a,b\xFF_C\n1,2\n").find("t.csv:1: column 2, character 4: byte 0xFF is not UTF-8"),
      std::string::npos)
      << CsvErrorOf("a,b\xFF_C\n1,2\n");
  EXPECT_NE(CsvErrorOf("# \xC3\xA9t\xE9\na\n1\n").find("t.csv:1: column 1, character 5: byte 0xE9"),
            std::string::npos)
      << "in a comment, after a valid two-byte character: "
      << CsvErrorOf("# \xC3\xA9t\xE9\na\n1\n");
  EXPECT_NE(CsvErrorOf("a,b\n1,2\n3,4\xC0\x80\n").find("t.csv:3: column 2, character 4: byte 0xC0"),
            std::string::npos)
      << "an overlong form";
  EXPECT_NE(CsvErrorOf("a,b\n1,\xED\xA0\x80\n").find("t.csv:2: column 2"), std::string::npos)
      << "a surrogate";
  const CsvTable t = ParseCsv(
      "temp_\xC2\xB0"
      "C,d_\xC2\xB5m\n1,2\n",
      "t.csv");  // "°", "µ"
  EXPECT_EQ(t.header[0],
            "temp_\xC2\xB0"
            "C");
}

// Only decimal numbers: strtod would also take hexadecimal floats and other forms.
TEST(Csv, OnlyDecimalNumbers) {
  for (const char* bad : {"0x1p3", "0X10", "-0x1.8p1", "0x0", "1e", "1e+", ".", "+", "-", "1.2.3",
                          "1e5.0", "1_000", "1d3"}) {
    const std::string e = CsvErrorOf(std::string("a,b\n1,") + bad + "\n");
    EXPECT_NE(e.find("t.csv:2: column 2 ('b')"), std::string::npos) << bad << ": " << e;
  }
  EXPECT_NE(CsvErrorOf("a\n0x1p3\n").find("not a decimal number"), std::string::npos);
  for (const char* nonfinite : {"nan", "NaN", "inf", "-Infinity", "1e999"})
    EXPECT_NE(CsvErrorOf(std::string("a\n") + nonfinite + "\n").find("not finite"),
              std::string::npos)
        << nonfinite;
  const CsvTable t = ParseCsv("a,b,c,d,e,f\n1,-0.5,.5,5.,+3e-2,1E5\n", "t.csv");
  EXPECT_EQ(t.rows[0], (std::vector<double>{1, -0.5, 0.5, 5, 0.03, 1e5}));
}

// The decimal rule against an independent statement of it (a regular expression), on random
// strings over the characters that matter; accepted text reads as strtod reads it.
TEST(Csv, DecimalRuleMatchesItsRegularExpressionOnRandomText) {
  const std::regex decimal(R"([+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?)");
  const std::string alphabet = "0123456789+-.eExXpPaAnNiIfF ,";
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<std::size_t> pick(0, alphabet.size() - 1), length(0, 8);
  int accepted = 0;
  for (int i = 0; i < 200000; ++i) {
    std::string s;
    for (std::size_t n = length(rng); n > 0; --n)
      s += alphabet[pick(rng) % (i % 3 ? 13 : alphabet.size())];
    const bool finite = std::isfinite(std::strtod(s.c_str(), nullptr));
    const auto v = ParseDecimal(s);
    ASSERT_EQ(v.has_value(), std::regex_match(s, decimal) && finite) << "'" << s << "'";
    if (v) {
      EXPECT_EQ(*v, std::strtod(s.c_str(), nullptr));
      ++accepted;
    }
  }
  EXPECT_GT(accepted, 10000);
}

// Columns whose cells may be missing read empty and nan cells as NaN; the other columns and the
// column's own numbers keep every rule.
TEST(Csv, MissingAllowedColumns) {
  CsvOptions o;
  o.missing_allowed = {"time_s"};
  const CsvTable t = ParseCsv("time_s,a\n,1\nNaN,2\n3,3\n", "t.csv", o);
  EXPECT_TRUE(std::isnan(t.rows[0][0]));
  EXPECT_TRUE(std::isnan(t.rows[1][0]));
  EXPECT_EQ(t.rows[2][0], 3);
  EXPECT_THROW(ParseCsv("time_s,a\n1,\n", "t.csv", o), InputError);
  EXPECT_THROW(ParseCsv("time_s,a\n0x1p3,1\n", "t.csv", o), InputError);
  EXPECT_THROW(ParseCsv("time_s,a\ninf,1\n", "t.csv", o), InputError);
}

TEST(Csv, FormatThenParseIsIdentity) {
  std::vector<std::vector<double>> rows = {{1.0 / 3, 2e-300}, {-7, 1e10}};
  const CsvTable t = ParseCsv(FormatCsv({"x", "y"}, rows, {"c"}), "m");
  EXPECT_EQ(t.rows, rows);
}

}  // namespace
}  // namespace whirl
