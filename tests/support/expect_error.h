#pragma once
// The helpers for tests of bad input: `f()` must throw an InputError whose message contains
// `fragment` (the field, value or rule the message has to name), or the message itself.
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

namespace whirl {

template <typename F>
void ExpectInputError(F f, const std::string& fragment) {
  try {
    f();
    ADD_FAILURE() << "no InputError (expected '" << fragment << "')";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

/// The message of the InputError `f()` throws; "" when it throws none.
template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace whirl
