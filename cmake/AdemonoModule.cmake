# ademono_add_module(<module> DEPS ...): the static library ademono_<module> from every .cpp in
# src/ademono/<module>/ (globbed, so adding a file needs no CMake edit). A module without sources
# yet is an INTERFACE library carrying its dependencies.
function(ademono_add_module module)
  cmake_parse_arguments(ARG "" "" "DEPS" ${ARGN})
  file(GLOB _sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/ademono/${module}/*.cpp)
  if(_sources)
    add_library(ademono_${module} STATIC ${_sources})
    target_include_directories(ademono_${module} PUBLIC ${PROJECT_SOURCE_DIR}/src)
    target_link_libraries(ademono_${module} PUBLIC ${ARG_DEPS})
  else()
    add_library(ademono_${module} INTERFACE)
    target_include_directories(ademono_${module} INTERFACE ${PROJECT_SOURCE_DIR}/src)
    target_link_libraries(ademono_${module} INTERFACE ${ARG_DEPS})
  endif()
endfunction()
