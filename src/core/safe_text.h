#pragma once
// Text that leaves whirl for another interpreter: HTML pages and gnuplot scripts. Anything a user
// supplies (a screw name, a run file's name, a column header, a path) passes through one of these
// before it is written into such a file, so it can never become markup or a gnuplot command.
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

}  // namespace whirl
