# mbopt_test_fmu(NAME): builds models/NAME.c (with models/model_frame.c) into
# binaries/<platform>/NAME.so next to models/NAME.xml as modelDescription.xml
# and zips both into ${MBOPT_TEST_FMU_DIR}/NAME.fmu. Every test FMU is part of
# the target mbopt_test_fmus (examples/fmu runs one of them).
#
# mbopt_test_fmu3(NAME): the same model as an FMI 3.0 FMU (models/NAME.c with
# models/model_frame3.c, models/NAME.fmi3.xml, binaries/<arch>-linux/) in
# ${MBOPT_TEST_FMU_DIR}/NAME_fmi3.fmu.
if(CMAKE_SYSTEM_NAME STREQUAL "Linux" AND CMAKE_SIZEOF_VOID_P EQUAL 8)
  set(MBOPT_FMU_PLATFORM linux64)
else()
  set(MBOPT_FMU_PLATFORM linux32)
endif()
# FMI 3.0 names platforms <architecture>-<system>.
if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  set(MBOPT_FMU3_PLATFORM x86_64-linux)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
  set(MBOPT_FMU3_PLATFORM aarch64-linux)
else()
  set(MBOPT_FMU3_PLATFORM ${CMAKE_SYSTEM_PROCESSOR}-linux)
endif()
set(MBOPT_TEST_FMU_DIR ${CMAKE_BINARY_DIR}/tests/fmu/archives CACHE INTERNAL "where the test FMUs are built")
set(MBOPT_TEST_FMU_MODELS ${CMAKE_CURRENT_LIST_DIR}/models)
if(NOT TARGET mbopt_test_fmus)
  add_custom_target(mbopt_test_fmus ALL)
endif()

# The shared part: FRAME over models/MODEL.c, described by DESCRIPTION, into
# binaries/PLATFORM/MODEL.so of ${MBOPT_TEST_FMU_DIR}/ARCHIVE.fmu.
function(mbopt_zip_test_fmu archive_name model frame description platform)
  set(stage ${MBOPT_TEST_FMU_DIR}/${archive_name})
  add_library(${archive_name}_fmu_binary MODULE ${MBOPT_TEST_FMU_MODELS}/${frame} ${MBOPT_TEST_FMU_MODELS}/${model}.c)
  target_include_directories(${archive_name}_fmu_binary PRIVATE ${PROJECT_SOURCE_DIR})
  set_target_properties(${archive_name}_fmu_binary PROPERTIES
    OUTPUT_NAME ${model} PREFIX "" SUFFIX ".so" C_STANDARD 99
    LIBRARY_OUTPUT_DIRECTORY ${stage}/binaries/${platform})
  target_compile_options(${archive_name}_fmu_binary PRIVATE -Wall -Wextra -Werror)
  set(archive ${MBOPT_TEST_FMU_DIR}/${archive_name}.fmu)
  add_custom_command(OUTPUT ${archive}
    COMMAND ${CMAKE_COMMAND} -E copy ${MBOPT_TEST_FMU_MODELS}/${description} ${stage}/modelDescription.xml
    COMMAND ${CMAKE_COMMAND} -E rm -f ${archive}
    COMMAND ${CMAKE_COMMAND} -E tar cf ${archive} --format=zip modelDescription.xml binaries
    WORKING_DIRECTORY ${stage}
    DEPENDS ${archive_name}_fmu_binary ${MBOPT_TEST_FMU_MODELS}/${description}
    COMMENT "Zipping the test FMU ${archive_name}.fmu"
    VERBATIM)
  add_custom_target(${archive_name}_fmu DEPENDS ${archive})
  add_dependencies(mbopt_test_fmus ${archive_name}_fmu)
endfunction()

function(mbopt_test_fmu name)
  mbopt_zip_test_fmu(${name} ${name} model_frame.c ${name}.xml ${MBOPT_FMU_PLATFORM})
endfunction()

function(mbopt_test_fmu3 name)
  mbopt_zip_test_fmu(${name}_fmi3 ${name} model_frame3.c ${name}.fmi3.xml ${MBOPT_FMU3_PLATFORM})
endfunction()
