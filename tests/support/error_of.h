#pragma once

#include <gtest/gtest.h>

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

/// `make()` throws InvalidParameter with a message that names `what` (the class) and
/// `parameter`.
template <class Make>
void expect_rejected_naming(Make make, const std::string& what, const std::string& parameter) {
    try {
        make();
        ADD_FAILURE() << what << " accepted " << parameter;
    } catch (const InvalidParameter& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find(what), std::string::npos) << message;
        EXPECT_NE(message.find(parameter), std::string::npos) << message;
    }
}

}  // namespace csgrt::test
