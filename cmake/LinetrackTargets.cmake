# Helpers shared by every folder: one library per folder, strict warnings on our own code only.

# Warnings for the project's own targets (third-party headers are included as SYSTEM by their
# imported targets, so -Werror does not trip on them).
function(linetrack_strict_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Werror)
endfunction()

# Sources compiled on their own in a unity build (-DCMAKE_UNITY_BUILD=ON, which scripts/test.sh
# and scripts/demo.sh use: each target's files compiled as a few large translation units): they
# define a file-local name that another file of the same target defines too.
function(linetrack_unity_apart)
  set_source_files_properties(${ARGN} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
endfunction()

# Precompiled headers: the third-party headers that most of the project's files include (Eigen in
# nine files of ten, ViSP's pose and image types in four of ten, GoogleTest in every test), parsed
# once per build instead of once per file. One header is compiled for the libraries (the first
# library built, linetrack_models, hosts it) and one for the tests (linetrack_test_pch).
set(LINETRACK_PCH_HEADERS <algorithm> <cmath> <functional> <map> <memory> <optional> <sstream>
    <string> <vector> <Eigen/Core> <Eigen/Geometry> <visp3/core/vpHomogeneousMatrix.h>
    <visp3/core/vpImage.h>)

# linetrack_add_library(NAME linetrack_models SRCS a.cc b.cc PUBLIC_LINK ... PRIVATE_LINK ...)
function(linetrack_add_library)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;PUBLIC_LINK;PRIVATE_LINK" ${ARGN})
  add_library(${ARG_NAME} STATIC ${ARG_SRCS})
  target_include_directories(${ARG_NAME} PUBLIC ${LINETRACK_SOURCE_DIR})
  target_link_libraries(${ARG_NAME} PUBLIC ${ARG_PUBLIC_LINK} PRIVATE ${ARG_PRIVATE_LINK})
  set_target_properties(${ARG_NAME} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  linetrack_strict_warnings(${ARG_NAME})
  if(LINETRACK_PRECOMPILE_HEADERS)
    if(ARG_NAME STREQUAL "linetrack_models")
      target_precompile_headers(${ARG_NAME} PRIVATE ${LINETRACK_PCH_HEADERS})
    else()
      target_precompile_headers(${ARG_NAME} REUSE_FROM linetrack_models)
    endif()
  endif()
endfunction()

# The tests' compile definitions (every test binary has the same; see linetrack_add_test).
function(linetrack_test_definitions target)
  target_compile_definitions(${target} PRIVATE
    LINETRACK_SOURCE_DIR="${LINETRACK_SOURCE_DIR}"
    LINETRACK_BINARY_DIR="${CMAKE_BINARY_DIR}")
endfunction()

# The tests' precompiled header, built by an object library with a test binary's flags.
function(linetrack_add_test_pch)
  if(NOT LINETRACK_PRECOMPILE_HEADERS)
    return()
  endif()
  file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/test_pch.cc "// hosts the tests' precompiled header\n")
  add_library(linetrack_test_pch OBJECT ${CMAKE_CURRENT_BINARY_DIR}/test_pch.cc)
  target_link_libraries(linetrack_test_pch PRIVATE GTest::gtest Eigen3::Eigen ${VISP_LIBRARIES})
  target_include_directories(linetrack_test_pch PRIVATE ${LINETRACK_SOURCE_DIR} ${VISP_INCLUDE_DIRS})
  linetrack_test_definitions(linetrack_test_pch)
  linetrack_strict_warnings(linetrack_test_pch)
  target_precompile_headers(linetrack_test_pch PRIVATE <gtest/gtest.h> ${LINETRACK_PCH_HEADERS})
endfunction()

# The whole binary as one ctest test `PREFIX.NAME`, with the binary's ctest properties.
function(linetrack_add_grouped_test name prefix properties)
  add_test(NAME ${prefix}.${name} COMMAND ${name} WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})
  # A binary that runs no test exits 0: fail then.
  set_tests_properties(${prefix}.${name} PROPERTIES
    FAIL_REGULAR_EXPRESSION "\\[  PASSED  \\] 0 tests" ${properties})
endfunction()

# linetrack_add_test(NAME models_cao_reader SRCS cao_reader_test.cc LINK linetrack_models)
# Test names read like `models.CaoReader.Parses...` in ctest. Optional PROPERTIES are ctest
# properties for every test of the binary (e.g. LABELS aravis RESOURCE_LOCK gige_port; COST puts
# the slow binaries first in a parallel ctest run). Optional SUITES are test suites that ctest
# runs as one test each (`PREFIX.Suite`), in one process, so that a suite's SetUpTestSuite does
# its expensive set-up once; every other test is a ctest test of its own. A binary marked GROUPED
# (many light tests) is one ctest test when LINETRACK_GROUP_TESTS is on: the sanitizer build, where
# each process start costs about a third of a second.
function(linetrack_add_test)
  cmake_parse_arguments(ARG "GROUPED" "NAME;PREFIX" "SRCS;LINK;PROPERTIES;SUITES" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SRCS})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_LINK} GTest::gtest GTest::gtest_main)
  target_include_directories(${ARG_NAME} PRIVATE ${LINETRACK_SOURCE_DIR})  # tests/support/
  linetrack_test_definitions(${ARG_NAME})
  linetrack_strict_warnings(${ARG_NAME})
  if(LINETRACK_PRECOMPILE_HEADERS)
    target_precompile_headers(${ARG_NAME} REUSE_FROM linetrack_test_pch)
  endif()
  set(properties ${ARG_PROPERTIES})
  if(LINETRACK_SANITIZE)  # leaks inside third-party libraries only; see the file
    list(APPEND properties ENVIRONMENT
         "LSAN_OPTIONS=suppressions=${LINETRACK_SOURCE_DIR}/tests/lsan_suppressions.txt")
  endif()
  if(ARG_GROUPED AND LINETRACK_GROUP_TESTS)
    linetrack_add_grouped_test(${ARG_NAME} ${ARG_PREFIX} "${properties}")
    return()
  endif()
  set(extra_properties)
  if(properties)
    set(extra_properties PROPERTIES ${properties})
  endif()
  set(filter)
  foreach(suite IN LISTS ARG_SUITES)
    add_test(NAME ${ARG_PREFIX}.${suite} COMMAND ${ARG_NAME} --gtest_filter=${suite}.*
             WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})
    # A filter that matches nothing runs no test and exits 0: fail then.
    set_tests_properties(${ARG_PREFIX}.${suite} PROPERTIES
      FAIL_REGULAR_EXPRESSION "\\[  PASSED  \\] 0 tests" ${properties})
    list(APPEND filter ${suite}.*)
  endforeach()
  if(filter)
    list(JOIN filter ":" filter)
    set(filter TEST_FILTER "-${filter}")
  endif()
  gtest_discover_tests(${ARG_NAME} TEST_PREFIX "${ARG_PREFIX}." DISCOVERY_TIMEOUT 60
    WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR} ${filter} ${extra_properties})
endfunction()
