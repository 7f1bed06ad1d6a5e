# Helpers shared by every module's CMakeLists.

# Our own code compiles with warnings as errors; generated code does not.
function(mbopt_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Werror
    -Wno-deprecated-declarations
    # GCC 12 reports false -Wrestrict positives on std::string at -O3.
    -Wno-restrict)
  if(MBOPT_FUZZ)
    # clang warns about other things than the GCC build that gates merges.
    target_compile_options(${target} PRIVATE -Wno-error -Wno-unknown-warning-option)
  endif()
endfunction()

# mbopt_library(NAME SOURCES ... DEPS ...): a module library with warnings on.
function(mbopt_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  mbopt_warnings(${name})
  # An edited include is checked before anything compiles (ModuleEdges.cmake).
  if(TARGET mbopt_module_edges)
    add_dependencies(${name} mbopt_module_edges)
  endif()
endfunction()

# mbopt_test(NAME SOURCES ... DEPS ... LABELS ...): a GoogleTest binary whose
# tests are registered with CTest one by one, labelled (unit, integration, e2e,
# hardcase) so that `ctest -L unit` runs the fast part in seconds.
function(mbopt_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gmock GTest::gtest_main)
  mbopt_warnings(${name})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  include(GoogleTest)
  gtest_discover_tests(${name}
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT}
    DISCOVERY_TIMEOUT 60)
endfunction()

# mbopt_programs_script_test(NAME SCRIPT LABELS ... [TIMEOUT s]): a test
# written as a bash script that runs the three programs, given their paths
# as `SCRIPT MBOPT_SERVER MBOPT_WORKER MBOPT` (tests/multihost, tests/slurm).
# Registered only once all three are part of the build.
function(mbopt_programs_script_test name script)
  cmake_parse_arguments(ARG "" "TIMEOUT" "LABELS" ${ARGN})
  if(NOT (TARGET mbopt AND TARGET mbopt-server AND TARGET mbopt-worker))
    return()
  endif()
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 600)
  endif()
  add_test(NAME ${name}
    COMMAND bash ${script} $<TARGET_FILE:mbopt-server> $<TARGET_FILE:mbopt-worker> $<TARGET_FILE:mbopt>)
  set_tests_properties(${name} PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT})
endfunction()
