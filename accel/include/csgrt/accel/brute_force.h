#pragma once

#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/accelerator_config.h"
#include "csgrt/core/aabb.h"

namespace csgrt {

/// Every primitive, every ray: the baseline of every speed-up and the oracle the other
/// structures are tested against.
template <class Set>
class BruteForce final : public AcceleratorBase<BruteForce<Set>, Set> {
public:
    void build(const Set& set, const BruteForceConfig& config = {});

    static constexpr std::string_view kName = "brute";
    /// Every query (the Accelerator overrides come from AcceleratorBase).
    template <QueryKind kKind, bool kCounted>
    bool query(const Ray& ray, QueryAnswer<kKind>& answer, QueryScratch& scratch,
               TraversalCounters& counters) const;

private:
    /// False when box culling is on and the ray misses primitive i's box.
    bool may_hit(std::size_t i, const Ray& ray, const Vector3& inverse_direction,
                 double t_max) const;

    const Set* set_ = nullptr;
    BruteForceConfig config_;
    std::vector<Aabb> boxes_;
    using AcceleratorBase<BruteForce<Set>, Set>::stats_;
};

extern template class BruteForce<TriangleSet<float>>;
extern template class BruteForce<TriangleSet<double>>;
extern template class BruteForce<ShapeSet>;

}  // namespace csgrt
