#pragma once
// One helper for tests of bad input: `f()` must throw an InputError whose message contains
// `fragment` (the field, value or rule the message has to name).
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

}  // namespace whirl
