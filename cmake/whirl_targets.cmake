# Helpers for the targets of whirl (included by the top-level CMakeLists.txt).

# whirl_set_warnings(<target>): -Wall -Wextra -Wpedantic behind WHIRL_WARNINGS.
function(whirl_set_warnings target)
  if(WHIRL_WARNINGS AND CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
  endif()
endfunction()

# whirl_library(<folder> <source>...): the static library of one domain folder, whirl_<folder>
# with the alias whirl::<folder>: C++17, warnings. The folder's CMakeLists.txt then links what its
# includes name:
#   target_link_libraries(whirl_<folder> PUBLIC whirl::<a>    # a header includes "a/..."
#                                        PRIVATE whirl::<b>)  # only a .cpp includes "b/..."
function(whirl_library folder)
  add_library(whirl_${folder} STATIC ${ARGN})
  add_library(whirl::${folder} ALIAS whirl_${folder})
  target_compile_features(whirl_${folder} PUBLIC cxx_std_17)
  whirl_set_warnings(whirl_${folder})
  target_compile_options(whirl_${folder} PRIVATE ${WHIRL_LIBRARY_OPTIMIZATION})
  whirl_unity_build(whirl_${folder})
  # A lab library's headers are found under src/lab (the product's under src/product, from core).
  if(CMAKE_CURRENT_SOURCE_DIR MATCHES "/src/lab/")
    target_include_directories(whirl_${folder} PUBLIC ${PROJECT_SOURCE_DIR}/src/lab)
  endif()
endfunction()

# whirl_unity_build(<target>): compile the target's files in batches of WHIRL_UNITY_BATCH_SIZE, one
# translation unit per batch (behind WHIRL_UNITY_BUILD). Each file of the libraries includes Eigen,
# nlohmann/json and the standard library and instantiates the same templates (matrix products and
# decompositions, JSON parsing and dumping); each instance is optimized once per translation unit,
# so batching saves most of that repeated work (measured in docs/development.md, "Build time").
# So the files of one folder must not define the same name twice at namespace scope, anonymous
# namespaces included: give a file's helpers names of their own. The batch size bounds what an edit
# of one file recompiles; WHIRL_UNITY_BUILD=OFF compiles file by file (and checks that each file
# includes what it uses).
function(whirl_unity_build target)
  if(WHIRL_UNITY_BUILD)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON
                                               UNITY_BUILD_BATCH_SIZE ${WHIRL_UNITY_BATCH_SIZE})
  endif()
endfunction()

# whirl_precompile(<target> <kind>): the precompiled third-party headers of <kind>, built once by
# a host target (whirl_pch_<kind>) and reused by every target of that kind (REUSE_FROM needs the
# same compile flags: one optimization level, warnings and standard per kind). One kind today:
#   test: the standard library, Eigen, nlohmann/json and GoogleTest, at the tests' optimization
#         level; measured: a test file compiles in 81 % of its time (5.3 s against 6.6 s).
# Not used where it did not pay: the libraries (a clean build's library files took 243 s of CPU
# with and without it, back to back, plus 6 s to build it: the time goes into optimizing, not
# parsing; at -O2, 2026-11-26, the libraries' batches took longer with it) and the command line
# (a unity build: too few files to pay for the header's build).
# A forced include hides a missing #include in a source file: WHIRL_PRECOMPILED_HEADERS=OFF checks.
set(WHIRL_PCH_test <algorithm> <cmath> <cstdint> <cstdio> <filesystem> <fstream> <functional>
    <map> <optional> <random> <set> <sstream> <string> <vector> <Eigen/Dense>
    <nlohmann/json.hpp> <gtest/gtest.h>)
function(whirl_precompile target kind)
  if(NOT WHIRL_PRECOMPILED_HEADERS)
    return()
  endif()
  set(host whirl_pch_${kind})
  if(NOT TARGET ${host})
    add_library(${host} OBJECT ${PROJECT_SOURCE_DIR}/cmake/pch_host.cpp)
    target_compile_features(${host} PUBLIC cxx_std_17)
    target_link_libraries(${host} PRIVATE Eigen3::Eigen nlohmann_json::nlohmann_json)
    if(kind STREQUAL "test")
      target_link_libraries(${host} PRIVATE GTest::gtest)
      target_compile_options(${host} PRIVATE ${WHIRL_TEST_OPTIMIZATION})
    endif()
    whirl_set_warnings(${host})
    target_precompile_headers(${host} PRIVATE ${WHIRL_PCH_${kind}})
  endif()
  target_precompile_headers(${target} REUSE_FROM ${host})
endfunction()
