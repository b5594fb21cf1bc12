# mechbal_add_generated(<target> <case> NAME <name> [PYTHON <python>] [FRAMES <frame>...])
#
# Generate, at build time, the C++ header of one mechanism (`mechbal codegen <case> --name <name>`)
# into ${CMAKE_CURRENT_BINARY_DIR}/mechbal_generated/<name>.hpp and put that folder on <target>'s
# include path, so that <target> can `#include "<name>.hpp"` (namespace mechbal_generated::<name>).
# <case> is a URDF or TOML file (regenerated when it changes) or a built-in case name. <python> is
# a Python that imports mechbal (default: MECHBAL_PYTHON, else Python3_EXECUTABLE, else python3).
function(mechbal_add_generated target case)
  cmake_parse_arguments(ARG "" "NAME;PYTHON" "FRAMES" ${ARGN})
  if(NOT ARG_NAME)
    message(FATAL_ERROR "mechbal_add_generated(${target} ${case}): NAME is required")
  endif()
  set(_py "${ARG_PYTHON}")
  if(NOT _py AND MECHBAL_PYTHON)
    set(_py "${MECHBAL_PYTHON}")
  endif()
  if(NOT _py AND Python3_EXECUTABLE)
    set(_py "${Python3_EXECUTABLE}")
  endif()
  if(NOT _py)
    find_program(_py NAMES python3 REQUIRED)
  endif()
  set(_dir ${CMAKE_CURRENT_BINARY_DIR}/mechbal_generated)
  set(_header ${_dir}/${ARG_NAME}.hpp)
  set(_depends "")
  if(EXISTS "${case}")
    set(_depends "${case}")
  endif()
  set(_frames "")
  if(ARG_FRAMES)
    set(_frames --frames ${ARG_FRAMES})
  endif()
  add_custom_command(
    OUTPUT ${_header}
    COMMAND ${_py} -m mechbal codegen "${case}" --out ${_dir} --name ${ARG_NAME} ${_frames} -q
    DEPENDS ${_depends}
    COMMENT "mechbal codegen ${case} -> ${ARG_NAME}.hpp"
    VERBATIM)
  add_custom_target(${target}_generated_${ARG_NAME} DEPENDS ${_header})
  add_dependencies(${target} ${target}_generated_${ARG_NAME})
  target_include_directories(${target} PRIVATE ${_dir})
endfunction()
