#pragma once
// Bad input is an exception; outcomes (a fit that did not converge) are values (STYLE.md 2).
#include <stdexcept>
#include <string>

namespace whirl {

/// Input that breaks a rule: a bad table cell, an impossible screw, a truncated model file.
/// The message names the field (file, line and column for data files), the value and the rule.
/// The command line turns it into "error: <message>" and exit code 1.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace whirl
