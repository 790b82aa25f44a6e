# Run after each test binary is linked (tests/CMakeLists.txt): lists its
# doctest cases and fails the build on a name holding ';'.
# doctest_discover_tests passes each name through a CMake list, so such a
# name is split into two ctest entries that match no case and pass without
# running anything (eight cases went unrun that way until the forty-seventh
# session). Usage: cmake -DEXE=TEST_BINARY -P check_case_names.cmake
execute_process(COMMAND "${EXE}" --list-test-cases OUTPUT_VARIABLE listed RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${EXE} --list-test-cases failed (${status})")
endif()
string(FIND "${listed}" ";" at)
if(NOT at EQUAL -1)
  string(REPLACE "\n" " | " shown "${listed}")
  message(FATAL_ERROR "${EXE}: a test case's name holds ';', which ctest would split and never run: ${shown}")
endif()
