#pragma once
// Command-line options of Miao et al.'s sensor selection (drift/selection.h), shared by the
// commands that fit drift models: whirl drift fit/crossval/holdout/... and whirl machine evaluate.
#include <CLI/CLI.hpp>
#include <string>

#include "drift/selection.h"

namespace whirl::cli {

struct SelectionArgs {
  double alpha = 0.05;
  std::string classes = "fewest";
  int max_sensors = 0;
};

/// --alpha, --classes, --max-sensors.
void AddSelectionOptions(CLI::App* sub, SelectionArgs* s);

/// The library's options; InputError for a --classes that is not fewest, margin, cv or a number.
drift::SelectionOptions ToSelection(const SelectionArgs& a);

}  // namespace whirl::cli
