#pragma once
// A scratch folder of this test process. ::testing::TempDir() is one folder for every checkout
// testing on the machine, so fixed file names there race between runs that overlap; names under
// ScratchDir() do not.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace whirl::test {

// Removes the folder and what the tests left in it when the process ends.
struct ScratchDirOwner {
  std::filesystem::path dir;
  ~ScratchDirOwner() {
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
  }
};

inline std::filesystem::path ScratchDir() {
  static const ScratchDirOwner owner{std::filesystem::path(::testing::TempDir()) /
                                     ("whirl_test_" + std::to_string(::getpid()))};
  std::filesystem::create_directories(owner.dir);
  return owner.dir;
}

}  // namespace whirl::test
