# Per-target defaults and the helpers every msgraphs target is declared through.
#
# There are no global include_directories / add_compile_options in this project: every setting
# is attached to a target here, and msgraphs_check_dependencies() verifies that no directory
# sneaks one in.

include_guard(GLOBAL)

# Warnings for project code. (-Wnull-dereference is left out: GCC 12 reports false positives
# through std::get_if at -O2.) -Werror is on unless MSGRAPHS_WERROR is OFF (for a newer compiler
# whose new warnings should not break a user's build).
function(msgraphs_target_defaults target)
  target_compile_features(${target} PRIVATE cxx_std_20)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion -Wdouble-promotion
    -Wcast-align -Wnon-virtual-dtor -Wold-style-cast -Woverloaded-virtual
    -Wimplicit-fallthrough -Wformat=2
    $<$<BOOL:${MSGRAPHS_WERROR}>:-Werror>)
  if(MSGRAPHS_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=${MSGRAPHS_SANITIZE} -fno-omit-frame-pointer
                                             -fno-sanitize-recover=all)
    target_link_options(${target} PRIVATE -fsanitize=${MSGRAPHS_SANITIZE})
  endif()
endfunction()

# Tags <target> with its layer and lists it for msgraphs_check_dependencies(). Targets not made
# by the helpers below (generated code, OBJECT libraries) call this directly.
function(msgraphs_register_target target layer)
  set_property(TARGET ${target} PROPERTY MSGRAPHS_LAYER ${layer})
  set_property(GLOBAL APPEND PROPERTY MSGRAPHS_TARGETS ${target})
endfunction()

# msgraphs_add_library(<name> LAYER <layer> [SOURCES ...] [HEADER_ONLY])
# Creates msgraphs_<name> with alias msgraphs::<name>, public include dir ./include, tagged with
# its layer for the dependency rule (cmake/MsgraphsDependencyRule.cmake).
function(msgraphs_add_library name)
  cmake_parse_arguments(arg "HEADER_ONLY" "LAYER" "SOURCES" ${ARGN})
  if(NOT arg_LAYER)
    message(FATAL_ERROR "msgraphs_add_library(${name}): LAYER is required")
  endif()
  set(target msgraphs_${name})
  if(arg_HEADER_ONLY)
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE
      $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
    target_compile_features(${target} INTERFACE cxx_std_20)
  else()
    add_library(${target} STATIC ${arg_SOURCES})
    target_include_directories(${target} PUBLIC
      $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
    target_compile_features(${target} PUBLIC cxx_std_20)
    msgraphs_target_defaults(${target})
  endif()
  add_library(msgraphs::${name} ALIAS ${target})
  msgraphs_register_target(${target} ${arg_LAYER})
endfunction()

# msgraphs_add_executable(<name> LAYER <runtime|tools|tests|bench> SOURCES ...)
function(msgraphs_add_executable name)
  cmake_parse_arguments(arg "" "LAYER" "SOURCES" ${ARGN})
  if(NOT arg_LAYER)
    message(FATAL_ERROR "msgraphs_add_executable(${name}): LAYER is required")
  endif()
  add_executable(${name} ${arg_SOURCES})
  msgraphs_target_defaults(${name})
  msgraphs_register_target(${name} ${arg_LAYER})
endfunction()
