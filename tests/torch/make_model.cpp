// Helper of the CLI smoke tests: writes a small trainbr model (torch_test_support.h) and its
// synthetic training table, so the tests depend neither on the simulator nor on `whirl train`.
// Usage: torch_make_model <model.json> <table.csv>
#include <cstdio>
#include <exception>

#include "nn/model.h"
#include "torch_test_support.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s <model.json> <table.csv>\n", argv[0]);
    return 1;
  }
  try {
    whirl::ProcessTable table = whirl::test::SyntheticTable(20, 7);
    table.comments = {"synthetic table: tests/torch/torch_test_support.h SyntheticTable(20, 7)"};
    whirl::WriteProcessTable(argv[2], table);
    whirl::nn::SaveModel(argv[1], whirl::test::SmallTrainedModel());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
