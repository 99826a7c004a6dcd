#pragma once

// A cell of RayClassification's five-dimensional trees (position x, y, z and direction u, v
// on one of the six direction faces), shared by its build and lazy splitting
// (ray_classification.cpp) and its queries (ray_classification_query.cpp). Private to
// accel/src.

#include <algorithm>
#include <atomic>
#include <cstdint>

#include "csgrt/accel/ray_classification.h"

namespace csgrt {

namespace detail {

/// The indices of the direction coordinates u and v in a cell's five coordinates.
inline constexpr int kDirectionU = 3;
inline constexpr int kDirectionV = 4;

}  // namespace detail

template <class Set>
struct RayClassification<Set>::Node {
    /// Two children, published with release once created; null for a leaf. A child's list
    /// is cut from this node's list when a ray first reaches it (`ready`).
    std::atomic<Node*> children{nullptr};
    /// The candidates, sorted by key; owned unless `borrowed` (then the parent's list). Never
    /// freed before the structure: a ray may still search a list while its cell is split.
    const Candidate* candidates = nullptr;
    std::uint32_t count = 0;
    /// Primitives under the candidates.
    std::uint32_t covered = 0;
    /// Rays that found this leaf too long but not yet visited often enough to split.
    std::atomic<std::uint32_t> visits{0};
    /// The axis (x, y, z, u, v) the cell was halved along; written before `children`.
    std::uint8_t axis = 0;
    /// Set with release once `candidates`, `count` and `covered` are final.
    std::atomic<bool> ready{false};
    /// Set when a split was refused (memory cap): the leaf is final.
    std::atomic<bool> closed{false};
    /// The list is the parent's, shared because the memory cap refused a copy.
    bool borrowed = false;

    ~Node() {
        if (!borrowed) delete[] candidates;
        delete[] children.load(std::memory_order_relaxed);
    }
};

template <class Set>
void RayClassification<Set>::root_cell(double lower[5], double upper[5]) const {
    for (int k = 0; k < 3; ++k) {
        lower[k] = scene_.lower[k];
        upper[k] = scene_.upper[k];
    }
    lower[detail::kDirectionU] = lower[detail::kDirectionV] = -1.0;
    upper[detail::kDirectionU] = upper[detail::kDirectionV] = 1.0;
}

template <class Set>
bool RayClassification<Set>::is_final(const Node& node, int depth) const {
    return node.covered <= config_.max_leaf_candidates || depth >= config_.max_depth ||
           node.closed.load(std::memory_order_relaxed);
}

}  // namespace csgrt
