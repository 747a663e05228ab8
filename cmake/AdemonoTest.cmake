# ademono_add_test(<name> [CLI] SOURCES ... LIBS ... [PROPERTIES ...])
# A GoogleTest executable whose tests CTest discovers. Tests find real data through
# ADEMONO_SHARED_DIR (../shared beside the checkout), fixtures through ADEMONO_SOURCE_DIR and the
# CLI through ADEMONO_CLI; only tests marked CLI (those that run it) make the CLI a build
# dependency, so a sanitized subset (scripts/test.sh) builds just the modules it tests.
function(ademono_add_test name)
  cmake_parse_arguments(ARG "CLI" "" "SOURCES;LIBS;PROPERTIES" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main GTest::gmock)
  if(ADEMONO_TEST_OPT)
    target_compile_options(${name} PRIVATE ${ADEMONO_TEST_OPT})
  endif()
  get_filename_component(_shared "${PROJECT_SOURCE_DIR}/../shared" ABSOLUTE)
  target_compile_definitions(${name} PRIVATE
    ADEMONO_SHARED_DIR="${_shared}"
    ADEMONO_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    ADEMONO_CLI="$<TARGET_FILE:ademono_cli>")
  if(ARG_CLI)
    add_dependencies(${name} ademono_cli)
  endif()
  set(_env "")
  if(ADEMONO_SANITIZE OR ADEMONO_FUZZ)
    # ONNX Runtime leaks 14 bytes of its own at start-up; nothing of ademono's is suppressed.
    set(_env "LSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/tools/lsan_onnxruntime.supp")
  endif()
  if(ADEMONO_TSAN)
    # Uninstrumented third-party thread pools only (see the file).
    set(_env "TSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/tools/tsan.supp")
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60
    PROPERTIES ${ARG_PROPERTIES} TIMEOUT 900 ENVIRONMENT "${_env}")
endfunction()
