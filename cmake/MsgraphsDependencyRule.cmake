# The msgraphs dependency rule, checked at configure time.
#
# Every project target is tagged with a layer (msgraphs_add_library/_executable). At the end of
# configuration msgraphs_check_dependencies() reads each target's direct link dependencies,
# classifies each one (a project layer, or an external class below) and stops configuration
# with FATAL_ERROR naming the rule when a target links something its layer may not.
#
# Because every layer's allowed set only points downwards, checking direct dependencies also
# rules out forbidden transitive paths. docs/architecture.md shows the resulting graph.

include_guard(GLOBAL)

# ---- the rule ------------------------------------------------------------------------------
# One sentence per layer: printed in the error so the reader sees the rule, not just "no".
set(_msgraphs_rule_base "base uses only the C++ standard library")
set(_msgraphs_rule_platform "platform uses base and the OS only")
set(_msgraphs_rule_core "core uses only base, the standard library and Eigen (Ceres only in core_graph)")
set(_msgraphs_rule_core_graph "core_graph uses base, core, Eigen and Ceres (Ceres PRIVATE)")
set(_msgraphs_rule_drivers "drivers use base, platform and their OS libraries, never core")
set(_msgraphs_rule_runtime "runtime may use every onboard layer and is the only one that sees Fast DDS; never PCL")
set(_msgraphs_rule_test_support "test_support uses base, platform and GoogleTest")
set(_msgraphs_rule_tools "tools are host-only programs: anything but test code")
set(_msgraphs_rule_tests "tests may use everything")
set(_msgraphs_rule_bench "benchmarks may use everything")

# Project layers each layer may link.
set(_msgraphs_layers_base base)
set(_msgraphs_layers_platform base platform)
set(_msgraphs_layers_core base core)
set(_msgraphs_layers_core_graph base core core_graph)
set(_msgraphs_layers_drivers base platform drivers)
set(_msgraphs_layers_runtime base platform core core_graph drivers runtime)
set(_msgraphs_layers_test_support base platform test_support)
set(_msgraphs_layers_tools base platform core core_graph drivers runtime tools)
set(_msgraphs_layers_tests base platform core core_graph drivers runtime tools test_support tests)
set(_msgraphs_layers_bench base platform core core_graph drivers runtime test_support bench)

# External dependency classes each layer may link.
set(_msgraphs_ext_base "")
set(_msgraphs_ext_platform os)
set(_msgraphs_ext_core eigen)
set(_msgraphs_ext_core_graph eigen ceres)
set(_msgraphs_ext_drivers os gpiod)
set(_msgraphs_ext_runtime eigen fastdds os)
set(_msgraphs_ext_test_support os gtest)
set(_msgraphs_ext_tools eigen ceres fastdds os gpiod pcl)
set(_msgraphs_ext_tests eigen ceres fastdds os gpiod pcl gtest benchmark)
set(_msgraphs_ext_bench eigen ceres fastdds os gpiod gtest benchmark zlib)

# External classes that may only be linked PRIVATE (never part of a public interface).
set(_msgraphs_private_only ceres)

set(_msgraphs_all_layers base platform core core_graph drivers runtime test_support tools tests bench)

# Classifies a link item that is not a project target. Sets <out> to the class or "".
function(_msgraphs_classify_external item out)
  set(class "")
  if(item MATCHES "^Eigen3::")
    set(class eigen)
  elseif(item MATCHES "^(Ceres::ceres|ceres)$")
    set(class ceres)
  elseif(item MATCHES "^(fastrtps|fastcdr|fastdds|fastrtps::.*|fastcdr::.*|fastdds::.*)$")
    set(class fastdds)
  elseif(item MATCHES "^(pcl_.*|PCL::.*|Boost::.*|VTK::.*|FLANN::.*|flann.*|.*/libpcl_.*)$")
    set(class pcl)
  elseif(item MATCHES "^(Threads::Threads|rt|dl|m|pthread|-pthread|atomic)$")
    set(class os)
  elseif(item MATCHES "^(PkgConfig::gpiod|PkgConfig::GPIOD|gpiod)$")
    set(class gpiod)
  elseif(item MATCHES "^(GTest::.*|gtest|gtest_main|gmock|gmock_main)$")
    set(class gtest)
  elseif(item MATCHES "^benchmark::")
    set(class benchmark)
  elseif(item MATCHES "^ZLIB::ZLIB$")
    # A peer in benchmarks only (bench/base_bench.cpp: CRC-32 against zlib's).
    set(class zlib)
  endif()
  set(${out} "${class}" PARENT_SCOPE)
endfunction()

function(_msgraphs_rule_error target layer what rule_layer)
  message(FATAL_ERROR
    "msgraphs dependency rule violated: target '${target}' (layer ${layer}) links ${what}.\n"
    "Rule: ${_msgraphs_rule_${rule_layer}}.\n"
    "See docs/architecture.md; the rule table is cmake/MsgraphsDependencyRule.cmake.")
endfunction()

# Checks one link item of <target>. <interface> is TRUE when the item is in the target's
# INTERFACE_LINK_LIBRARIES, i.e. visible to its users.
function(_msgraphs_check_item target layer raw_item interface)
  set(item "${raw_item}")
  set(link_only FALSE)
  if(item MATCHES "^\\$<LINK_ONLY:(.*)>$")
    set(item "${CMAKE_MATCH_1}")
    set(link_only TRUE)
  endif()
  if(item MATCHES "^\\$<BUILD_INTERFACE:(.*)>$")
    set(item "${CMAKE_MATCH_1}")
  endif()
  if(item STREQUAL "")
    return()
  endif()
  if(item MATCHES "^\\$<")
    _msgraphs_rule_error(${target} ${layer}
      "'${raw_item}', a generator expression the rule cannot see through (link it plainly)" ${layer})
  endif()

  if(TARGET "${item}")
    get_target_property(aliased "${item}" ALIASED_TARGET)
    if(aliased)
      set(resolved "${aliased}")
    else()
      set(resolved "${item}")
    endif()
    get_target_property(dep_layer "${resolved}" MSGRAPHS_LAYER)
    if(dep_layer)
      if(NOT dep_layer IN_LIST _msgraphs_layers_${layer})
        _msgraphs_rule_error(${target} ${layer} "'${item}' (layer ${dep_layer})" ${layer})
      endif()
      return()
    endif()
  endif()

  _msgraphs_classify_external("${item}" class)
  if(class STREQUAL "")
    message(FATAL_ERROR
      "msgraphs dependency rule: target '${target}' (layer ${layer}) links '${item}', which the rule "
      "does not know. Classify it in _msgraphs_classify_external (cmake/MsgraphsDependencyRule.cmake) "
      "and decide which layers may use it.")
  endif()
  if(NOT class IN_LIST _msgraphs_ext_${layer})
    _msgraphs_rule_error(${target} ${layer} "'${item}' (${class})" ${layer})
  endif()
  if(class IN_LIST _msgraphs_private_only AND interface AND NOT link_only)
    _msgraphs_rule_error(${target} ${layer}
      "'${item}' (${class}) in its public interface (${class} must be linked PRIVATE)" ${layer})
  endif()
endfunction()

function(msgraphs_check_dependencies)
  get_property(targets GLOBAL PROPERTY MSGRAPHS_TARGETS)
  set(checked_dirs "")
  foreach(target IN LISTS targets)
    get_target_property(layer ${target} MSGRAPHS_LAYER)
    if(NOT layer IN_LIST _msgraphs_all_layers)
      message(FATAL_ERROR "msgraphs dependency rule: target '${target}' has unknown layer '${layer}' "
                          "(known: ${_msgraphs_all_layers})")
    endif()
    get_target_property(type ${target} TYPE)
    set(direct "")
    if(NOT type STREQUAL "INTERFACE_LIBRARY")
      get_target_property(direct ${target} LINK_LIBRARIES)
    endif()
    get_target_property(iface ${target} INTERFACE_LINK_LIBRARIES)
    foreach(item IN LISTS direct)
      if(item AND NOT item MATCHES "-NOTFOUND$")
        _msgraphs_check_item(${target} ${layer} "${item}" FALSE)
      endif()
    endforeach()
    foreach(item IN LISTS iface)
      if(item AND NOT item MATCHES "-NOTFOUND$")
        _msgraphs_check_item(${target} ${layer} "${item}" TRUE)
      endif()
    endforeach()

    # Per-target settings only: no directory-wide include paths or compile options.
    get_target_property(dir ${target} SOURCE_DIR)
    if(NOT dir IN_LIST checked_dirs)
      list(APPEND checked_dirs "${dir}")
      foreach(prop INCLUDE_DIRECTORIES COMPILE_OPTIONS COMPILE_DEFINITIONS LINK_LIBRARIES)
        get_property(value DIRECTORY "${dir}" PROPERTY ${prop})
        if(value)
          message(FATAL_ERROR
            "msgraphs build rule violated: directory '${dir}' sets ${prop} (${value}) for every target "
            "in it. Attach settings to targets (target_${prop}-style commands) instead.")
        endif()
      endforeach()
    endif()
  endforeach()
  list(LENGTH targets count)
  message(STATUS "msgraphs dependency rule: ${count} targets checked")
endfunction()
