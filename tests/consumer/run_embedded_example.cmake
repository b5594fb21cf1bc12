# The embedded example as a user builds it: install the core from MECHBAL_BUILD_DIR into a scratch
# prefix, configure and build examples/embedded against it (find_package(mechbal) only), then run
# the balanced PAMINSA under its [control] for a few hundred ticks at 1 kHz. Fails on any step.
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${ARGV}")
  endif()
endfunction()
run(${CMAKE_COMMAND} --install ${MECHBAL_BUILD_DIR} --prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/embedded -B ${WORK_DIR}/build
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/mechbal_embedded ${SOURCE_DIR}/python/mechbal/papers/paminsa/cases/paminsa-linkage.toml
    ${SOURCE_DIR}/examples/embedded/paminsa-control.toml --ticks 300)
