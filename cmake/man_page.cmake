# Writes the csgrt man page with help2man from the program's own help (run at build time by
# cmake/install.cmake): `csgrt --help` and `--version` for NAME, SYNOPSIS and OPTIONS, and each
# subcommand's --help as a section of its own, so the page says what the program says.
cmake_minimum_required(VERSION 3.25)
foreach(variable PROGRAM HELP2MAN OUTPUT)
    if(NOT DEFINED ${variable})
        message(FATAL_ERROR "man_page.cmake: ${variable} is not set")
    endif()
endforeach()
get_filename_component(directory ${OUTPUT} DIRECTORY)
file(MAKE_DIRECTORY ${directory})
set(include_file ${OUTPUT}.include)
file(WRITE ${include_file} "")
foreach(subcommand render info validate)
    execute_process(COMMAND ${PROGRAM} ${subcommand} --help OUTPUT_VARIABLE help
        RESULT_VARIABLE result)
    if(NOT result EQUAL 0)
        message(FATAL_ERROR "man_page.cmake: '${PROGRAM} ${subcommand} --help' failed")
    endif()
    # roff: a backslash is an escape, a leading dot or quote a request.
    string(REPLACE "\\" "\\\\" help "${help}")
    string(REGEX REPLACE "(^|\n)([.'])" "\\1\\\\&\\2" help "${help}")
    string(TOUPPER ${subcommand} title)
    file(APPEND ${include_file} "[COMMAND ${title}]\n.nf\n${help}.fi\n\n")
endforeach()
file(APPEND ${include_file} "[FILES]\nThe documentation, the scene format (scene-format.md, scene.schema.json) and example\nscenes (examples/) are installed under share/doc/csgrt.\n\n")
execute_process(COMMAND ${HELP2MAN} --no-info --no-discard-stderr
    --name "render and check CSG scenes of analytic shapes and meshes"
    --section 1 --include ${include_file} --output ${OUTPUT} ${PROGRAM}
    RESULT_VARIABLE result ERROR_VARIABLE error)
if(NOT result EQUAL 0)
    message(FATAL_ERROR "man_page.cmake: help2man failed: ${error}")
endif()
