# libFuzzer harnesses of every loader, built only when the compiler is Clang
# (-fsanitize=fuzzer): scripts/fuzz.sh configures such a build in build-fuzz and runs them.
# The library sources are compiled once more with coverage and ASan/UBSan for the fuzzers
# (whirl_fuzz_lib, one library of every module's sources), so the normal libraries stay
# uninstrumented. CTest label 'fuzz' (a short run of each harness over its seed corpus), excluded
# from the default run (scripts/test.sh).
if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  return()
endif()
set(WHIRL_FUZZ_FLAGS -fsanitize=address,undefined -fno-sanitize-recover=undefined -g)
set(fuzz_lib_sources)
foreach(module core sim nn gp family fit drift interp machine ballbar surface compare)
  get_target_property(sources whirl_${module} SOURCES)
  get_target_property(dir whirl_${module} SOURCE_DIR)
  foreach(src IN LISTS sources)
    if(IS_ABSOLUTE ${src})
      list(APPEND fuzz_lib_sources ${src})
    else()
      list(APPEND fuzz_lib_sources ${dir}/${src})
    endif()
  endforeach()
endforeach()
add_library(whirl_fuzz_lib STATIC ${fuzz_lib_sources})
target_include_directories(whirl_fuzz_lib PUBLIC ${PROJECT_SOURCE_DIR}/src/product
                                                 ${PROJECT_SOURCE_DIR}/src/lab ${PROJECT_SOURCE_DIR})
target_link_libraries(whirl_fuzz_lib PUBLIC Eigen3::Eigen nlohmann_json::nlohmann_json Boost::headers)
target_compile_features(whirl_fuzz_lib PUBLIC cxx_std_17)
target_compile_options(whirl_fuzz_lib PRIVATE -fsanitize=fuzzer-no-link ${WHIRL_FUZZ_FLAGS})
target_link_options(whirl_fuzz_lib INTERFACE ${WHIRL_FUZZ_FLAGS})
set_target_properties(whirl_fuzz_lib PROPERTIES EXCLUDE_FROM_ALL ON)

# name -> seed corpus (shipped files of the same kind)
set(seeds_csv ${PROJECT_SOURCE_DIR}/datasets)
set(seeds_process_table ${PROJECT_SOURCE_DIR}/datasets)
set(seeds_curve ${PROJECT_SOURCE_DIR}/tests/fuzz/seeds/curve)
set(seeds_screw ${PROJECT_SOURCE_DIR}/datasets/screws)
set(seeds_model ${PROJECT_SOURCE_DIR}/models)
set(seeds_lead ${PROJECT_SOURCE_DIR}/tests/fuzz/seeds/lead)
set(seeds_iso_table ${PROJECT_SOURCE_DIR}/datasets/standards)
set(seeds_drift_run ${PROJECT_SOURCE_DIR}/tests/fuzz/seeds/drift_run)
set(seeds_drift_model ${PROJECT_SOURCE_DIR}/tests/fuzz/seeds/drift_model)
set(seeds_machine_profile ${PROJECT_SOURCE_DIR}/datasets/machines)
set(seeds_ballbar ${PROJECT_SOURCE_DIR}/tests/fuzz/seeds/ballbar)
set(seeds_surface ${PROJECT_SOURCE_DIR}/tests/fuzz/seeds/surface)
foreach(name csv process_table curve screw model lead iso_table drift_run drift_model machine_profile
        ballbar surface)
  add_executable(fuzz_${name} ${CMAKE_CURRENT_LIST_DIR}/fuzz_${name}.cpp)
  target_link_libraries(fuzz_${name} PRIVATE whirl_fuzz_lib)
  target_compile_options(fuzz_${name} PRIVATE -fsanitize=fuzzer ${WHIRL_FUZZ_FLAGS})
  target_link_options(fuzz_${name} PRIVATE -fsanitize=fuzzer)
  set_target_properties(fuzz_${name} PROPERTIES EXCLUDE_FROM_ALL ON)
  set(corpus ${CMAKE_CURRENT_BINARY_DIR}/fuzz_corpus/${name})
  file(MAKE_DIRECTORY ${corpus})
  # New inputs go into the first (scratch) directory; the seeds are only read.
  add_test(NAME fuzz_${name}
           COMMAND fuzz_${name} -runs=3000 -max_len=8192 -timeout=10 -rss_limit_mb=2048
                   ${corpus} ${seeds_${name}})
  set_tests_properties(fuzz_${name} PROPERTIES LABELS "fuzz" TIMEOUT 600)
endforeach()
