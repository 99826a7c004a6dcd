// The BVH's single-ray queries, compiled here beside the Accelerator overrides that call them
// (accelerator_base.h), so that each override inlines Bvh::query.

#include "bvh_traversal.h"

#include "accelerator_base.h"
#include "csgrt/accel/bvh.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"

namespace csgrt {

template <class Set>
template <QueryKind kKind, bool kCounted>
bool Bvh<Set>::query(const Ray& ray, QueryAnswer<kKind>& answer, QueryScratch& scratch,
                     TraversalCounters& counters) const {
    using Traversal = detail::BvhTraversal<Set>;
#if CSGRT_BVH_AVX2
    if (use_avx2_)
        return Traversal::template run_avx2<kKind, kCounted>(*this, ray, answer, scratch, counters);
#endif
    return Traversal::template run<kKind, kCounted, false>(*this, ray, answer, scratch, counters);
}

}  // namespace csgrt

CSGRT_INSTANTIATE_ACCELERATOR_BASE(csgrt::Bvh);
