# Shared build settings and helper functions for SRI-GVINS targets.

set(GVINS_WARNINGS -Wall -Wextra -Wpedantic -Wshadow=local -Wno-unknown-warning-option)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  # Eigen 3.4 triggers maybe-uninitialized false positives with g++ 12 at -O2/-O3.
  # g++ 12 also reports -Wrestrict false positives inside std::string concatenation (GCC PR 105329).
  list(APPEND GVINS_WARNINGS -Wno-maybe-uninitialized -Wno-restrict)
  list(REMOVE_ITEM GVINS_WARNINGS -Wno-unknown-warning-option)
endif()

if(GVINS_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
if(GVINS_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "GVINS_FUZZ=ON needs clang (CXX=clang++)")
  endif()
  # Undefined behaviour stops the run (a finding with its input), as in the sanitizer build;
  # otherwise UBSan only prints a line and the fuzzer carries on.
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined
                      -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()

# gvins_add_library(NAME <target> SOURCES ... DEPS ...)
# A library folder: public headers under include/, sources under src/. The library is installed
# with its headers and exported as SriGvins::<module> (gvins_base -> SriGvins::base; the package
# config is made at the top level). Eigen's heap alignment (GVINS_EIGEN_DEFINITIONS, set at the top
# level) is a PUBLIC definition: every translation unit that allocates or frees Eigen objects
# across the library boundary, ours or a consumer's, must be compiled with the same value.
function(gvins_add_library)
  cmake_parse_arguments(A "" "NAME" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${A_NAME} ${A_SOURCES})
  target_include_directories(${A_NAME} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${A_NAME} PUBLIC ${A_DEPS} PRIVATE ${A_PRIVATE_DEPS})
  target_compile_definitions(${A_NAME} PUBLIC ${GVINS_EIGEN_DEFINITIONS})
  target_compile_options(${A_NAME} PRIVATE ${GVINS_WARNINGS})
  string(REGEX REPLACE "^gvins_" "" export_name ${A_NAME})
  # Static libraries by default; with -DBUILD_SHARED_LIBS=ON the shared objects are versioned
  # (0.x: the minor version changes the ABI).
  set_target_properties(${A_NAME} PROPERTIES EXPORT_NAME ${export_name} VERSION ${PROJECT_VERSION}
    SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
  add_library(SriGvins::${export_name} ALIAS ${A_NAME})
  install(TARGETS ${A_NAME} EXPORT SriGvinsTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  set_property(GLOBAL APPEND PROPERTY GVINS_LIBRARIES ${A_NAME})
endfunction()

# gvins_add_app(NAME gvins-<verb> SOURCES ... DEPS ...)
function(gvins_add_app)
  cmake_parse_arguments(A "" "NAME" "SOURCES;DEPS" ${ARGN})
  add_executable(${A_NAME} ${A_SOURCES})
  target_link_libraries(${A_NAME} PRIVATE ${A_DEPS})
  target_compile_options(${A_NAME} PRIVATE ${GVINS_WARNINGS})
  set_target_properties(${A_NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin)
endfunction()

# gvins_add_test(NAME <name> SOURCES ... DEPS ... [LABELS ...] [TIMEOUT s])
# GoogleTest executable registered with CTest. Tests run with the source tree's tests/data
# reachable through the GVINS_TEST_DATA environment variable and compile definition.
function(gvins_add_test)
  cmake_parse_arguments(A "" "NAME;TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  if(GVINS_FUZZ)
    return()  # fuzzing builds contain only fuzz targets
  endif()
  add_executable(${A_NAME} ${A_SOURCES})
  target_link_libraries(${A_NAME} PRIVATE ${A_DEPS} GTest::gtest GTest::gtest_main)
  target_include_directories(${A_NAME} PRIVATE ${PROJECT_SOURCE_DIR}/tests/support)
  target_compile_options(${A_NAME} PRIVATE ${GVINS_WARNINGS})
  target_compile_definitions(${A_NAME} PRIVATE
    GVINS_TEST_DATA="${PROJECT_SOURCE_DIR}/tests/data"
    GVINS_BIN_DIR="${PROJECT_BINARY_DIR}/bin")
  set_target_properties(${A_NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
  if(NOT A_TIMEOUT)
    set(A_TIMEOUT 300)
  endif()
  if(NOT A_LABELS)
    set(A_LABELS unit)
  endif()
  gtest_discover_tests(${A_NAME} DISCOVERY_TIMEOUT 60
    PROPERTIES LABELS "${A_LABELS}" TIMEOUT ${A_TIMEOUT}
    ENVIRONMENT "GVINS_TEST_DATA=${PROJECT_SOURCE_DIR}/tests/data")
endfunction()

# gvins_add_fuzzer(NAME fuzz_<what> SOURCES ... DEPS ... CORPUS <dir>)
# A libFuzzer target defining LLVMFuzzerTestOneInput. With GVINS_FUZZ it links libFuzzer;
# otherwise it links a small driver that replays every file of CORPUS (regression test in CTest).
function(gvins_add_fuzzer)
  cmake_parse_arguments(A "" "NAME;CORPUS" "SOURCES;DEPS" ${ARGN})
  if(GVINS_FUZZ)
    add_executable(${A_NAME} ${A_SOURCES})
    target_link_options(${A_NAME} PRIVATE -fsanitize=fuzzer)
  else()
    add_executable(${A_NAME} ${A_SOURCES} ${PROJECT_SOURCE_DIR}/tests/fuzz/replay_driver.cpp)
    add_test(NAME ${A_NAME}_corpus COMMAND ${A_NAME} ${A_CORPUS})
    set_tests_properties(${A_NAME}_corpus PROPERTIES LABELS fuzz TIMEOUT 300)
  endif()
  target_link_libraries(${A_NAME} PRIVATE ${A_DEPS})
  target_compile_options(${A_NAME} PRIVATE ${GVINS_WARNINGS})
  target_compile_definitions(${A_NAME} PRIVATE GVINS_TEST_DATA="${PROJECT_SOURCE_DIR}/tests/data")
  set_target_properties(${A_NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/fuzz)
endfunction()

# gvins_add_benchmark(NAME bench_<what> SOURCES ... DEPS ...)
function(gvins_add_benchmark)
  cmake_parse_arguments(A "" "NAME" "SOURCES;DEPS" ${ARGN})
  add_executable(${A_NAME} ${A_SOURCES})
  target_link_libraries(${A_NAME} PRIVATE ${A_DEPS} benchmark::benchmark)
  target_compile_options(${A_NAME} PRIVATE ${GVINS_WARNINGS})
  target_compile_definitions(${A_NAME} PRIVATE GVINS_TEST_DATA="${PROJECT_SOURCE_DIR}/tests/data")
  set_target_properties(${A_NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bench)
endfunction()
