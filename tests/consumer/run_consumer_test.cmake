# Checks that the umbrella header mechbal.hpp includes every public header, installs the core from
# MECHBAL_BUILD_DIR into a scratch prefix, then configures, builds and runs the consumer project
# (which includes only <mechbal/mechbal.hpp>) against it. Fails on any step.
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${ARGV}")
  endif()
endfunction()

if(HEADER_DIR)
  file(READ ${HEADER_DIR}/mechbal.hpp umbrella)
  file(GLOB_RECURSE headers RELATIVE ${HEADER_DIR} ${HEADER_DIR}/*.hpp ${HEADER_DIR}/*.hpp.in)
  list(FILTER headers EXCLUDE REGEX "(^|/)detail/")  # private headers
  set(missing "")
  foreach(h IN LISTS headers)
    string(REGEX REPLACE "\\.in$" "" h "${h}")
    if(NOT h STREQUAL "mechbal.hpp" AND NOT umbrella MATCHES "#include \"mechbal/${h}\"")
      list(APPEND missing ${h})
    endif()
  endforeach()
  if(missing)
    message(FATAL_ERROR "mechbal.hpp does not include these public headers: ${missing}")
  endif()
endif()

run(${CMAKE_COMMAND} --install ${MECHBAL_BUILD_DIR} --prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${WORK_DIR}/build
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/consumer)
