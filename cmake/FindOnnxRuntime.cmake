# Finds ONNX Runtime (C/C++ API). Set ONNXRUNTIME_ROOT to a prefix holding include/ and lib/
# (an official onnxruntime-linux release unpacked, or .deps/onnxruntime made by scripts/setup.sh).
# Defines the imported target OnnxRuntime::OnnxRuntime.
set(_ort_hints ${ONNXRUNTIME_ROOT} $ENV{ONNXRUNTIME_ROOT} "${CMAKE_CURRENT_LIST_DIR}/../.deps/onnxruntime")
find_path(OnnxRuntime_INCLUDE_DIR onnxruntime_cxx_api.h
  HINTS ${_ort_hints} PATH_SUFFIXES include include/onnxruntime include/onnxruntime/core/session)
find_library(OnnxRuntime_LIBRARY NAMES onnxruntime libonnxruntime.so.1
  HINTS ${_ort_hints} PATH_SUFFIXES lib lib64)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OnnxRuntime REQUIRED_VARS OnnxRuntime_LIBRARY OnnxRuntime_INCLUDE_DIR)
if(OnnxRuntime_FOUND AND NOT TARGET OnnxRuntime::OnnxRuntime)
  add_library(OnnxRuntime::OnnxRuntime SHARED IMPORTED)
  set_target_properties(OnnxRuntime::OnnxRuntime PROPERTIES
    IMPORTED_LOCATION "${OnnxRuntime_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${OnnxRuntime_INCLUDE_DIR}")
  # Packaged builds only ship libonnxruntime.so.1; the SONAME is what the loader looks for.
  get_filename_component(_ort_libdir "${OnnxRuntime_LIBRARY}" DIRECTORY)
  set_property(TARGET OnnxRuntime::OnnxRuntime PROPERTY INTERFACE_LINK_DIRECTORIES "${_ort_libdir}")
endif()
mark_as_advanced(OnnxRuntime_INCLUDE_DIR OnnxRuntime_LIBRARY)
