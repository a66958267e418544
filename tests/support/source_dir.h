#pragma once
// The source tree of the checkout under test (WHIRL_SOURCE_DIR, set for every test executable by
// tests/CMakeLists.txt): a test file says `using test::kSource;`, which may be repeated where files
// are compiled together (unity build), unlike a definition of its own.
#include <filesystem>

namespace whirl::test {

inline const std::filesystem::path kSource{WHIRL_SOURCE_DIR};

}  // namespace whirl::test
