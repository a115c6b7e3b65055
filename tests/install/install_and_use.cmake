# The installed package, as a user meets it: `cmake --install` into a fresh prefix, then
# examples/find_package configured, built and run against that prefix alone. The example prints
# the KR 16-2's flange at the KUKA home position (A2 = -90 deg, A3 = +90 deg), which the URDF's
# SOURCE.md gives as (1.088, 0, 1.320) m; the installed URDF robot is read.
# Variables: BUILD_DIR, SOURCE_DIR, WORK_DIR, GENERATOR, CXX, LAUNCHER.
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(installed include/imscal/robot/forward_kinematics.hpp include/imscal/core/version.hpp
                  lib/libimscal_calib.a lib/libimscal_robot.a lib/cmake/imscal/imscalConfig.cmake
                  lib/cmake/imscal/imscalTargets.cmake share/imscal/robots/kr16.urdf)
  if(NOT EXISTS ${prefix}/${installed})
    message(FATAL_ERROR "not installed: ${installed}")
  endif()
endforeach()
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/find_package -B ${WORK_DIR}/build -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER}
    -DCMAKE_PREFIX_PATH=${prefix})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/flange_pose ${prefix}/share/imscal/robots/kr16.urdf 0 -90 90 0 0 0)
if(NOT output MATCHES "flange xyz_m 1\\.088000 -?0\\.000000 1\\.320000")
  message(FATAL_ERROR "unexpected flange pose:\n${output}")
endif()
message(STATUS "installed package works:\n${output}")
file(REMOVE_RECURSE ${WORK_DIR})
