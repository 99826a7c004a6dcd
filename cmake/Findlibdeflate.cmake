# Finds libdeflate (Debian's libdeflate-dev), which ships neither a CMake package before
# version 1.15 nor anything but a pkg-config file. Defines libdeflate::libdeflate, and
# libdeflate_FOUND, libdeflate_INCLUDE_DIR and libdeflate_LIBRARY. Installed with csgrt's
# package, whose config finds it with this module for a consumer of the static libraries.
find_path(libdeflate_INCLUDE_DIR libdeflate.h)
find_library(libdeflate_LIBRARY NAMES deflate)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(libdeflate REQUIRED_VARS libdeflate_LIBRARY libdeflate_INCLUDE_DIR)
if(libdeflate_FOUND AND NOT TARGET libdeflate::libdeflate)
    add_library(libdeflate::libdeflate UNKNOWN IMPORTED)
    set_target_properties(libdeflate::libdeflate PROPERTIES
        IMPORTED_LOCATION "${libdeflate_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${libdeflate_INCLUDE_DIR}")
endif()
mark_as_advanced(libdeflate_INCLUDE_DIR libdeflate_LIBRARY)
