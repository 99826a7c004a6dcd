#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "csgrt/core/query_scratch.h"
#include "csgrt/core/shape.h"

namespace csgrt {

/// Counts by kind() (Shape::kind's literals), for the statistics of every camera ray. A short
/// list searched by the literal's address: each class returns one literal, so a lookup is a
/// few pointer compares (a std::map keyed by the text compared strings on every root solve,
/// about 7% of a showcase render). Two entries may name the same text when two literals of it
/// exist; readers add them up by text (for_each gives both).
class KindCounts {
public:
    void add(std::string_view kind, std::uint64_t count = 1) {
        for (Entry& entry : entries_) {
            if (entry.kind.data() == kind.data() && entry.kind.size() == kind.size()) {
                entry.count += count;
                return;
            }
        }
        entries_.push_back(Entry{kind, count});  // once per literal met, not per ray
    }
    /// Calls visit(kind, count) for every entry.
    template <class Visit>
    void for_each(Visit&& visit) const {
        for (const Entry& entry : entries_) visit(entry.kind, entry.count);
    }
    bool empty() const { return entries_.empty(); }

private:
    struct Entry {
        std::string_view kind;
        std::uint64_t count;
    };
    std::vector<Entry> entries_;
};

/// The work a query causes at every level of a scene, counted while a CostScope is open on the
/// scratch the query uses (docs/rendering.md, "Cost"). Nothing is counted otherwise, and an
/// uncounted query pays one test of the scratch's pointer per structure and per leaf.
struct QueryCost {
    /// Box tests: nodes, grid cells or ray-space cells visited by every structure the query
    /// reaches (the scene's, compounds', meshes'), plus the bounding-box tests compounds and
    /// CSG nodes make before asking their children.
    std::uint64_t nodes = 0;
    /// Primitive tests by those structures: a member shape of a scene or compound, a triangle
    /// of a mesh.
    std::uint64_t primitives = 0;
    /// Root solves: calls of a leaf shape's own intersection routine (its crossing or its
    /// spans), whoever asks (a structure, an instance, a CSG node). A sphere that a structure
    /// tests counts once as a primitive test and once as a solve; a mesh's triangles are
    /// primitive tests only (its structure tests them without a shape call).
    std::uint64_t solves = 0;
    /// When set, the solves are also counted here by the leaf's kind() (kinds are literals,
    /// so the keys outlive every shape). It grows only when a kind is first met.
    KindCounts* solves_by_kind = nullptr;

    std::uint64_t total() const { return nodes + primitives + solves; }

    /// Adds the counts (not the kinds: those went where `other` pointed).
    QueryCost& operator+=(const QueryCost& other) {
        nodes += other.nodes;
        primitives += other.primitives;
        solves += other.solves;
        return *this;
    }
    /// Equal counts.
    friend bool operator==(const QueryCost& a, const QueryCost& b) {
        return a.nodes == b.nodes && a.primitives == b.primitives && a.solves == b.solves;
    }
};

/// Counts into `cost` the work of every query made with `scratch` while it lives (adding to
/// what `cost` holds), then restores what the scratch counted into before; scopes nest.
class CostScope {
public:
    CostScope(QueryScratch& scratch, QueryCost& cost)
        : scratch_(scratch), previous_(scratch.cost()) {
        scratch.set_cost(&cost);
    }
    ~CostScope() { scratch_.set_cost(previous_); }
    CostScope(const CostScope&) = delete;
    CostScope& operator=(const CostScope&) = delete;

private:
    QueryScratch& scratch_;
    QueryCost* previous_;
};

/// The counting hooks the queries call: each adds to the scratch's cost when it has one.
inline void count_box_tests(QueryScratch& scratch, std::uint64_t tests) {
    if (QueryCost* cost = scratch.cost()) [[unlikely]]
        cost->nodes += tests;
}
inline void count_primitive_test(QueryScratch& scratch) {
    if (QueryCost* cost = scratch.cost()) [[unlikely]]
        ++cost->primitives;
}
/// `leaf` solves for its roots.
inline void count_solve(QueryScratch& scratch, const Shape& leaf) {
    if (QueryCost* cost = scratch.cost()) [[unlikely]] {
        ++cost->solves;
        if (cost->solves_by_kind != nullptr) cost->solves_by_kind->add(leaf.kind());
    }
}

}  // namespace csgrt
