# spidar_gtest_discover(<target> [TEST_PREFIX p] [TEST_FILTER f] [WORKING_DIRECTORY d]
#                       [DISCOVERY_TIMEOUT s] [PROPERTIES k v ...])
#
# Registers a GoogleTest executable's tests with ctest, with gtest_discover_tests' arguments.
#
# - SPIDAR_TEST_BATCH OFF (the release preset, `make test`): one ctest test per GoogleTest test,
#   as gtest_discover_tests makes them.
# - SPIDAR_TEST_BATCH ON (the asan and tsan presets): one ctest test per test suite (the suite's
#   tests that pass TEST_FILTER, in one process), named `<prefix><Suite>.*`, or
#   `<prefix><Suite>.* (<tag>)` when PROPERTIES sets LABELS or RESOURCE_LOCK (a suite split
#   across calls then keeps two names). A sanitized process of a binary that loads MuJoCo,
#   OpenCV and Mesa takes 0.5–0.8 s to start and to check for leaks at exit, longer than most
#   tests: one process per test spent about three quarters of the ASan suite's time there.
#
# The suites are listed after each link (POST_BUILD, as gtest_discover_tests does by default), into
# a file ctest includes. DISABLED_ tests are left out.
option(SPIDAR_TEST_BATCH "One ctest test per GoogleTest suite instead of per test" OFF)

set(_SPIDAR_TESTS_SCRIPT "${CMAKE_CURRENT_LIST_DIR}/SpidarTestsBatch.cmake")

function(spidar_gtest_discover target)
  cmake_parse_arguments(ARG "" "TEST_PREFIX;TEST_FILTER;WORKING_DIRECTORY;DISCOVERY_TIMEOUT"
                        "PROPERTIES" ${ARGN})
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "spidar_gtest_discover(${target}): unknown arguments ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT ARG_WORKING_DIRECTORY)
    set(ARG_WORKING_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}")
  endif()
  if(NOT ARG_DISCOVERY_TIMEOUT)
    set(ARG_DISCOVERY_TIMEOUT 60)
  endif()
  if(NOT SPIDAR_TEST_BATCH)
    set(forward TEST_PREFIX "${ARG_TEST_PREFIX}" WORKING_DIRECTORY "${ARG_WORKING_DIRECTORY}"
                DISCOVERY_TIMEOUT ${ARG_DISCOVERY_TIMEOUT})
    if(ARG_TEST_FILTER)
      list(APPEND forward TEST_FILTER "${ARG_TEST_FILTER}")
    endif()
    if(ARG_PROPERTIES)
      list(APPEND forward PROPERTIES ${ARG_PROPERTIES})
    endif()
    gtest_discover_tests(${target} ${forward})
    return()
  endif()
  # The tag that tells apart the batches of one suite split across calls.
  set(tag "")
  list(FIND ARG_PROPERTIES LABELS i)
  if(i EQUAL -1)
    list(FIND ARG_PROPERTIES RESOURCE_LOCK i)
  endif()
  if(NOT i EQUAL -1)
    math(EXPR i "${i} + 1")
    list(GET ARG_PROPERTIES ${i} tag)
  endif()
  get_property(calls GLOBAL PROPERTY SPIDAR_BATCH_CALLS_${target})
  if(calls STREQUAL "")
    set(calls 0)
  endif()
  math(EXPR n "${calls} + 1")
  set_property(GLOBAL PROPERTY SPIDAR_BATCH_CALLS_${target} ${n})
  set(base "${CMAKE_CURRENT_BINARY_DIR}/${target}_batch${n}")
  # The call's arguments, for the listing script (a file, so that no list is escaped on a
  # command line), with the executable's path filled in at generation time.
  set(props "")
  foreach(p IN LISTS ARG_PROPERTIES)
    string(APPEND props " [==[${p}]==]")
  endforeach()
  file(GENERATE OUTPUT "${base}_args.cmake" CONTENT
"set(EXE [==[$<TARGET_FILE:${target}>]==])
set(PREFIX [==[${ARG_TEST_PREFIX}]==])
set(FILTER [==[${ARG_TEST_FILTER}]==])
set(WORKDIR [==[${ARG_WORKING_DIRECTORY}]==])
set(TIMEOUT ${ARG_DISCOVERY_TIMEOUT})
set(TAG [==[${tag}]==])
set(PROPS${props})
set(OUT [==[${base}_tests.cmake]==])
")
  add_custom_command(TARGET ${target} POST_BUILD
    COMMAND "${CMAKE_COMMAND}" -D "ARGS_FILE=${base}_args.cmake" -P "${_SPIDAR_TESTS_SCRIPT}"
    BYPRODUCTS "${base}_tests.cmake" VERBATIM)
  file(WRITE "${base}_include.cmake"
"if(EXISTS [==[${base}_tests.cmake]==])
  include([==[${base}_tests.cmake]==])
else()
  add_test([==[${target}_batch${n}_NOT_BUILT]==] [==[${target}_batch${n}_NOT_BUILT]==])
endif()
")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${base}_include.cmake")
endfunction()
