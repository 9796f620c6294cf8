cmake_minimum_required(VERSION 3.25)
# cmake -DCASE=<case> -DEXPECT=<regex or empty> -DWORK_DIR=<dir> -DMSGRAPHS_CMAKE_DIR=<dir> -P run_case.cmake
# Configures the fixture with CASE. EXPECT empty: configure must succeed. Otherwise it must fail
# and its output must match EXPECT (the message that names the rule).
set(build_dir ${WORK_DIR}/${CASE})
file(REMOVE_RECURSE ${build_dir})
execute_process(
  COMMAND ${CMAKE_COMMAND} -S ${CMAKE_CURRENT_LIST_DIR}/fixture -B ${build_dir} -G Ninja
          -DCASE=${CASE} -DMSGRAPHS_CMAKE_DIR=${MSGRAPHS_CMAKE_DIR}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
file(REMOVE_RECURSE ${build_dir})
string(REGEX REPLACE "\n +" " " all "${out}${err}")  # CMake wraps long messages
if(EXPECT STREQUAL "")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "case ${CASE}: configure should succeed but failed:\n${out}${err}")
  endif()
  message(STATUS "case ${CASE}: configured as expected")
else()
  if(rc EQUAL 0)
    message(FATAL_ERROR "case ${CASE}: configure should have failed but succeeded:\n${out}")
  endif()
  if(NOT all MATCHES "${EXPECT}")
    message(FATAL_ERROR "case ${CASE}: failed, but without the expected message '${EXPECT}':\n${err}")
  endif()
  message(STATUS "case ${CASE}: rejected as expected:\n${err}")
endif()
