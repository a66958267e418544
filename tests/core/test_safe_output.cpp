#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/parallel.h"
#include "core/run_program.h"
#include "core/safe_text.h"
#include "support/rfc4180.h"
#include "support/scratch_dir.h"

namespace whirl {
namespace {
namespace fs = std::filesystem;

TEST(SafeText, HtmlEscapeLeavesNoMarkup) {
  EXPECT_EQ(HtmlEscape("<script>alert('x')&\"</script>"),
            "&lt;script&gt;alert(&#39;x&#39;)&amp;&quot;&lt;/script&gt;");
  EXPECT_EQ(HtmlEscape("a\x01"
                       "b"),
            "a\xEF\xBF\xBD"
            "b");
  EXPECT_EQ(HtmlEscape("plain 80x10"), "plain 80x10");
}

TEST(SafeText, GnuplotStringHasNoLineBreakAndBalancedQuotes) {
  EXPECT_EQ(GnuplotString("O'Brien"), "'O''Brien'");
  const std::string hostile = "x'; system \"touch /tmp/PWNED\"; set title '\n! rm -rf /\r\\";
  const std::string q = GnuplotString(hostile);
  EXPECT_EQ(q.find('\n'), std::string::npos);
  EXPECT_EQ(q.find('\r'), std::string::npos);
  // Inside the outer quotes every ' is doubled, so the literal never closes early.
  const std::string inner = q.substr(1, q.size() - 2);
  for (std::size_t i = 0; i < inner.size(); ++i) {
    if (inner[i] != '\'') continue;
    ASSERT_LT(i + 1, inner.size());
    EXPECT_EQ(inner[i + 1], '\'');
    ++i;
  }
}

TEST(SafeText, SlugIsAFileName) {
  EXPECT_EQ(Slug("../../etc/passwd"), "_._.._etc_passwd");
  EXPECT_EQ(Slug(".."), "_.");
  EXPECT_EQ(Slug(""), "x");
  EXPECT_EQ(Slug("-rf"), "_rf");
  EXPECT_EQ(Slug(std::string(200, 'a')).size(), 64u);
}

// A strict UTF-8 reader, independent of TerminalText's own: true if `text` is valid UTF-8 and
// holds no code point a terminal takes as a control (C0 but tab/newline, DEL, C1).
bool IsInertTerminalText(const std::string& text) {
  for (std::size_t i = 0; i < text.size();) {
    const auto u = static_cast<unsigned char>(text[i]);
    std::size_t n = 0;
    unsigned cp = 0;
    if (u < 0x80) {
      n = 1, cp = u;
    } else if ((u & 0xE0) == 0xC0) {
      n = 2, cp = u & 0x1F;
    } else if ((u & 0xF0) == 0xE0) {
      n = 3, cp = u & 0x0F;
    } else if ((u & 0xF8) == 0xF0) {
      n = 4, cp = u & 0x07;
    } else {
      return false;
    }
    if (i + n > text.size()) return false;
    for (std::size_t k = 1; k < n; ++k) {
      const auto c = static_cast<unsigned char>(text[i + k]);
      if ((c & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (c & 0x3F);
    }
    const unsigned min_cp[] = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < min_cp[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    if ((cp < 0x20 && cp != '\t' && cp != '\n') || (cp >= 0x7F && cp <= 0x9F)) return false;
    i += n;
  }
  return true;
}

TEST(SafeText, TerminalTextShowsControlsAsVisibleEscapes) {
  EXPECT_EQ(TerminalText("sensor\x1b]0;pwned\x07 T1"), "sensor\\x1B]0;pwned\\x07 T1");
  EXPECT_EQ(TerminalText("a\rb\x7f"), "a\\x0Db\\x7F");
  EXPECT_EQ(TerminalText("csi \xc2\x9b" "2J"), "csi \\u009B2J");  // U+009B, the C1 CSI
  EXPECT_EQ(TerminalText("lone \x9b byte"), "lone \\x9B byte");      // not UTF-8
  EXPECT_EQ(TerminalText("overlong \xc0\x9b"), "overlong \\xC0\\x9B");
  EXPECT_EQ(TerminalText("cut \xe2\x82"), "cut \\xE2\\x82");       // truncated sequence
  // Ordinary text, tab, newline, backslash and valid UTF-8 (degree sign, micro, CJK) unchanged.
  const std::string plain = "T_bed [\xc2\xb0" "C]\t12.5 \xc2\xb5m\n\xe4\xb8\x9d\xe6\x9d\xa0 C:\\x";
  EXPECT_EQ(TerminalText(plain), plain);
}

// Property over random byte strings: the output is always inert terminal text, and text that
// already is inert is returned unchanged.
TEST(SafeText, TerminalTextIsAlwaysInertAndKeepsInertText) {
  std::mt19937_64 rng(20261125);
  std::uniform_int_distribution<int> byte(0, 255), length(0, 24);
  for (int trial = 0; trial < 20000; ++trial) {
    std::string text(static_cast<std::size_t>(length(rng)), '\0');
    for (char& c : text) c = static_cast<char>(byte(rng));
    const std::string shown = TerminalText(text);
    ASSERT_TRUE(IsInertTerminalText(shown)) << "trial " << trial;
    if (IsInertTerminalText(text)) {
      ASSERT_EQ(shown, text) << "trial " << trial;
    }
  }
}

// Property over random strings: a spreadsheet cell never starts a formula, not even after its
// leading spaces and apostrophes; text that does not is unchanged, one that does keeps its text
// after the apostrophe; SpreadsheetText gives the text back.
TEST(SafeText, SpreadsheetCellNeverStartsAFormula) {
  std::mt19937_64 rng(20261126);
  const std::string alphabet = "=+-@\t\r'a1 ,\"";
  std::uniform_int_distribution<std::size_t> pick(0, alphabet.size() - 1), length(0, 6);
  for (int trial = 0; trial < 20000; ++trial) {
    std::string text(length(rng), '\0');
    for (char& c : text) c = alphabet[pick(rng)];
    const std::string cell = SpreadsheetCell(text);
    ASSERT_FALSE(LooksLikeFormula(cell)) << "trial " << trial;
    const std::size_t first = text.find_first_not_of("' ");
    const bool formula = first != std::string::npos &&
                         std::string("=+-@\t\r").find(text[first]) != std::string::npos;
    ASSERT_EQ(cell, formula ? "'" + text : text) << "trial " << trial;
    const std::size_t shown = cell.find_first_not_of(' ');
    if (shown != std::string::npos) {
      ASSERT_FALSE(LooksLikeFormula(cell.substr(shown))) << "trial " << trial;
    }
    ASSERT_EQ(SpreadsheetText(cell), text) << "trial " << trial;
  }
  EXPECT_EQ(SpreadsheetCell("'=x"), "''=x") << "the marker itself is not mistaken for text";
  EXPECT_EQ(SpreadsheetText("'abc"), "'abc");
}

// RFC 4180 section 2, rules 5-7, by hand: quotes only where needed, '"' doubled, the guard first.
TEST(SafeText, CsvTextCellQuotesByRfc4180) {
  EXPECT_EQ(CsvTextCell("t1_C"), "t1_C");
  EXPECT_EQ(CsvTextCell(""), "");
  EXPECT_EQ(CsvTextCell("a,b"), "\"a,b\"");
  EXPECT_EQ(CsvTextCell("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(CsvTextCell("a\nb"), "\"a\nb\"");
  EXPECT_EQ(CsvTextCell("a\rb"), "\"a\rb\"");
  EXPECT_EQ(CsvTextCell("=1+2"), "'=1+2");
  EXPECT_EQ(CsvTextCell("=A1,\"x\""), "\"'=A1,\"\"x\"\"\"");
  // Beyond the RFC's must: blanks at an end (readers trim them), ';' and tab (a decimal-comma
  // spreadsheet's separators), a leading '#' (a comment line as a row's first cell).
  EXPECT_EQ(CsvTextCell(" a"), "\" a\"");
  EXPECT_EQ(CsvTextCell("a "), "\"a \"");
  EXPECT_EQ(CsvTextCell("a;b"), "\"a;b\"");
  EXPECT_EQ(CsvTextCell("a\tb"), "\"a\tb\"");
  EXPECT_EQ(CsvTextCell("#a"), "\"#a\"");
  EXPECT_EQ(CsvTextCell("a#"), "a#");
  EXPECT_EQ(CsvTextCell(" =1"), "' =1");
}

// Property over random strings: a row of CsvTextCell cells read by an RFC 4180 reader gives one
// record with the cells' texts (each after the guard's apostrophe when it looked like a formula).
TEST(SafeText, CsvTextCellsReadBackByRfc4180) {
  std::mt19937_64 rng(20261130);
  const std::string alphabet = "=+-@\t\r\n'a1 ,\"";
  std::uniform_int_distribution<std::size_t> pick(0, alphabet.size() - 1), length(0, 6);
  for (int trial = 0; trial < 20000; ++trial) {
    std::vector<std::string> texts(3);
    std::string row;
    for (std::size_t i = 0; i < texts.size(); ++i) {
      texts[i].assign(length(rng), '\0');
      for (char& c : texts[i]) c = alphabet[pick(rng)];
      row += (i ? "," : "") + CsvTextCell(texts[i]);
    }
    const auto records = test::ParseRfc4180(row + "\r\n");
    ASSERT_EQ(records.size(), 1u) << "trial " << trial;
    ASSERT_EQ(records[0].size(), texts.size()) << "trial " << trial;
    for (std::size_t i = 0; i < texts.size(); ++i) {
      ASSERT_EQ(records[0][i], SpreadsheetCell(texts[i])) << "trial " << trial;
      ASSERT_FALSE(LooksLikeFormula(records[0][i])) << "trial " << trial;
    }
  }
}

// Property over random lines: after SpreadsheetLine no comma-separated cell starts a formula
// (first non-blank character) unless it is a plain number, there is no control character, and
// removing the inserted apostrophes gives the input with controls as spaces.
TEST(SafeText, SpreadsheetLineLeavesNoCellStartingAFormula) {
  std::mt19937_64 rng(20261127);
  const std::string alphabet = "=+-@\t\r\n ,'a1.";
  std::uniform_int_distribution<std::size_t> pick(0, alphabet.size() - 1), length(0, 12);
  for (int trial = 0; trial < 20000; ++trial) {
    std::string line(length(rng), '\0');
    for (char& c : line) c = alphabet[pick(rng)];
    const std::string out = SpreadsheetLine(line);
    std::string expected = line;
    for (char& c : expected)
      if (c == '\t' || c == '\r' || c == '\n') c = ' ';
    std::size_t start = 0;
    while (true) {
      const std::size_t end = std::min(out.find(',', start), out.size());
      const std::string cell = out.substr(start, end - start);
      ASSERT_EQ(cell.find_first_of("\t\r\n"), std::string::npos) << "trial " << trial;
      const std::size_t first = cell.find_first_not_of(' ');
      if (first != std::string::npos) {
        const std::string rest = cell.substr(first);
        char* parsed = nullptr;
        std::strtod(rest.c_str(), &parsed);
        const bool number = parsed != rest.c_str() &&
                            rest.find_first_not_of(' ', parsed - rest.c_str()) == std::string::npos;
        ASSERT_TRUE(number || !LooksLikeFormula(rest)) << "trial " << trial << ": " << out;
      }
      if (end == out.size()) break;
      start = end + 1;
    }
    // Walking both: every extra character of the output is an apostrophe right before the
    // formula character it protects.
    std::size_t j = 0;
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (j < expected.size() && out[i] == expected[j]) {
        ++j;
        continue;
      }
      ASSERT_EQ(out[i], '\'') << "trial " << trial << ": '" << line << "' -> '" << out << "'";
      ASSERT_TRUE(i + 1 < out.size() && LooksLikeFormula(out.substr(i + 1, 1)))
          << "trial " << trial;
    }
    ASSERT_EQ(j, expected.size()) << "trial " << trial << ": '" << line << "' -> '" << out << "'";
  }
}

// Gnuplot itself parses the quoted string back to the original text (control characters aside):
// the reference is gnuplot's own reader, not our encoder.
TEST(SafeText, GnuplotReadsTheStringBack) {
  if (!ProgramSucceeds({"gnuplot", "--version"})) GTEST_SKIP() << "gnuplot not installed";
  const fs::path d = whirl::test::ScratchDir() / "whirl_test_gnuplot_string";
  fs::remove_all(d);
  fs::create_directories(d);
  const std::string name = "x'; system \"touch PWNED\"; print 'y\\ \"<b>\"";
  WriteFileAtomic(d / "t.gp", "set print 'out.txt'\nprint " + GnuplotString(name) + "\n");
  ASSERT_EQ(RunProgram({"gnuplot", "t.gp"}, d, d / "log.txt"), 0);
  EXPECT_FALSE(fs::exists(d / "PWNED"));
  EXPECT_EQ(ReadTextFile(d / "out.txt"), name + "\n");
}

TEST(RunProgram, PassesArgumentsWithoutAShell) {
  const fs::path d = whirl::test::ScratchDir() / "whirl_test_run_program";
  fs::remove_all(d);
  fs::create_directories(d);
  const std::string arg = "a b; touch PWNED $(touch PWNED2) 'c'";
  ASSERT_EQ(RunProgram({"printf", "%s", arg}, d, d / "log.txt"), 0);
  EXPECT_EQ(ReadTextFile(d / "log.txt"), arg);
  EXPECT_FALSE(fs::exists(d / "PWNED"));
  EXPECT_FALSE(fs::exists(d / "PWNED2"));
  EXPECT_EQ(RunProgram({"false"}), 1);
  EXPECT_EQ(RunProgram({"whirl-no-such-program-xyz"}), 127);
  EXPECT_EQ(RunProgram({"true"}, d / "missing"), 127);
  EXPECT_THROW(RunProgram({}), std::invalid_argument);
}

TEST(ParallelFor, SameResultForAnyThreadCount) {
  for (int threads : {1, 2, 3, 8}) {
    std::vector<double> out(1000, 0.0);
    std::atomic<std::size_t> calls{0};
    ParallelFor(out.size(), threads, [&](std::size_t i) {
      out[i] = static_cast<double>(i) * 0.5;
      ++calls;
    });
    EXPECT_EQ(calls.load(), out.size());
    for (std::size_t i = 0; i < out.size(); ++i) ASSERT_EQ(out[i], 0.5 * static_cast<double>(i));
  }
}

TEST(ParallelFor, AnyExceptionReachesTheCaller) {
  for (int threads : {1, 2, 4}) {
    EXPECT_THROW(ParallelFor(100, threads,
                             [](std::size_t i) {
                               if (i == 37) throw std::logic_error("not an InputError");
                             }),
                 std::logic_error);
    EXPECT_THROW(ParallelFor(10, threads, [](std::size_t) { throw 42; }), int);
  }
  std::size_t last = 0;
  ParallelFor(
      5, 2, [](std::size_t) {},
      [&](std::size_t done, std::size_t n) {
        EXPECT_EQ(n, 5u);
        last = std::max(last, done);
      });
  EXPECT_EQ(last, 5u);
}

}  // namespace
}  // namespace whirl
