# Install rules: `cmake --install` puts the five libraries (static, or shared with
# BUILD_SHARED_LIBS=ON), their headers, a CMake package with one component per library, a
# pkg-config file per library, the csgrt program with its man page, and the docs into the
# prefix. The CGAL reference and the command-line library are not installed.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(CSGRT_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/csgrt)
set(CSGRT_INSTALL_COMPONENTS core accel mesh csg render)

# Which packages a component's consumer must find: the public dependencies, and for static
# libraries the private ones too (they reach the final link). Each entry maps a prefix of the
# imported target names to the find_package arguments and the pkg-config module that provide
# it. A dependency that is added to a library and missing here stops the configure, so the
# package can never forget one. Header-only private dependencies are linked inside
# $<BUILD_INTERFACE:...> by their library and so never appear here.
set(CSGRT_KNOWN_DEPENDENCIES
    "Eigen3::|Eigen3 3.4 NO_MODULE|eigen3"
    "TBB::|TBB|tbb"
    "OpenEXR::|OpenEXR 3|OpenEXR"
    "PNG::|PNG|libpng"
    "libdeflate::|libdeflate|libdeflate"
    "OpenMesh|OpenMesh CONFIG|openmesh")

# csgrt_component_dependencies(<component> <find_out> <public_pc_out> <private_pc_out>)
function(csgrt_component_dependencies component find_out public_pc_out private_pc_out)
    set(target csgrt_${component})
    get_target_property(public ${target} INTERFACE_LINK_LIBRARIES)
    get_target_property(all ${target} LINK_LIBRARIES)
    get_target_property(type ${target} TYPE)
    set(find_text "")
    set(public_pc "")
    set(private_pc "")
    foreach(name IN LISTS all)
        if(name MATCHES "^\\$<BUILD_INTERFACE:" OR name MATCHES "^csgrt")
            continue()  # build settings, header-only dependencies, csgrt's own layers
        endif()
        set(known FALSE)
        foreach(entry IN LISTS CSGRT_KNOWN_DEPENDENCIES)
            string(REPLACE "|" ";" parts "${entry}")
            list(GET parts 0 prefix)
            list(GET parts 1 arguments)
            list(GET parts 2 module)
            string(FIND "${name}" "${prefix}" position)
            if(NOT position EQUAL 0)
                continue()
            endif()
            set(known TRUE)
            set(is_public FALSE)
            if(name IN_LIST public)
                set(is_public TRUE)
            endif()
            if(is_public OR type STREQUAL "STATIC_LIBRARY")
                string(FIND "${find_text}" "find_dependency(${arguments})" seen)
                if(seen EQUAL -1)
                    string(APPEND find_text "    find_dependency(${arguments})\n")
                endif()
            endif()
            # pkg-config: static libraries need every dependency at the consumer's link.
            if(is_public OR type STREQUAL "STATIC_LIBRARY")
                list(APPEND public_pc ${module})
            else()
                list(APPEND private_pc ${module})
            endif()
        endforeach()
        if(NOT known)
            message(FATAL_ERROR "cmake/install.cmake: csgrt_${component} links ${name}, which "
                "CSGRT_KNOWN_DEPENDENCIES does not list")
        endif()
    endforeach()
    list(REMOVE_DUPLICATES public_pc)
    list(REMOVE_DUPLICATES private_pc)
    set(${find_out} "${find_text}" PARENT_SCOPE)
    set(${public_pc_out} "${public_pc}" PARENT_SCOPE)
    set(${private_pc_out} "${private_pc}" PARENT_SCOPE)
endfunction()

# Every layer below a component, as pkg-config modules (csgrt-core, ...).
set(CSGRT_LAYERS_BELOW_core "")
set(CSGRT_LAYERS_BELOW_accel "csgrt-core")
set(CSGRT_LAYERS_BELOW_mesh "csgrt-accel")
set(CSGRT_LAYERS_BELOW_csg "csgrt-mesh")
set(CSGRT_LAYERS_BELOW_render "csgrt-csg")

file(RELATIVE_PATH CSGRT_PC_PREFIX_FROM_PCFILEDIR
    /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
set(CSGRT_COMPONENT_DEPENDENCIES "")
foreach(component IN LISTS CSGRT_INSTALL_COMPONENTS)
    install(TARGETS csgrt_${component} EXPORT csgrt_${component}_targets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
    install(EXPORT csgrt_${component}_targets NAMESPACE csgrt::
        FILE csgrt_${component}_targets.cmake DESTINATION ${CSGRT_INSTALL_CMAKEDIR})
    # The command line's header belongs to the program (render/CMakeLists.txt).
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/${component}/include/
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        PATTERN command_line.h EXCLUDE)

    csgrt_component_dependencies(${component} find_text public_pc private_pc)
    string(APPEND CSGRT_COMPONENT_DEPENDENCIES
        "if(\"${component}\" IN_LIST _csgrt_load)\n${find_text}endif()\n")

    set(CSGRT_PC_NAME csgrt-${component})
    set(CSGRT_PC_DESCRIPTION "csgrt's ${component} library")
    list(JOIN public_pc " " CSGRT_PC_REQUIRES)
    string(PREPEND CSGRT_PC_REQUIRES "${CSGRT_LAYERS_BELOW_${component}} ")
    string(STRIP "${CSGRT_PC_REQUIRES}" CSGRT_PC_REQUIRES)
    list(JOIN private_pc " " CSGRT_PC_REQUIRES_PRIVATE)
    set(CSGRT_PC_LIBS "-L\${libdir} -lcsgrt_${component}")
    set(CSGRT_PC_CFLAGS "-I\${includedir}")
    configure_file(${PROJECT_SOURCE_DIR}/cmake/csgrt.pc.in
        ${PROJECT_BINARY_DIR}/pkgconfig/csgrt-${component}.pc @ONLY)
    install(FILES ${PROJECT_BINARY_DIR}/pkgconfig/csgrt-${component}.pc
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endforeach()
# csgrt.pc: every library, as csgrt::csgrt.
set(CSGRT_PC_NAME csgrt)
set(CSGRT_PC_DESCRIPTION "${PROJECT_DESCRIPTION}")
set(CSGRT_PC_REQUIRES "csgrt-render")
set(CSGRT_PC_REQUIRES_PRIVATE "")
set(CSGRT_PC_LIBS "")
set(CSGRT_PC_CFLAGS "")
configure_file(${PROJECT_SOURCE_DIR}/cmake/csgrt.pc.in ${PROJECT_BINARY_DIR}/pkgconfig/csgrt.pc
    @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/pkgconfig/csgrt.pc
    DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# csgrt::csgrt, loaded with the render component (which brings every layer).
set_target_properties(csgrt_package PROPERTIES EXPORT_NAME csgrt)
install(TARGETS csgrt_package EXPORT csgrt_targets)
install(EXPORT csgrt_targets NAMESPACE csgrt:: FILE csgrt_targets.cmake
    DESTINATION ${CSGRT_INSTALL_CMAKEDIR})

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/csgrtConfig.cmake.in
    ${PROJECT_BINARY_DIR}/csgrtConfig.cmake
    INSTALL_DESTINATION ${CSGRT_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/csgrtConfigVersion.cmake
    VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/csgrtConfig.cmake ${PROJECT_BINARY_DIR}/csgrtConfigVersion.cmake
    ${PROJECT_SOURCE_DIR}/cmake/Findlibdeflate.cmake
    DESTINATION ${CSGRT_INSTALL_CMAKEDIR})

# The program, its man page (help2man, from the program's own --help: cmake/man_page.cmake),
# the docs and the example scenes under share/doc/csgrt.
if(TARGET csgrt)
    install(TARGETS csgrt RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
    find_program(CSGRT_HELP2MAN help2man)
    if(CSGRT_HELP2MAN)
        add_custom_command(OUTPUT ${PROJECT_BINARY_DIR}/man/csgrt.1
            COMMAND ${CMAKE_COMMAND} -D PROGRAM=$<TARGET_FILE:csgrt> -D HELP2MAN=${CSGRT_HELP2MAN}
                -D OUTPUT=${PROJECT_BINARY_DIR}/man/csgrt.1
                -P ${PROJECT_SOURCE_DIR}/cmake/man_page.cmake
            DEPENDS csgrt ${PROJECT_SOURCE_DIR}/cmake/man_page.cmake
            COMMENT "help2man: csgrt.1")
        add_custom_target(csgrt_man_page ALL DEPENDS ${PROJECT_BINARY_DIR}/man/csgrt.1)
        install(FILES ${PROJECT_BINARY_DIR}/man/csgrt.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
    else()
        message(STATUS "help2man not found: no man page (scripts/bootstrap installs it)")
    endif()
endif()
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/LICENSE
    DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}
    FILES_MATCHING PATTERN "*.md" PATTERN "*.json")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/data/scenes/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)

# The install tests (label "install"): each stages an install under a temporary prefix, then
# builds and runs one consumer project per component against that prefix only
# (tests/install/run_install_test.cmake). install.consumer_project installs this build;
# install.shared_libraries configures and builds the libraries with BUILD_SHARED_LIBS=ON in
# a tree of its own first, then does the same.
# Both test the package as a user gets it, so the sanitizer trees leave them out: their libraries
# need the sanitizer runtimes, which the package (rightly) does not pass on to a consumer, and the
# shared build would be a second build of the libraries for the same CMake check.
if(CSGRT_BUILD_TESTS AND NOT CSGRT_SANITIZE AND NOT CSGRT_TSAN AND NOT CSGRT_FUZZ)
    set(CSGRT_INSTALL_TEST_ARGUMENTS
        -D CONSUMER_SOURCE_DIR=${PROJECT_SOURCE_DIR}/tests/install/consumer
        -D GENERATOR=${CMAKE_GENERATOR}
        -D CXX_COMPILER=${CMAKE_CXX_COMPILER}
        -D BUILD_TYPE=${CMAKE_BUILD_TYPE})
    # The shared build compiles as this one does when a launcher (ccache) can reuse its objects.
    string(TOUPPER "${CMAKE_BUILD_TYPE}" csgrt_build_type_upper)
    set(CSGRT_SHARED_TEST_ARGUMENTS
        "-D LAUNCHER=${CMAKE_CXX_COMPILER_LAUNCHER}" "-D CXX_FLAGS=${CMAKE_CXX_FLAGS}"
        "-D CXX_FLAGS_CONFIG=${CMAKE_CXX_FLAGS_${csgrt_build_type_upper}}"
        -D NATIVE=${CSGRT_NATIVE})
    add_test(NAME install.consumer_project
        COMMAND ${CMAKE_COMMAND} ${CSGRT_INSTALL_TEST_ARGUMENTS}
            -D BUILD_DIR=${PROJECT_BINARY_DIR}
            -D WORK_DIR=${PROJECT_BINARY_DIR}/install_test
            -P ${PROJECT_SOURCE_DIR}/tests/install/run_install_test.cmake)
    set_tests_properties(install.consumer_project PROPERTIES LABELS install TIMEOUT 600)
    add_test(NAME install.shared_libraries
        COMMAND ${CMAKE_COMMAND} ${CSGRT_INSTALL_TEST_ARGUMENTS} ${CSGRT_SHARED_TEST_ARGUMENTS}
            -D SOURCE_DIR=${PROJECT_SOURCE_DIR}
            -D BUILD_DIR=${PROJECT_BINARY_DIR}/install_test_shared/libraries
            -D WORK_DIR=${PROJECT_BINARY_DIR}/install_test_shared
            -D SHARED=ON
            -P ${PROJECT_SOURCE_DIR}/tests/install/run_install_test.cmake)
    set_tests_properties(install.shared_libraries PROPERTIES LABELS install TIMEOUT 1200)
endif()
