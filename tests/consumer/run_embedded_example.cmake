# The embedded example as a user builds it: install the core from MECHBAL_BUILD_DIR into a scratch
# prefix, configure and build examples/embedded against it (find_package(mechbal) only), then run
# the balanced PAMINSA under its [control] and the reaction-wheel arm under its reactionless
# controller for a few hundred ticks at 1 kHz. Fails on any step, and when the reaction-wheel arm's
# predicted shaking moment about z is not ~0 (at most 1e-9 of the same motion's with the wheel held).
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
execute_process(COMMAND ${WORK_DIR}/build/mechbal_embedded ${SOURCE_DIR}/python/mechbal/cases/reaction-wheel-arm.toml
                        ${SOURCE_DIR}/examples/embedded/reaction-wheel-control.toml --ticks 300
                RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message("${out}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the reaction-wheel arm failed (${rc})")
endif()
if(NOT out MATCHES "cancelled moment_z: peak ([^ ]+) \\(balancing joints held: ([^)]+)\\), ratio ([^\n]+)")
  message(FATAL_ERROR "the reaction-wheel arm did not report its cancelled moment about z")
endif()
set(ratio ${CMAKE_MATCH_3})
if(NOT CMAKE_MATCH_2 GREATER 0.1 OR ratio GREATER 1e-9)
  message(FATAL_ERROR "the wheel did not cancel the shaking moment about z: held peak ${CMAKE_MATCH_2}, ratio ${ratio}")
endif()
