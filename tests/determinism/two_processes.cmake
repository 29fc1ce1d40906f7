# Cross-process determinism: runs the same command twice, as two separate processes, each writing
# its own output file, and requires the two files to be identical byte for byte (a hidden global
# state, an address-dependent order or an uninitialised value would show up as a difference that a
# comparison of two runs inside one process can miss).
# cmake -DPROGRAM=<exe> -DARGS="a;b;c" -DOUT_FLAG=--out -DWORK_DIR=<dir> -P two_processes.cmake
foreach(v PROGRAM OUT_FLAG WORK_DIR)
  if(NOT ${v})
    message(FATAL_ERROR "pass -D${v}=...")
  endif()
endforeach()
file(MAKE_DIRECTORY "${WORK_DIR}")
foreach(run 1 2)
  execute_process(COMMAND "${PROGRAM}" ${ARGS} ${OUT_FLAG} "${WORK_DIR}/run${run}.out"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "run ${run} of ${PROGRAM} failed (${rc}):\n${out}\n${err}")
  endif()
endforeach()
file(SIZE "${WORK_DIR}/run1.out" size)
if(size EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} wrote an empty file: nothing was compared")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files "${WORK_DIR}/run1.out" "${WORK_DIR}/run2.out" RESULT_VARIABLE differ)
if(differ)
  message(FATAL_ERROR "two processes of ${PROGRAM} wrote different files: ${WORK_DIR}/run1.out vs run2.out")
endif()
message(STATUS "1 passed, 0 failed: ${size} bytes identical from two processes of ${PROGRAM}")
