# Linkage model blocks: the resolved linkage and the planar beam element.
# Included at the end of worker/model/CMakeLists.txt.
mbopt_library(mbopt_linkage_model
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/linkage_model.cc ${CMAKE_CURRENT_LIST_DIR}/beam_element.cc
  DEPS mbopt_spec mbopt_common Eigen3::Eigen absl::status absl::statusor
  PRIVATE_DEPS absl::strings absl::str_format)
