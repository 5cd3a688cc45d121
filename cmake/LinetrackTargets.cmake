# Helpers shared by every folder: one library per folder, strict warnings on our own code only.

# Warnings for the project's own targets (third-party headers are included as SYSTEM by their
# imported targets, so -Werror does not trip on them).
function(linetrack_strict_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Werror)
endfunction()

# linetrack_add_library(NAME linetrack_models SRCS a.cc b.cc PUBLIC_LINK ... PRIVATE_LINK ...)
function(linetrack_add_library)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;PUBLIC_LINK;PRIVATE_LINK" ${ARGN})
  add_library(${ARG_NAME} STATIC ${ARG_SRCS})
  target_include_directories(${ARG_NAME} PUBLIC ${LINETRACK_SOURCE_DIR})
  target_link_libraries(${ARG_NAME} PUBLIC ${ARG_PUBLIC_LINK} PRIVATE ${ARG_PRIVATE_LINK})
  set_target_properties(${ARG_NAME} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  linetrack_strict_warnings(${ARG_NAME})
endfunction()

# linetrack_add_test(NAME models_cao_reader SRCS cao_reader_test.cc LINK linetrack_models)
# Test names read like `models.CaoReader.Parses...` in ctest. Optional PROPERTIES are ctest
# properties for every test of the binary (e.g. LABELS aravis RESOURCE_LOCK gige_port; COST puts
# the slow binaries first in a parallel ctest run). Optional SUITES are test suites that ctest
# runs as one test each (`PREFIX.Suite`), in one process, so that a suite's SetUpTestSuite does
# its expensive set-up once; every other test is a ctest test of its own.
function(linetrack_add_test)
  cmake_parse_arguments(ARG "" "NAME;PREFIX" "SRCS;LINK;PROPERTIES;SUITES" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SRCS})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_LINK} GTest::gtest GTest::gtest_main)
  target_include_directories(${ARG_NAME} PRIVATE ${LINETRACK_SOURCE_DIR})  # tests/support/
  target_compile_definitions(${ARG_NAME} PRIVATE
    LINETRACK_SOURCE_DIR="${LINETRACK_SOURCE_DIR}"
    LINETRACK_BINARY_DIR="${CMAKE_BINARY_DIR}")
  linetrack_strict_warnings(${ARG_NAME})
  set(properties ${ARG_PROPERTIES})
  if(LINETRACK_SANITIZE)  # leaks inside third-party libraries only; see the file
    list(APPEND properties ENVIRONMENT
         "LSAN_OPTIONS=suppressions=${LINETRACK_SOURCE_DIR}/tests/lsan_suppressions.txt")
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
