# Run by CTest (install.consumer_project, install.shared_libraries): stages an install of the
# build in BUILD_DIR under WORK_DIR/prefix, then, against that prefix only, configures, builds
# and runs the consumer project (tests/install/consumer) once for find_package(csgrt) and once
# per component alone, with the packages that component must not need made unfindable; builds
# one program through pkg-config; and checks the installed docs and man page. With SHARED=ON it
# first configures and builds the libraries and the program from SOURCE_DIR into BUILD_DIR with
# BUILD_SHARED_LIBS=ON, and checks each library's SONAME and that it exports csgrt's symbols
# only. Fails on the first step that fails, with that step's output.
cmake_minimum_required(VERSION 3.25)
foreach(variable BUILD_DIR CONSUMER_SOURCE_DIR WORK_DIR GENERATOR CXX_COMPILER)
    if(NOT DEFINED ${variable})
        message(FATAL_ERROR "run_install_test.cmake: ${variable} is not set")
    endif()
endforeach()
if(NOT BUILD_TYPE)
    set(BUILD_TYPE Release)
endif()

function(run_step name)
    execute_process(COMMAND ${ARGN} WORKING_DIRECTORY ${WORK_DIR}
        RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output)
    if(NOT result EQUAL 0)
        message(FATAL_ERROR "install test: ${name} failed (${result}):\n${output}")
    endif()
    message(STATUS "install test: ${name} ok")
    set(step_output "${output}" PARENT_SCOPE)
endfunction()

set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${prefix} ${WORK_DIR}/consumers)
file(MAKE_DIRECTORY ${WORK_DIR})

if(SHARED)
    if(NOT DEFINED SOURCE_DIR)
        message(FATAL_ERROR "run_install_test.cmake: SHARED=ON needs SOURCE_DIR")
    endif()
    # The build tree is kept between runs, so a re-run rebuilds only what changed.
    # With a compiler launcher (ccache: scripts/test sets CMAKE_CXX_COMPILER_LAUNCHER) the
    # libraries are compiled exactly as the build that runs this test compiled its own (same
    # build type and flags; every csgrt library is position-independent and defines no
    # <target>_EXPORTS, cmake/csgrt_library.cmake), so each object is a cache hit and this
    # second build of every library costs its links only. Without one they are compiled at
    # -O0 without debug information: what this test checks (SONAMEs, the exported symbols,
    # consumers that find, link and run them) does not depend on optimisation, and that halves
    # a cold build. Without the Python module: it is a module (a shared object) whatever
    # BUILD_SHARED_LIBS says, and tests/python tests it.
    if(LAUNCHER)
        string(TOUPPER "${BUILD_TYPE}" build_type_upper)
        set(flags -D CMAKE_BUILD_TYPE=${BUILD_TYPE} -D CMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER}
            "-D CMAKE_CXX_FLAGS=${CXX_FLAGS}"
            "-D CMAKE_CXX_FLAGS_${build_type_upper}=${CXX_FLAGS_CONFIG}"
            -D CSGRT_NATIVE=${NATIVE})
    else()
        set(flags -D CMAKE_BUILD_TYPE=Debug -D CMAKE_CXX_FLAGS_DEBUG=-O0)
    endif()
    run_step("configure the shared libraries" ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${BUILD_DIR}
        -G ${GENERATOR} ${flags} -D CMAKE_CXX_COMPILER=${CXX_COMPILER}
        -D BUILD_SHARED_LIBS=ON -D CSGRT_BUILD_TESTS=OFF -D CSGRT_BUILD_BENCH=OFF
        -D CSGRT_BUILD_PYTHON=OFF -D CSGRT_WERROR=ON)
    run_step("build the shared libraries" ${CMAKE_COMMAND} --build ${BUILD_DIR} -j 2)
endif()

run_step("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# What the installed package must and must not contain.
file(GLOB_RECURSE installed RELATIVE ${prefix} ${prefix}/*)
foreach(required include/csgrt/core/shapes.h include/csgrt/render/renderer.h
        lib/cmake/csgrt/csgrtConfig.cmake lib/cmake/csgrt/csgrtConfigVersion.cmake
        lib/pkgconfig/csgrt.pc lib/pkgconfig/csgrt-core.pc bin/csgrt share/man/man1/csgrt.1
        share/doc/csgrt/README.md share/doc/csgrt/LICENSE share/doc/csgrt/scene.schema.json
        share/doc/csgrt/rendering.md share/doc/csgrt/examples/showcase.json)
    if(NOT required IN_LIST installed)
        message(FATAL_ERROR "install test: ${required} is not installed")
    endif()
endforeach()
foreach(path IN LISTS installed)
    if(path MATCHES "cgal|reference|command_line|CLI")
        message(FATAL_ERROR "install test: ${path} is installed; it is for csgrt's own build")
    endif()
endforeach()

if(SHARED)
    find_program(READELF readelf REQUIRED)
    find_program(NM nm REQUIRED)
    # The SONAME carries major.minor of the package's version.
    file(STRINGS ${prefix}/lib/cmake/csgrt/csgrtConfigVersion.cmake version_line
        REGEX "set\\(PACKAGE_VERSION \"")
    string(REGEX MATCH "[0-9]+\\.[0-9]+" version "${version_line}")
    string(REPLACE "." "\\." version "${version}")
    foreach(library core accel mesh csg render)
        set(file ${prefix}/lib/libcsgrt_${library}.so)
        if(NOT EXISTS ${file})
            message(FATAL_ERROR "install test: ${file} is not installed")
        endif()
        run_step("readelf ${library}" ${READELF} -d ${file})
        if(NOT step_output MATCHES "Library soname: \\[libcsgrt_${library}\\.so\\.${version}\\]")
            message(FATAL_ERROR "install test: libcsgrt_${library}.so has no SONAME "
                "libcsgrt_${library}.so.${version}:\n${step_output}")
        endif()
        # Every defined dynamic symbol is csgrt's (cmake/csgrt.map), demangled by nm -C.
        run_step("nm ${library}" ${NM} -D -C --defined-only ${file})
        string(REGEX MATCHALL "[^\n]+" lines "${step_output}")
        set(foreign "")
        set(count 0)
        foreach(line IN LISTS lines)
            math(EXPR count "${count} + 1")
            if(NOT line MATCHES "csgrt::")
                list(APPEND foreign "${line}")
            endif()
        endforeach()
        if(foreign)
            list(LENGTH foreign foreign_count)
            list(SUBLIST foreign 0 10 shown)
            list(JOIN shown "\n  " shown)
            message(FATAL_ERROR "install test: libcsgrt_${library}.so exports ${foreign_count} "
                "symbols outside namespace csgrt, among them:\n  ${shown}")
        endif()
        message(STATUS "install test: libcsgrt_${library}.so exports ${count} symbols, all csgrt's")
    endforeach()
endif()

# Packages a consumer of each component must not need. In the static build a library's
# private dependencies reach the consumer's link; in the shared build they stay inside it.
set(never CGAL Boost GMP MPFR CLI11 nlohmann_json embree benchmark GTest)
if(SHARED)
    set(not_needed_core OpenMesh TBB OpenEXR PNG ${never})
    set(not_needed_accel ${not_needed_core})
    set(not_needed_csg ${not_needed_core})
    set(not_needed_render ${not_needed_core})
    set(not_needed_mesh ${not_needed_core})
else()
    set(not_needed_core OpenMesh TBB OpenEXR PNG ${never})
    set(not_needed_accel OpenMesh OpenEXR PNG ${never})
    set(not_needed_mesh OpenEXR PNG ${never})
    set(not_needed_csg OpenEXR PNG ${never})
    set(not_needed_render ${never})
endif()
set(not_needed_all ${not_needed_render})

foreach(component all core accel mesh csg render)
    set(build ${WORK_DIR}/consumers/${component})
    set(disabled "")
    foreach(package IN LISTS not_needed_${component})
        list(APPEND disabled -D CMAKE_DISABLE_FIND_PACKAGE_${package}=ON)
    endforeach()
    # CMAKE_FIND_USE_PACKAGE_REGISTRY off and only the staged prefix on the path: the
    # consumer cannot find csgrt anywhere else (in particular not in the build tree).
    run_step("configure the consumer of ${component}" ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR}
        -B ${build} -G ${GENERATOR} -D CMAKE_BUILD_TYPE=${BUILD_TYPE}
        -D CMAKE_CXX_COMPILER=${CXX_COMPILER} -D CMAKE_PREFIX_PATH=${prefix}
        -D CMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -D COMPONENT=${component} ${disabled})
    run_step("build the consumer of ${component}" ${CMAKE_COMMAND} --build ${build})
    if(component MATCHES "^(all|render)$")
        run_step("run the consumer of ${component}" ${build}/consumer ${build}/sphere.exr)
        foreach(file sphere.exr sphere.png sphere.cost.png)
            if(NOT EXISTS ${build}/${file})
                message(FATAL_ERROR "install test: the consumer of ${component} did not write ${file}")
            endif()
        endforeach()
    else()
        run_step("run the consumer of ${component}" ${build}/consumer)
    endif()
endforeach()

# An unknown component is reported as not found.
execute_process(COMMAND ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${WORK_DIR}/consumers/bogus
    -G ${GENERATOR} -D CMAKE_PREFIX_PATH=${prefix} -D CMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
    -D COMPONENT=bogus RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output)
if(result EQUAL 0 OR NOT output MATCHES "bogus")
    message(FATAL_ERROR "install test: COMPONENTS bogus was accepted:\n${output}")
endif()
message(STATUS "install test: an unknown component is refused")

# pkg-config, with only the staged prefix on its path: csgrt-core's flags build the core
# program with the compiler alone.
find_program(PKG_CONFIG pkg-config REQUIRED)
set(ENV{PKG_CONFIG_PATH} ${prefix}/lib/pkgconfig)
run_step("pkg-config csgrt-core" ${PKG_CONFIG} --cflags --libs csgrt-core)
separate_arguments(flags UNIX_COMMAND "${step_output}")
run_step("compile with pkg-config's flags" ${CXX_COMPILER} -std=c++20
    ${CONSUMER_SOURCE_DIR}/component_core.cpp ${flags} -o ${WORK_DIR}/consumers/pkg_config_core)
set(ENV{LD_LIBRARY_PATH} ${prefix}/lib)
run_step("run the pkg-config program" ${WORK_DIR}/consumers/pkg_config_core)
run_step("pkg-config csgrt" ${PKG_CONFIG} --exists --print-errors csgrt)
