# Run by CTest (install.consumer_project): stages an install of the build in BUILD_DIR under
# WORK_DIR/prefix, then configures, builds and runs the consumer project against that prefix
# only. Fails on the first step that fails, with that step's output.
foreach(variable BUILD_DIR CONSUMER_SOURCE_DIR WORK_DIR GENERATOR CXX_COMPILER)
    if(NOT DEFINED ${variable})
        message(FATAL_ERROR "run_install_test.cmake: ${variable} is not set")
    endif()
endforeach()
if(NOT BUILD_TYPE)
    set(BUILD_TYPE Release)
endif()

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

function(run_step name)
    execute_process(COMMAND ${ARGN} WORKING_DIRECTORY ${WORK_DIR}
        RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output)
    if(NOT result EQUAL 0)
        message(FATAL_ERROR "install test: ${name} failed (${result}):\n${output}")
    endif()
    message(STATUS "install test: ${name} ok")
endfunction()

run_step("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
# CMAKE_FIND_USE_PACKAGE_REGISTRY off and only the staged prefix on the path: the consumer
# cannot find csgrt anywhere else (in particular not in the build tree).
run_step("configure the consumer" ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${WORK_DIR}/build
    -G ${GENERATOR} -D CMAKE_BUILD_TYPE=${BUILD_TYPE} -D CMAKE_CXX_COMPILER=${CXX_COMPILER}
    -D CMAKE_PREFIX_PATH=${WORK_DIR}/prefix -D CMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
run_step("build the consumer" ${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run_step("run the consumer" ${WORK_DIR}/build/consumer ${WORK_DIR}/sphere.exr)
foreach(file sphere.exr sphere.png sphere.cost.png)
    if(NOT EXISTS ${WORK_DIR}/${file})
        message(FATAL_ERROR "install test: the consumer did not write ${file}")
    endif()
endforeach()
