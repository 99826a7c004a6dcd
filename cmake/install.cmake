# Install rules and the CMake package: `cmake --install` puts the headers of all four layers,
# their static libraries, the csgrt program and a package config into the prefix, so another
# project can find_package(csgrt) and link csgrt::csgrt.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(CSGRT_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/csgrt)
set(CSGRT_LIBRARIES csgrt_core csgrt_accel csgrt_csg csgrt_render)

# The umbrella target a consumer links: every layer and, through them, every dependency.
add_library(csgrt_package INTERFACE)
target_link_libraries(csgrt_package INTERFACE ${CSGRT_LIBRARIES})
set_target_properties(csgrt_package PROPERTIES EXPORT_NAME csgrt)
foreach(library IN LISTS CSGRT_LIBRARIES)
    string(REPLACE "csgrt_" "" short_name ${library})
    set_target_properties(${library} PROPERTIES EXPORT_NAME ${short_name})
endforeach()
# The static libraries name these two interface targets in their link interface.
set_target_properties(csgrt_options PROPERTIES EXPORT_NAME options)
set_target_properties(csgrt_warnings PROPERTIES EXPORT_NAME warnings)

install(TARGETS ${CSGRT_LIBRARIES} csgrt_package csgrt_options csgrt_warnings
    EXPORT csgrtTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
foreach(layer core accel csg render)
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/${layer}/include/
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()
if(TARGET csgrt)
    install(TARGETS csgrt RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
install(EXPORT csgrtTargets NAMESPACE csgrt:: DESTINATION ${CSGRT_INSTALL_CMAKEDIR})

# find_dependency calls for every package our libraries link, public or private (static
# libraries carry their private dependencies to the final link). Each entry maps a prefix of
# the imported target names to the find_package arguments that provide it; a dependency that
# is added to a layer and missing here makes the install test fail at the consumer's configure.
# OpenMesh is asked for its CONFIG package: CGAL's config puts a FindOpenMesh.cmake module on
# the path that does not find Debian's OpenMesh.
set(CSGRT_KNOWN_DEPENDENCIES
    "Eigen3::|Eigen3 3.4 NO_MODULE"
    "Threads::|Threads"
    "CGAL::|CGAL"
    "TBB::|TBB"
    "OpenEXR::|OpenEXR 3"
    "PNG::|PNG"
    "CLI11::|CLI11"
    "nlohmann_json::|nlohmann_json"
    "OpenMesh|OpenMesh CONFIG"
    "embree|embree 3")
set(CSGRT_FIND_DEPENDENCIES "")
set(linked "")
foreach(library IN LISTS CSGRT_LIBRARIES)
    get_target_property(libraries ${library} LINK_LIBRARIES)
    if(libraries)
        list(APPEND linked ${libraries})
    endif()
endforeach()
foreach(entry IN LISTS CSGRT_KNOWN_DEPENDENCIES)
    string(REPLACE "|" ";" parts "${entry}")
    list(GET parts 0 prefix)
    list(GET parts 1 arguments)
    foreach(name IN LISTS linked)
        string(FIND "${name}" "${prefix}" position)
        if(position EQUAL 0)
            string(APPEND CSGRT_FIND_DEPENDENCIES "find_dependency(${arguments})\n")
            break()
        endif()
    endforeach()
endforeach()

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/csgrtConfig.cmake.in
    ${PROJECT_BINARY_DIR}/csgrtConfig.cmake
    INSTALL_DESTINATION ${CSGRT_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/csgrtConfigVersion.cmake
    VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/csgrtConfig.cmake ${PROJECT_BINARY_DIR}/csgrtConfigVersion.cmake
    DESTINATION ${CSGRT_INSTALL_CMAKEDIR})

# The install test (label "install"): installs this build into a temporary prefix, then
# configures, builds and runs a small consumer project against it.
if(CSGRT_BUILD_TESTS)
    add_test(NAME install.consumer_project
        COMMAND ${CMAKE_COMMAND}
            -D BUILD_DIR=${PROJECT_BINARY_DIR}
            -D CONSUMER_SOURCE_DIR=${PROJECT_SOURCE_DIR}/tests/install/consumer
            -D WORK_DIR=${PROJECT_BINARY_DIR}/install_test
            -D GENERATOR=${CMAKE_GENERATOR}
            -D CXX_COMPILER=${CMAKE_CXX_COMPILER}
            -D BUILD_TYPE=${CMAKE_BUILD_TYPE}
            -P ${PROJECT_SOURCE_DIR}/tests/install/run_install_test.cmake)
    set_tests_properties(install.consumer_project PROPERTIES LABELS install TIMEOUT 600)
endif()
