# Installs ManiSoft into a scratch prefix, then configures, builds and runs a consumer project
# that finds it with find_package(ManiSoft). Run with cmake -P (see tests/CMakeLists.txt).
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "command failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
endfunction()
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}" -B "${WORK_DIR}/lib" -DCMAKE_CXX_COMPILER=${CXX}
    -DMANISOFT_BUILD_TESTS=OFF -DMANISOFT_BUILD_EXAMPLES=OFF -DMANISOFT_BUILD_BENCHMARKS=OFF
    -DCMAKE_INSTALL_PREFIX=${prefix})
run(${CMAKE_COMMAND} --install "${WORK_DIR}/lib")
# Release at -O1 and two jobs: the three programs only show that the installed package builds
# and runs (CI's slowest test at -O3, one job at a time: 151 s).
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/consumer" -B "${WORK_DIR}/app"
    -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS_RELEASE=-O1 -DNDEBUG")
run(${CMAKE_COMMAND} --build "${WORK_DIR}/app" --parallel 2)
run("${WORK_DIR}/app/consumer")
run("${WORK_DIR}/app/consumer_contact")
run("${WORK_DIR}/app/consumer_scene")
