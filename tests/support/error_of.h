#pragma once

#include <string>

#include "csgrt/core/error.h"

namespace csgrt::test {

/// The message of the InvalidParameter that `make()` throws, or "no exception": what the
/// constructor tests search for the shape's and the parameter's names.
template <class Make>
std::string error_of(Make make) {
    try {
        make();
    } catch (const InvalidParameter& error) {
        return error.what();
    }
    return "no exception";
}

}  // namespace csgrt::test
