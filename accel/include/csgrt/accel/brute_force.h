#pragma once

#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/accelerator_config.h"
#include "csgrt/core/aabb.h"

namespace csgrt {


/// Every primitive, every ray: the baseline of every speed-up and the oracle the other
/// structures are tested against.
template <class Set>
class BruteForce final : public Accelerator<Set> {
public:
    void build(const Set& set, const BruteForceConfig& config = {});

    std::string_view name() const override { return "brute"; }
    bool intersect(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override;
    bool occluded(const Ray& ray, QueryScratch& scratch) const override;
    bool intersect_counted(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                           TraversalCounters& counters) const override;
    bool occluded_counted(const Ray& ray, QueryScratch& scratch,
                          TraversalCounters& counters) const override;
    void all_hits(const Ray& ray, std::vector<HitRecord>& hits,
                  QueryScratch& scratch) const override;
    AcceleratorStats stats() const override { return stats_; }

private:
    template <bool kCount>
    bool intersect_impl(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                        TraversalCounters& counters) const;
    template <bool kCount>
    bool occluded_impl(const Ray& ray, QueryScratch& scratch, TraversalCounters& counters) const;
    /// False when box culling is on and the ray misses primitive i's box.
    bool may_hit(std::size_t i, const Ray& ray, const Vector3& inverse_direction,
                 double t_max) const;

    const Set* set_ = nullptr;
    BruteForceConfig config_;
    std::vector<Aabb> boxes_;
    AcceleratorStats stats_;
};

class ShapeSet;
template <class Real>
class TriangleSet;
extern template class BruteForce<TriangleSet<float>>;
extern template class BruteForce<TriangleSet<double>>;
extern template class BruteForce<ShapeSet>;

}  // namespace csgrt
