#pragma once
// Text that leaves whirl for another interpreter: HTML pages, gnuplot scripts and the user's
// terminal. Anything a user supplies (a screw name, a run file's name, a column header, a path)
// passes through one of these before it is written into such a file or printed, so it can never
// become markup, a gnuplot command or a terminal control sequence.
#include <string>
#include <string_view>

namespace whirl {

/// HTML text and attribute values: & < > " ' become entities; control characters other than tab
/// and newline become U+FFFD. Safe inside element text and inside single- or double-quoted
/// attributes.
std::string HtmlEscape(std::string_view text);

/// A gnuplot single-quoted string literal, quotes included: ' is doubled (gnuplot's own rule for
/// single-quoted strings, where backslash has no meaning), and every control character (newline,
/// carriage return, ...) becomes a space, because a newline would end the command. The result can
/// be placed wherever gnuplot takes a string (titles, labels, file names in `plot`, `set output`).
/// Use it with a `noenhanced` terminal or `noenhanced` titles so ^ _ @ { } are printed as typed.
std::string GnuplotString(std::string_view text);

/// A file-name-safe slug: ASCII letters, digits, '-', '_' and '.' kept, every other byte '_',
/// at most `max_length` characters, never empty (then "x"), never starting with '.' or '-'.
std::string Slug(std::string_view text, std::size_t max_length = 64);

/// Text for a terminal (messages, warnings, tables on stdout/stderr): every byte that a terminal
/// could take as a control (C0 controls other than tab and newline, DEL, the C1 controls U+0080 to
/// U+009F, e.g. CSI, and bytes that are not valid UTF-8) is shown as the visible escape \xNN
/// (for C1: \u00NN); a backslash stays as it is. Valid UTF-8 text (e.g. "°C", "µm") is unchanged.
/// Why: a hostile column header or screw name holding ESC sequences could otherwise retitle the
/// window, rewrite what is on screen or, on some terminals, reach the clipboard.
std::string TerminalText(std::string_view text);

/// Offset of the first byte of `text` that does not belong to a valid UTF-8 sequence (overlong
/// forms, surrogates and code points above U+10FFFF are invalid), or std::string_view::npos when
/// all of it is UTF-8. Input files are read as UTF-8 (core/csv.h, core/json_file.h).
std::size_t InvalidUtf8Offset(std::string_view text);

/// True when a spreadsheet would evaluate a CSV cell holding `text` as a formula: it starts with
/// '=', '+', '-', '@', a tab or a carriage return (OWASP "CSV injection").
bool LooksLikeFormula(std::string_view text);

/// A CSV cell from user text that a spreadsheet shows as text: a cell that would start a formula
/// once its leading apostrophes and spaces are passed over (LooksLikeFormula) gets a leading
/// apostrophe, the spreadsheet's text marker (spreadsheets show the rest as typed, without the
/// apostrophe); anything else is unchanged. SpreadsheetText undoes it exactly, which whirl's CSV
/// reader does for column names (core/csv.h), so "-Z_um" or "'=x" survives a write and a read.
std::string SpreadsheetCell(std::string_view text);

/// The text of a cell SpreadsheetCell wrote: its leading apostrophe dropped when SpreadsheetCell
/// would have added it (SpreadsheetText(SpreadsheetCell(t)) == t for every t).
std::string SpreadsheetText(std::string_view cell);

/// One CSV cell of user text (a name, a message, a column name) in a CSV file (RFC 4180, "Common
/// Format and MIME Type for CSV Files", section 2): first SpreadsheetCell's formula guard, then a
/// cell holding ',', '"', CR, LF, ';' or a tab, or starting with '#', or with a space at either
/// end, is enclosed in double quotes with each '"' doubled; any other cell is written as it is.
/// A reader by RFC 4180 gets the text back (after the guard's apostrophe), with one cell per
/// cell, one record per row; whirl's reader (core/csv.h) gets the text itself back.
std::string CsvTextCell(std::string_view text);

/// A whole CSV line holding user text (a '#' comment, a header), made inert for spreadsheets, which
/// split it at every comma: control characters become spaces, and each comma-separated cell whose
/// first non-blank character starts a formula gets an apostrophe before that character, unless the
/// cell is a plain number ("-0.5" stays). Data rows of numbers need no such pass.
std::string SpreadsheetLine(std::string_view line);

}  // namespace whirl
