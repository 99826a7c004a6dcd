#include "csgrt/accel/brute_force.h"

#include <chrono>

#include "accelerator_base.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"

namespace csgrt {

template <class Set>
void BruteForce<Set>::build(const Set& set, const BruteForceConfig& config) {
    const auto start = std::chrono::steady_clock::now();
    set_ = &set;
    config_ = config;
    boxes_.clear();
    if (config.box_culling) {
        boxes_.reserve(set.size());
        for (std::size_t i = 0; i < set.size(); ++i) boxes_.push_back(set.bounds(i));
    }
    stats_ = AcceleratorStats{};
    stats_.name = config.box_culling ? "brute (box culling)" : "brute";
    stats_.bytes = boxes_.capacity() * sizeof(Aabb);
    stats_.primitives = stats_.references = set.size();
    stats_.build_milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

template <class Set>
bool BruteForce<Set>::may_hit(std::size_t i, const Ray& ray, const Vector3& inverse_direction,
                              double t_max) const {
    if (!config_.box_culling) return true;
    Ray bounded = ray;
    bounded.t_max = t_max;
    double t_enter, t_exit;
    return boxes_[i].intersect(bounded, inverse_direction, t_enter, t_exit);
}

template <class Set>
template <QueryKind kKind, bool kCounted>
bool BruteForce<Set>::query(const Ray& ray, QueryAnswer<kKind>& answer, QueryScratch& scratch,
                            TraversalCounters& counters) const {
    if (set_ == nullptr || !is_valid(ray)) return false;
    const auto prepared = set_->prepare(ray, scratch);
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    HitRecord best;
    best.t = ray.t_max;
    bool found = false;
    for (std::size_t i = 0; i < set_->size(); ++i) {
        if constexpr (kCounted) counters.boxes_tested += config_.box_culling ? 1 : 0;
        // Only the nearest-hit query narrows the interval as it goes.
        if (!may_hit(i, ray, inverse_direction, best.t)) continue;
        if constexpr (kCounted) ++counters.primitives_tested;
        if constexpr (kKind == QueryKind::kNearest) {
            found |= set_->intersect(i, prepared, best);
        } else if constexpr (kKind == QueryKind::kAny) {
            if (set_->occluded(i, prepared)) return true;
        } else {
            HitRecord record;
            record.t = ray.t_max;
            if (set_->intersect(i, prepared, record)) {
                answer.push_back(record);
                found = true;
            }
        }
    }
    if constexpr (kKind == QueryKind::kNearest) {
        if (found) answer = best;
    }
    return found;
}

template class BruteForce<TriangleSet<float>>;
template class BruteForce<TriangleSet<double>>;
template class BruteForce<ShapeSet>;

}  // namespace csgrt

CSGRT_INSTANTIATE_ACCELERATOR_BASE(csgrt::BruteForce);
