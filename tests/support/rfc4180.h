#pragma once
// A reader of CSV text by RFC 4180 ("Common Format and MIME Type for CSV Files", section 2), for
// tests of the writers: fields separated by ',', records by LF or CRLF, a field in double quotes
// may hold ',', CR, LF and '"' written as "". Written from the RFC, independent of whirl's own
// code, so it can judge what whirl writes. Throws std::invalid_argument on text the RFC does not
// allow (a quote inside an unquoted field, text after a closing quote, an unclosed quote).
#include <stdexcept>
#include <string>
#include <vector>

namespace whirl::test {

inline std::vector<std::vector<std::string>> ParseRfc4180(const std::string& text) {
  std::vector<std::vector<std::string>> records;
  std::vector<std::string> record;
  std::string field;
  bool quoted = false, closed = false;
  auto end_field = [&] {
    record.push_back(field);
    field.clear();
    quoted = closed = false;
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted && !closed) {
      if (c != '"') {
        field += c;
      } else if (i + 1 < text.size() && text[i + 1] == '"') {
        field += '"';
        ++i;
      } else {
        closed = true;
      }
    } else if (c == ',') {
      end_field();
    } else if (c == '\n' || (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n')) {
      if (c == '\r') ++i;
      end_field();
      records.push_back(record);
      record.clear();
    } else if (c == '"' && field.empty() && !quoted) {
      quoted = true;
    } else if (closed || c == '"') {
      throw std::invalid_argument("RFC 4180: stray '\"' or text after a closing quote at byte " +
                                  std::to_string(i));
    } else {
      field += c;
    }
  }
  if (quoted && !closed) throw std::invalid_argument("RFC 4180: unclosed quote");
  if (!field.empty() || !record.empty() || quoted) {
    end_field();
    records.push_back(record);
  }
  return records;
}

}  // namespace whirl::test
