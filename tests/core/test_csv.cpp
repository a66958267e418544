#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>

#include "core/csv.h"
#include "core/error.h"
#include "core/process.h"
#include "core/safe_text.h"
#include "support/rfc4180.h"

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

// A spreadsheet's "save as CSV" with "quote all text cells": RFC 4180 quoted names and cells;
// "" in quotes is one '"'; a quoted number follows its column's number rules; blanks around the
// quotes are not part of the cell, blanks inside a quoted name are.
TEST(Csv, QuotedNamesAndCellsByRfc4180) {
  const CsvTable t = ParseCsv(
      "\xEF\xBB\xBF\"hardness_hrc\",\"diameter_mm\"\r\n\"58.5\",20\r\n 61 , \"-2e1\" \r\n", "t.csv");
  EXPECT_EQ(t.header, (std::vector<std::string>{"hardness_hrc", "diameter_mm"}));
  EXPECT_EQ(t.rows, (std::vector<std::vector<double>>{{58.5, 20}, {61, -20}}));
  EXPECT_EQ(t.line_numbers, (std::vector<int>{2, 3}));
  EXPECT_EQ(ParseCsv("\"say \"\"hi\"\"\",\" b \",\"c,d\"\n1,2,3\n", "t.csv").header,
            (std::vector<std::string>{"say \"hi\"", " b ", "c,d"}));
  EXPECT_NE(CsvErrorOf("a,b\n1,\"x\"\n").find("t.csv:2: column 2 ('b'): 'x' is not a number"),
            std::string::npos);
  EXPECT_NE(CsvErrorOf("a,b\n1,\"\"\n").find("t.csv:2: column 2 ('b'): empty cell"),
            std::string::npos);
  EXPECT_NE(CsvErrorOf("a,b\n1,\"0x1p3\"\n").find("not a decimal number"), std::string::npos);
  EXPECT_NE(CsvErrorOf("a,b\n1,\"2,3\"\n").find("'2,3' is not a number"), std::string::npos)
      << "a quoted comma is no separator";
  EXPECT_NE(CsvErrorOf("a,b\n\"1\",\"2\",3\n").find("t.csv:2: expected 2 cells, found 3"),
            std::string::npos);
  CsvOptions o;
  o.missing_allowed = {"time_s"};
  const CsvTable m = ParseCsv("\"time_s\",\"a\"\n\"\",1\n\"nan\",2\n", "t.csv", o);
  EXPECT_TRUE(std::isnan(m.rows[0][0]) && std::isnan(m.rows[1][0]));
  EXPECT_EQ(m.rows[1][1], 2);
}

// What RFC 4180 does not allow is refused naming the file, line, column, character and the rule.
TEST(Csv, QuotesRfc4180RefusesAreNamed) {
  const std::string stray = CsvErrorOf("a,b\"c\n1,2\n");
  EXPECT_NE(stray.find("t.csv:1: column 2, character 4: a '\"' inside a cell that does not start "
                       "with one (RFC 4180: a cell holding ',', '\"' or a line break is enclosed "
                       "in double quotes, each '\"' in it doubled)"),
            std::string::npos)
      << stray;
  EXPECT_NE(CsvErrorOf("a,b\n1,2\"\n").find("t.csv:2: column 2, character 4: a '\"' inside"),
            std::string::npos);
  EXPECT_NE(CsvErrorOf("\"a\"x,b\n1,2\n")
                .find("t.csv:1: column 1, character 4: text after the closing '\"'"),
            std::string::npos);
  EXPECT_NE(CsvErrorOf("a,\"b\" \"c\"\n1,2\n").find("t.csv:1: column 2, character 7: text after"),
            std::string::npos);
  const std::string open = CsvErrorOf("a,b\n1,\"2\n3,4\n");
  EXPECT_NE(open.find("t.csv:2: column 2, character 3: the '\"' opening this cell is never closed"),
            std::string::npos)
      << open;
  EXPECT_NE(CsvErrorOf("x\xC3\xA9,\"b,c\",d\xFF\n1,2,3\n")
                .find("t.csv:1: column 3, character 11: byte 0xFF is not UTF-8"),
            std::string::npos)
      << "the column counts cells, not commas: " << CsvErrorOf("x\xC3\xA9,\"b,c\",d\xFF\n1,2,3\n");
}

// A quoted cell may hold line breaks: the record goes on, line numbers stay the file's, and a
// '#' comment line holding a '"' is still one line.
TEST(Csv, LineBreaksInsideQuotesKeepFileLines) {
  const std::string text = "# say \"hi\n\"a\nb\",\"c\r\n\r\nd\"\n# note\n1,2\n3,x\n";
  const std::string e = CsvErrorOf(text);
  EXPECT_NE(e.find("t.csv:8: column 2 ('c\r\n\r\nd'): 'x' is not a number"), std::string::npos) << e;
  const CsvTable t = ParseCsv(text.substr(0, text.size() - 4), "t.csv");
  EXPECT_EQ(t.header, (std::vector<std::string>{"a\nb", "c\r\n\r\nd"}));
  EXPECT_EQ(t.header_line, 2);
  EXPECT_EQ(t.line_numbers, (std::vector<int>{7}));
  EXPECT_EQ(t.comments, (std::vector<std::string>{"say \"hi", "note"}));
  EXPECT_NE(CsvErrorOf("\"a\n\nx\",b\n1,2\n3\n").find("t.csv:5: expected 2 cells"),
            std::string::npos);
}

// A decimal-comma spreadsheet's export with quoted text is still named at the header; a quoted
// ';' is a character of a name.
TEST(Csv, QuotedSemicolonExportIsNamedAtTheHeader) {
  const std::string e = CsvErrorOf("\"a\";\"b\"\n1;2\n");
  EXPECT_NE(e.find("t.csv:1: the header is one column holding ';'"), std::string::npos) << e;
  EXPECT_EQ(ParseCsv("\"a;b\"\n1\n", "t.csv").header, (std::vector<std::string>{"a;b"}));
}

// Column names that need quoting, by hand: written quoted (the formula guard inside the quotes),
// each read back as it was.
TEST(Csv, NamesNeedingQuotesAreWrittenQuotedAndReadBack) {
  const std::vector<std::string> names = {"a,b", "say \"hi\"", " lead", "trail ", "x\ny",
                                          "=1+2", "'=x", "#n", "p;q", " =cmd"};
  const std::string text = FormatCsv(names, {{1, 2, 3, 4, 5, 6, 7, 8, 9, 10}});
  EXPECT_EQ(text.substr(0, text.find("\n1,")),
            "\"a,b\",\"say \"\"hi\"\"\",\" lead\",\"trail \",\"x\ny\",'=1+2,''=x,\"#n\",\"p;q\","
            "' =cmd");
  const CsvTable t = ParseCsv(text, "m");
  EXPECT_EQ(t.header, names);
  EXPECT_EQ(t.rows.at(0).at(9), 10);
}

// Random names over the characters that matter (separators, quotes, blanks, line breaks, formula
// starts, '#', the text marker, UTF-8): every table whirl writes reads back with its names and
// numbers (from text; every 25th from a file too), and its header is one RFC 4180 record (an
// independent reader) of the guarded names.
TEST(Csv, RandomNamesRoundTrip) {
  const std::vector<std::string> alphabet = {"=", "+", "-", "@", "\t", "\r", "\n", "'", "a", "1",
                                             " ", ",", "\"", ";", "#", "\xC2\xB5", "\r\n"};
  std::mt19937_64 rng(20261130);
  std::uniform_int_distribution<std::size_t> pick(0, alphabet.size() - 1), length(1, 6),
      columns(1, 4);
  const auto file = std::filesystem::temp_directory_path() / "whirl_csv_names.csv";
  for (int trial = 0; trial < 5000; ++trial) {
    std::vector<std::string> names;
    while (names.size() < columns(rng)) {
      std::string n;
      for (std::size_t k = length(rng); k > 0; --k) n += alphabet[pick(rng)];
      if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
    }
    const std::vector<std::vector<double>> rows = {std::vector<double>(names.size(), trial),
                                                   std::vector<double>(names.size(), -0.5)};
    const std::string text = FormatCsv(names, rows, {"c \"" + names[0]});
    const CsvTable t = ParseCsv(text, "m");
    ASSERT_EQ(t.header, names) << "trial " << trial << ": " << text;
    ASSERT_EQ(t.rows, rows) << "trial " << trial;
    if (trial % 25 == 0) {  // a file reader holds a 1 MiB buffer: every 25th table
      std::ofstream(file, std::ios::binary | std::ios::trunc) << text;
      CsvReader reader(file);
      ASSERT_EQ(reader.header(), names) << "trial " << trial;
    }
    const auto records = test::ParseRfc4180(text.substr(text.find('\n') + 1));
    ASSERT_EQ(records.size(), 3u) << "trial " << trial;
    for (std::size_t i = 0; i < names.size(); ++i)
      ASSERT_EQ(records[0][i], SpreadsheetCell(names[i])) << "trial " << trial;
  }
  std::filesystem::remove(file);
}

// The file reader's first chunk (1 MiB) ends before, at or after the line break inside a quoted
// cell: the rows before it and the refusal of that cell (a number cannot hold a line break) are
// ParseCsv's on the whole text, on the file's line.
TEST(Csv, QuotedRecordsAcrossChunksReadAsTheWholeText) {
  std::string rows = "\"t\nime_s\",\"v\"\n";
  for (int i = 0; rows.size() < (1u << 20) - 64; ++i)
    rows += (i % 3 ? "\"" + std::to_string(i) + "\"" : std::to_string(i)) + ", \" " +
            FormatNumber(0.25 * i) + " \"\n";
  const auto file = std::filesystem::temp_directory_path() / "whirl_csv_chunks.csv";
  for (std::size_t k = 0; k < 12; ++k) {
    // a comment line that puts the '\n' inside "1\n2" at byte 2^20 - 6 + k of the file
    const std::string pad((1u << 20) - rows.size() - 12 + k, ' ');
    const std::string text = rows + "#" + pad + "\n5,\"1\n2\"\n6,7\n";
    ASSERT_EQ(text.find("1\n2"), (1u << 20) - 6 + k - 1);
    std::ofstream(file, std::ios::binary | std::ios::trunc) << text;
    const std::string whole = CsvErrorOf(text);
    const auto line = 1 + std::count(text.begin(), text.begin() + text.find("5,\"1"), '\n');
    EXPECT_NE(whole.find(":" + std::to_string(line) + ": column 2 ('v'): '1\n2' is not a number"),
              std::string::npos)
        << whole;
    const CsvTable before = ParseCsv(rows, "t.csv");
    CsvReader reader(file);
    EXPECT_EQ(reader.header(), (std::vector<std::string>{"t\nime_s", "v"}));
    double row[2];
    int row_line = 0;
    std::size_t n = 0;
    try {
      for (; reader.Next(row, &row_line); ++n) {
        ASSERT_LT(n, before.rows.size());
        ASSERT_EQ(row_line, before.line_numbers[n]);
        ASSERT_EQ(row[0], before.rows[n][0]);
        ASSERT_EQ(row[1], before.rows[n][1]);
      }
      ADD_FAILURE() << "no error, k = " << k;
    } catch (const InputError& e) {
      EXPECT_EQ(n, before.rows.size());
      const std::string message = e.what();
      EXPECT_EQ(message.substr(message.find(':')), whole.substr(whole.find(':'))) << k;
    }
  }
  std::filesystem::remove(file);
}

// A quote never closed in a long file stops the reader at its memory bound (kMaxCsvLineBytes),
// naming where the quote opened, instead of reading the file into one record.
TEST(Csv, UnclosedQuoteStopsAtTheMemoryBound) {
  const auto file = std::filesystem::temp_directory_path() / "whirl_csv_unclosed.csv";
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out << "a,b\n1,2\n3,\"4\n";
    const std::string rows(1 << 20, '\n');
    for (std::size_t written = 0; written <= kMaxCsvLineBytes; written += rows.size()) out << rows;
  }
  CsvReader reader(file);
  double row[2];
  int line = 0;
  ASSERT_TRUE(reader.Next(row, &line));
  try {
    reader.Next(row, &line);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":3: column 2, character 3: the '\"' opening this cell "
                                         "is not closed within 16 MiB"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace whirl
