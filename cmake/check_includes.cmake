cmake_minimum_required(VERSION 3.25)
# cmake -DROOT=<source tree> -P check_includes.cmake
# The include half of the dependency rule: headers a layer may not include, even though the
# compiler could find them (system headers all live in /usr/include). Fails listing every
# offending line.
set(ban_os "<(unistd|pthread|sched|fcntl|poll|signal|gpiod)\\.h>|<(sys|linux|arpa|netinet|net)/")
set(ban_io_threads_clocks "<(thread|mutex|condition_variable|future|chrono|iostream|fstream|filesystem|cstdio)>")
set(ban_up_core "msgraphs/(platform|drivers|runtime)/")
set(ban_libs_not_eigen "<(ceres|fastdds|fastrtps|fastcdr|pcl)/")

# layer directory | forbidden include regex | the rule, for the message
set(rules
  "core/base|<Eigen/|${ban_libs_not_eigen}|${ban_os}|${ban_io_threads_clocks}|msgraphs/(core|platform|drivers|runtime)/@base uses only the C++ standard library"
  "core/graph|<(fastdds|fastrtps|fastcdr|pcl)/|${ban_os}|${ban_io_threads_clocks}|${ban_up_core}@core_graph: Eigen and Ceres only, no I/O, threads or clocks"
  "core|${ban_libs_not_eigen}|${ban_os}|${ban_io_threads_clocks}|${ban_up_core}@core: standard library and Eigen only, no I/O, threads or clocks"
  "platform|<Eigen/|${ban_libs_not_eigen}|msgraphs/(core|drivers|runtime)/@platform uses base and the OS only"
  "drivers|<Eigen/|${ban_libs_not_eigen}|msgraphs/(core|runtime)/@drivers use base and platform, never core"
  "runtime|<pcl/@runtime never sees PCL")

set(violations "")
set(claimed "")
foreach(rule IN LISTS rules)
  string(REPLACE "@" ";" parts "${rule}")
  list(GET parts 1 why)
  list(GET parts 0 spec)
  string(FIND "${spec}" "|" bar)
  string(SUBSTRING "${spec}" 0 ${bar} dir)
  math(EXPR start "${bar} + 1")
  string(SUBSTRING "${spec}" ${start} -1 banned)
  file(GLOB_RECURSE files "${ROOT}/${dir}/*.hpp" "${ROOT}/${dir}/*.cpp" "${ROOT}/${dir}/*.h")
  foreach(f IN LISTS files)
    if(f IN_LIST claimed)  # the more specific folder (core/base, core/graph) decided already
      continue()
    endif()
    list(APPEND claimed "${f}")
    file(STRINGS "${f}" lines REGEX "^[ \t]*#[ \t]*include")
    foreach(line IN LISTS lines)
      if(line MATCHES "${banned}")
        file(RELATIVE_PATH rel "${ROOT}" "${f}")
        string(APPEND violations "  ${rel}: ${line}\n    rule: ${why}\n")
      endif()
    endforeach()
  endforeach()
endforeach()
if(violations)
  message(FATAL_ERROR "msgraphs include rule violated:\n${violations}")
endif()
list(LENGTH claimed n)
message(STATUS "msgraphs include rule: ${n} files checked")
