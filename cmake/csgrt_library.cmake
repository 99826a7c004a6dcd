include(GNUInstallDirs)

# What every csgrt library shares: its public headers, the build-only settings, its exported
# name, the version and SONAME, and, when shared, the list of symbols it exports.
#
# Shared libraries export csgrt's own symbols and nothing else through a linker version script
# (cmake/csgrt.map) rather than -fvisibility=hidden: the script needs no export macro on every
# public declaration of every header, and it still hides what the libraries instantiate or
# pull in from their dependencies (OpenMesh's templates, Eigen, the standard library), so a
# consumer binds to csgrt's ABI only. The SONAME carries major.minor: before 1.0 a minor
# release may break the ABI, the same promise as the package's version file (SameMinorVersion).

# An installed program finds the installed shared libraries beside it (bin/../lib).
if(BUILD_SHARED_LIBS AND NOT DEFINED CMAKE_INSTALL_RPATH)
    set(CMAKE_INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
endif()

# csgrt_library_conventions(<target> <component>): call after add_library(<target> ...) in
# the folder whose include/ holds the target's public headers.
function(csgrt_library_conventions target component)
    add_library(csgrt::${component} ALIAS ${target})
    target_include_directories(${target} PUBLIC
        $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
        $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_link_libraries(${target}
        PUBLIC $<BUILD_INTERFACE:csgrt_options>
        PRIVATE $<BUILD_INTERFACE:csgrt_warnings> $<BUILD_INTERFACE:csgrt_exact_fp>)
    # The public headers are C++20; a consumer's compiler is told so by the target.
    target_compile_features(${target} PUBLIC cxx_std_20)
    # Position-independent always: the Python module (a shared object) links the static
    # libraries, and the static and shared builds then compile every source alike, so the
    # install test's shared build reuses the objects through ccache. -fno-semantic-interposition
    # keeps -fPIC from blocking inlining of a library's calls to its own functions. No
    # <target>_EXPORTS define: exports are the version script's (cmake/csgrt.map).
    set_target_properties(${target} PROPERTIES
        EXPORT_NAME ${component}
        VERSION ${PROJECT_VERSION}
        SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR}
        POSITION_INDEPENDENT_CODE ON
        DEFINE_SYMBOL "")
    if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
        target_compile_options(${target} PRIVATE -fno-semantic-interposition)
    endif()
    get_target_property(type ${target} TYPE)
    if(type STREQUAL "SHARED_LIBRARY")
        # --no-undefined: a shared library that forgot a dependency fails to link here, not
        # in a consumer's program.
        target_link_options(${target} PRIVATE
            -Wl,--version-script=${PROJECT_SOURCE_DIR}/cmake/csgrt.map -Wl,--no-undefined)
        set_property(TARGET ${target} APPEND PROPERTY LINK_DEPENDS
            ${PROJECT_SOURCE_DIR}/cmake/csgrt.map)
    endif()
    set_property(GLOBAL APPEND PROPERTY CSGRT_COMPONENTS ${component})
endfunction()
