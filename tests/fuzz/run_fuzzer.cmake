# Runs one fuzzer (ctest, tests/fuzz/CMakeLists.txt): a fresh copy of its corpus in WORK_DIR, then
# FUZZER on it for SECONDS (0: each corpus input once); fails on any finding, naming the input
# libFuzzer saved.
# cmake -DFUZZER=... -DCORPUS=... -DWORK_DIR=... -DSECONDS=... -DTIMEOUT=... -DRSS_MB=... -P run_fuzzer.cmake
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR}/corpus)
file(GLOB seeds ${CORPUS}/*)
file(COPY ${seeds} DESTINATION ${WORK_DIR}/corpus)
if(SECONDS EQUAL 0)
  set(length -runs=0)  # the corpus only
else()
  set(length -max_total_time=${SECONDS})
endif()
execute_process(
  COMMAND ${FUZZER} ${length} -timeout=${TIMEOUT} -rss_limit_mb=${RSS_MB} -print_final_stats=1
    -artifact_prefix=${WORK_DIR}/ ${WORK_DIR}/corpus
  WORKING_DIRECTORY ${WORK_DIR}
  RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  file(GLOB found ${WORK_DIR}/crash-* ${WORK_DIR}/leak-* ${WORK_DIR}/timeout-* ${WORK_DIR}/oom-*)
  message(FATAL_ERROR "${FUZZER} found a failing input (exit status ${status}): ${found}")
endif()
