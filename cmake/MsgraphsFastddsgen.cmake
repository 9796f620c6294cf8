# msgraphs_fastddsgen(<target> [ROS2] <idl>...): a static library of the C++ that fastddsgen generates
# from the IDL files at build time, so the generated code always matches the IDL and the
# installed Fast DDS. Generated sources are not project code: included as SYSTEM headers so
# their warnings stay out of ours. fastddsgen runs on the build machine, also when
# cross-compiling.
find_program(MSGRAPHS_FASTDDSGEN fastddsgen REQUIRED)

# ROS2: -typeros2, the type names rmw_fastrtps uses ("pkg::msg::dds_::Msg_").
function(msgraphs_fastddsgen target)
  cmake_parse_arguments(arg "ROS2" "" "" ${ARGN})
  set(gen_dir ${CMAKE_CURRENT_BINARY_DIR}/${target}_gen)
  set(sources "")
  set(flags "")
  if(arg_ROS2)
    set(flags -typeros2)
  endif()
  foreach(idl IN LISTS arg_UNPARSED_ARGUMENTS)
    get_filename_component(name ${idl} NAME_WE)
    get_filename_component(idl_path ${idl} ABSOLUTE)
    set(outputs ${gen_dir}/${name}.cxx ${gen_dir}/${name}.h
                ${gen_dir}/${name}PubSubTypes.cxx ${gen_dir}/${name}PubSubTypes.h)
    add_custom_command(
      OUTPUT ${outputs}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${gen_dir}
      COMMAND ${MSGRAPHS_FASTDDSGEN} ${flags} -replace -d ${gen_dir} ${idl_path} > ${gen_dir}/${name}.fastddsgen.log
      DEPENDS ${idl_path}
      COMMENT "fastddsgen ${name}.idl"
      VERBATIM)
    list(APPEND sources ${gen_dir}/${name}.cxx ${gen_dir}/${name}PubSubTypes.cxx)
  endforeach()
  add_library(${target} STATIC ${sources})
  target_include_directories(${target} SYSTEM PUBLIC ${gen_dir})
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_link_libraries(${target} PUBLIC fastrtps fastcdr)
endfunction()
