# swim_add_test(NAME <name> LABEL <unit|regression|validation> SOURCES <files...> LIBS <targets...>)
# One GoogleTest executable, every TEST discovered by CTest and labelled.
function(swim_add_test)
  cmake_parse_arguments(T "" "NAME;LABEL" "SOURCES;LIBS" ${ARGN})
  if(NOT T_LABEL MATCHES "^(unit|regression|validation)$")
    message(FATAL_ERROR "swim_add_test(${T_NAME}): LABEL must be unit, regression or validation")
  endif()
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE ${T_LIBS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${T_NAME} PRIVATE
    SWIM_SOURCE_DIR="${CMAKE_SOURCE_DIR}" SWIM_BINARY_DIR="${CMAKE_BINARY_DIR}")
  set_target_properties(${T_NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  gtest_discover_tests(${T_NAME} PROPERTIES LABELS ${T_LABEL} DISCOVERY_TIMEOUT 60)
endfunction()
