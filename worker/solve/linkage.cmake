# Linkage analysis: kinematic, kinetostatic and elastodynamic formulations.
# Included at the end of worker/solve/CMakeLists.txt (after mbopt_cvodes).
mbopt_library(mbopt_linkage
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/kinematic_solver.cc
    ${CMAKE_CURRENT_LIST_DIR}/kinetostatic_solver.cc
    ${CMAKE_CURRENT_LIST_DIR}/elastodynamic_solver.cc
    ${CMAKE_CURRENT_LIST_DIR}/linkage_analysis.cc
  DEPS mbopt_linkage_model mbopt_cvodes mbopt_common Eigen3::Eigen absl::status absl::statusor
  PRIVATE_DEPS absl::strings absl::str_format)
