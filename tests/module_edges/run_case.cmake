# Runs the module edge checker in script mode on one fixture tree and
# compares its verdict with the tree's expected.txt: "PASS", or lines that
# must each appear in the checker's error output (the last one gives the
# number of violations, so that no extra violation goes unnoticed).
#   cmake -DCHECKER=<cmake/ModuleEdges.cmake> -DTREE=<fixture dir> -P run_case.cmake
cmake_minimum_required(VERSION 3.25)
execute_process(
  COMMAND "${CMAKE_COMMAND}" "-DROOT=${TREE}" "-DDECLARATION=${TREE}/modules.cmake" -P "${CHECKER}"
  RESULT_VARIABLE result
  OUTPUT_VARIABLE output
  ERROR_VARIABLE output)
file(STRINGS "${TREE}/expected.txt" expected)
if(expected STREQUAL "PASS")
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "the checker rejected a clean tree (exit ${result}):\n${output}")
  endif()
  return()
endif()
if(result EQUAL 0)
  message(FATAL_ERROR "the checker accepted ${TREE}, which it must reject:\n${output}")
endif()
foreach(line IN LISTS expected)
  string(FIND "${output}" "${line}" at)
  if(at LESS 0)
    message(FATAL_ERROR "missing from the checker's output: ${line}\noutput:\n${output}")
  endif()
endforeach()
