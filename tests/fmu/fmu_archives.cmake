# mbopt_test_fmu(NAME): builds models/NAME.c (with models/model_frame.c) into
# binaries/<platform>/NAME.so next to models/NAME.xml as modelDescription.xml
# and zips both into ${MBOPT_TEST_FMU_DIR}/NAME.fmu. Every test FMU is part of
# the target mbopt_test_fmus (examples/fmu runs one of them).
if(CMAKE_SYSTEM_NAME STREQUAL "Linux" AND CMAKE_SIZEOF_VOID_P EQUAL 8)
  set(MBOPT_FMU_PLATFORM linux64)
else()
  set(MBOPT_FMU_PLATFORM linux32)
endif()
set(MBOPT_TEST_FMU_DIR ${CMAKE_BINARY_DIR}/tests/fmu/archives CACHE INTERNAL "where the test FMUs are built")
set(MBOPT_TEST_FMU_MODELS ${CMAKE_CURRENT_LIST_DIR}/models)
if(NOT TARGET mbopt_test_fmus)
  add_custom_target(mbopt_test_fmus ALL)
endif()

function(mbopt_test_fmu name)
  set(stage ${MBOPT_TEST_FMU_DIR}/${name})
  add_library(${name}_fmu_binary MODULE ${MBOPT_TEST_FMU_MODELS}/model_frame.c ${MBOPT_TEST_FMU_MODELS}/${name}.c)
  target_include_directories(${name}_fmu_binary PRIVATE ${PROJECT_SOURCE_DIR})
  set_target_properties(${name}_fmu_binary PROPERTIES
    OUTPUT_NAME ${name} PREFIX "" SUFFIX ".so" C_STANDARD 99
    LIBRARY_OUTPUT_DIRECTORY ${stage}/binaries/${MBOPT_FMU_PLATFORM})
  target_compile_options(${name}_fmu_binary PRIVATE -Wall -Wextra -Werror)
  set(archive ${MBOPT_TEST_FMU_DIR}/${name}.fmu)
  add_custom_command(OUTPUT ${archive}
    COMMAND ${CMAKE_COMMAND} -E copy ${MBOPT_TEST_FMU_MODELS}/${name}.xml ${stage}/modelDescription.xml
    COMMAND ${CMAKE_COMMAND} -E rm -f ${archive}
    COMMAND ${CMAKE_COMMAND} -E tar cf ${archive} --format=zip modelDescription.xml binaries
    WORKING_DIRECTORY ${stage}
    DEPENDS ${name}_fmu_binary ${MBOPT_TEST_FMU_MODELS}/${name}.xml
    COMMENT "Zipping the test FMU ${name}.fmu"
    VERBATIM)
  add_custom_target(${name}_fmu DEPENDS ${archive})
  add_dependencies(mbopt_test_fmus ${name}_fmu)
endfunction()
