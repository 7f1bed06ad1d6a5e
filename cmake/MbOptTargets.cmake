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

# mbopt_precompile_proto_headers(TARGET): TARGET's units start from the
# precompiled Protobuf, gRPC and generated headers (proto/precompiled_headers.h).
# They dominate the front end's work in every unit of the boundary
# libraries; one precompiled header is built, by the first target asking,
# and reused by the others (they share their compile flags, as GCC requires;
# with -Winvalid-pch and -Werror a mismatch fails the build instead of
# silently parsing again). mbopt_library calls it for every library that
# links mbopt_proto.
function(mbopt_precompile_proto_headers target)
  if(NOT MBOPT_PRECOMPILED_HEADERS)
    return()
  endif()
  get_property(host GLOBAL PROPERTY MBOPT_PROTO_PCH_HOST)
  if(host)
    target_precompile_headers(${target} REUSE_FROM ${host})
  else()
    target_precompile_headers(${target} PRIVATE ${PROJECT_SOURCE_DIR}/proto/precompiled_headers.h)
    set_property(GLOBAL PROPERTY MBOPT_PROTO_PCH_HOST ${target})
  endif()
endfunction()

# mbopt_library(NAME SOURCES ... DEPS ...): a module library with warnings on.
function(mbopt_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  mbopt_warnings(${name})
  if("mbopt_proto" IN_LIST ARG_DEPS OR "mbopt_proto" IN_LIST ARG_PRIVATE_DEPS)
    mbopt_precompile_proto_headers(${name})
  endif()
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
