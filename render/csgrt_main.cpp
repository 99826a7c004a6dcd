// The csgrt program: render, info and validate (see `csgrt --help` and docs/rendering.md).
#include <unistd.h>

#include <iostream>

#include "csgrt/render/command_line.h"

int main(int argc, char** argv) {
    return csgrt::run_csgrt(argc, argv, {std::cout, std::cerr, ::isatty(STDERR_FILENO) == 1});
}
