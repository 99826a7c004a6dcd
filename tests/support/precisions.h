#pragma once

#include <gtest/gtest.h>

namespace csgrt::test {

/// The precisions the triangle sets (and the structures and batches over them) come in: a typed
/// suite over these runs each of its tests once in float and once in double.
using Precisions = ::testing::Types<float, double>;

}  // namespace csgrt::test
