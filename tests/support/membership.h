#pragma once

#include "csgrt/csg/boolean.h"

namespace csgrt::test {

/// Point membership of a boolean node from its operands' memberships: the independent answer
/// the CSG tests' models give (Requicha, "Representations for Rigid Solids", 1980), written
/// here once rather than taken from the library under test.
inline bool combine_membership(BooleanOperation operation, bool in_first, bool in_second) {
    switch (operation) {
        case BooleanOperation::Union:
            return in_first || in_second;
        case BooleanOperation::Intersection:
            return in_first && in_second;
        case BooleanOperation::Difference:
            return in_first && !in_second;
    }
    return false;
}

}  // namespace csgrt::test
