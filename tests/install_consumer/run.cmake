# CTest install/consumer: installs this build (`cmake --install`) into a fresh prefix, then
# configures, builds and runs tests/install_consumer against it, as a client of the package would.
# Arguments (-D): BUILD_DIR (the build to install), WORK_DIR (emptied), CONSUMER_DIR,
# CXX_COMPILER, CXX_LAUNCHER and CXX_FLAGS (may be empty), BUILD_TYPE, VERSION (the project's). The consumer builds one
# file against the installed static libraries, so this takes seconds, not a rebuild.
foreach(var BUILD_DIR WORK_DIR CONSUMER_DIR CXX_COMPILER BUILD_TYPE VERSION)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run.cmake: -D${var}=... missing")
  endif()
endforeach()

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "install/consumer: ${what} failed (${code}):\n${out}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
run("cmake --install" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}")

# Headers only under include/bifilar/, the private step headers not among them.
file(GLOB_RECURSE headers RELATIVE "${prefix}/include" "${prefix}/include/*")
if(NOT headers)
  message(FATAL_ERROR "install/consumer: no header installed under ${prefix}/include")
endif()
foreach(header IN LISTS headers)
  if(NOT header MATCHES "^bifilar/" OR header MATCHES "_steps\\.h$")
    message(FATAL_ERROR "install/consumer: ${prefix}/include/${header} should not be installed")
  endif()
endforeach()
foreach(file lib/cmake/bifilar/bifilarConfig.cmake lib/cmake/bifilar/bifilarConfigVersion.cmake
             bin/bifilar)
  if(NOT EXISTS "${prefix}/${file}")
    message(FATAL_ERROR "install/consumer: ${prefix}/${file} was not installed")
  endif()
endforeach()

set(launcher "")
if(CXX_LAUNCHER)
  set(launcher "-DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_LAUNCHER}")
endif()
run("configuring the consumer" "${CMAKE_COMMAND}" -S "${CONSUMER_DIR}" -B "${WORK_DIR}/build"
    "-DCMAKE_PREFIX_PATH=${prefix}" "-DCMAKE_BUILD_TYPE=${BUILD_TYPE}"
    "-DBIFILAR_EXPECTED_VERSION=${VERSION}"
    "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}" ${launcher})
run("building the consumer" "${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
run("running the consumer" "${WORK_DIR}/build/consumer")
message(STATUS "${output}")
