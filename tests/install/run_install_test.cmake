# Embedding test (ctest label "install"): installs a flatrad build tree into
# a temporary prefix, builds apps/embed_example.cpp against it as an outside
# project would (tests/install/CMakeLists.txt: find_package(flatrad),
# flatrad::api), runs it on data/default.json and checks its output.
#
#   cmake -DFLATRAD_SOURCE_DIR=... -DFLATRAD_BINARY_DIR=... -DWORK_DIR=...
#         -DGENERATOR=... -DCXX_COMPILER=... -DBUILD_TYPE=... -P run_install_test.cmake
foreach(var FLATRAD_SOURCE_DIR FLATRAD_BINARY_DIR WORK_DIR GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_install_test.cmake: -D${var}=... is required")
  endif()
endforeach()
if(NOT BUILD_TYPE)
  set(BUILD_TYPE Release)
endif()

set(prefix ${WORK_DIR}/prefix)
set(consumer ${WORK_DIR}/consumer)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

# Runs a command; stops the test with its output when it fails.
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${ARGN}\n--- stdout\n${out}\n--- stderr\n${err}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
  message(STATUS "${what}: ok")
endfunction()

# 1. Install the build tree.
run("install" ${CMAKE_COMMAND} --install ${FLATRAD_BINARY_DIR} --prefix ${prefix})
foreach(f include/flatrad/flatrad.h bin/flatrad)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "install: ${prefix}/${f} missing")
  endif()
endforeach()
file(GLOB_RECURSE config ${prefix}/*/flatradConfig.cmake)
file(GLOB_RECURSE config_version ${prefix}/*/flatradConfigVersion.cmake)
if(NOT config OR NOT config_version)
  message(FATAL_ERROR "install: flatradConfig.cmake / flatradConfigVersion.cmake missing under ${prefix}")
endif()
# The public face is the one header: no engine/solver header may leak out.
file(GLOB_RECURSE headers RELATIVE ${prefix}/include ${prefix}/include/*)
if(NOT headers STREQUAL "flatrad/flatrad.h")
  message(FATAL_ERROR "install: expected only include/flatrad/flatrad.h, found: ${headers}")
endif()

# 2. Configure and build the consumer against the prefix alone.
run("configure consumer" ${CMAKE_COMMAND} -S ${FLATRAD_SOURCE_DIR}/tests/install -B ${consumer}
    -G ${GENERATOR} -DCMAKE_BUILD_TYPE=${BUILD_TYPE} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
    -DCMAKE_PREFIX_PATH=${prefix} -DFLATRAD_EXAMPLE_SOURCE=${FLATRAD_SOURCE_DIR}/apps/embed_example.cpp
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
file(STRINGS ${consumer}/CMakeCache.txt found REGEX "^flatrad_DIR:")
string(FIND "${found}" "${prefix}/" at)
if(NOT at GREATER -1)
  message(FATAL_ERROR "configure consumer: flatrad found outside ${prefix}: ${found}")
endif()
run("build consumer" ${CMAKE_COMMAND} --build ${consumer})

# 3. Run it: the built-in scene, then data/default.json (37 patches, 3 channels).
run("run embed_example" ${consumer}/embed_example ${FLATRAD_SOURCE_DIR}/data/default.json)
foreach(expected "scene \"box with a lamp and a blocker\": 7 patches"
                 "room with a niche, a lamp, a pillar and a shelf\": 37 patches, 3 channel"
                 "form factor lamp -> box" ": done")
  string(FIND "${run_output}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "embed_example: expected \"${expected}\" in its output:\n${run_output}")
  endif()
endforeach()
message(STATUS "embed_example output:\n${run_output}")
run("run installed flatrad --help" ${prefix}/bin/flatrad --help)
