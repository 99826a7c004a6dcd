#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "csgrt/core/hit.h"
#include "csgrt/core/span.h"

namespace csgrt {

class Instance;
struct QueryCost;

/// Working memory for one query at a time, owned by the caller (one per thread) and reused
/// from ray to ray, so that once its buffers have grown no query allocates. It holds the
/// instance paths of recorded hits and pools of span and hit lists that CSG nodes and meshes
/// borrow while they evaluate.
class QueryScratch {
public:
    /// One instance on a hit's path from the query's root to its leaf; `inner` is the next
    /// instance toward the leaf (kNoIndex: the leaf itself).
    struct PathNode {
        const Instance* instance;
        std::uint32_t inner;
    };

    /// Forgets the paths of the previous query. Called by every top-level query.
    void reset() { path_.clear(); }

    /// Records that `instance` encloses the path `inner`; returns the new path's index.
    std::uint32_t push_instance(const Instance* instance, std::uint32_t inner) {
        path_.push_back(PathNode{instance, inner});
        return static_cast<std::uint32_t>(path_.size() - 1);
    }
    const PathNode& path_node(std::uint32_t index) const { return path_[index]; }

    /// A cleared span list lent until `return_spans`; borrows nest (last out, first back).
    SpanList& borrow_spans() { return borrow(span_pool_, spans_in_use_); }
    void return_spans() { --spans_in_use_; }

    /// A cleared hit list lent until `return_hits` (meshes collect crossings in one).
    std::vector<HitRecord>& borrow_hits() { return borrow(hit_pool_, hits_in_use_); }
    void return_hits() { --hits_in_use_; }

    /// Where queries made with this scratch add their work (core/query_cost.h: CostScope sets
    /// it), or null when nothing is counted.
    QueryCost* cost() const { return cost_; }
    void set_cost(QueryCost* cost) { cost_ = cost; }

private:
    template <class List>
    static List& borrow(std::vector<std::unique_ptr<List>>& pool, std::size_t& in_use) {
        // unique_ptr keeps lent lists in place when the pool itself grows.
        if (in_use == pool.size()) pool.push_back(std::make_unique<List>());
        List& list = *pool[in_use++];
        list.clear();
        return list;
    }

    std::vector<PathNode> path_;
    std::vector<std::unique_ptr<SpanList>> span_pool_;
    std::vector<std::unique_ptr<std::vector<HitRecord>>> hit_pool_;
    std::size_t spans_in_use_ = 0;
    std::size_t hits_in_use_ = 0;
    QueryCost* cost_ = nullptr;
};

/// Borrows a span list from `scratch` for the enclosing scope.
class BorrowedSpans {
public:
    explicit BorrowedSpans(QueryScratch& scratch)
        : scratch_(scratch), list_(scratch.borrow_spans()) {}
    ~BorrowedSpans() { scratch_.return_spans(); }
    BorrowedSpans(const BorrowedSpans&) = delete;
    BorrowedSpans& operator=(const BorrowedSpans&) = delete;

    SpanList& list() { return list_; }

private:
    QueryScratch& scratch_;
    SpanList& list_;
};

/// Borrows a hit list from `scratch` for the enclosing scope.
class BorrowedHits {
public:
    explicit BorrowedHits(QueryScratch& scratch)
        : scratch_(scratch), list_(scratch.borrow_hits()) {}
    ~BorrowedHits() { scratch_.return_hits(); }
    BorrowedHits(const BorrowedHits&) = delete;
    BorrowedHits& operator=(const BorrowedHits&) = delete;

    std::vector<HitRecord>& list() { return list_; }

private:
    QueryScratch& scratch_;
    std::vector<HitRecord>& list_;
};

/// This thread's scratch, for the convenience queries on Shape.
QueryScratch& thread_query_scratch();

}  // namespace csgrt
