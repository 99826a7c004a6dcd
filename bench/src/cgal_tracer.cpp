#include "peers.h"

namespace csgrt::bench {

namespace {

class CgalTracer final : public Tracer {
public:
    explicit CgalTracer(const CgalReference& reference) : reference_(reference) {}

    std::size_t nearest(std::span<const Ray> rays, QueryScratch&) const override {
        std::size_t hits = 0;
        for (const Ray& ray : rays) hits += reference_.first_intersected_primitive(ray) ? 1 : 0;
        return hits;
    }
    std::size_t occluded(std::span<const Ray> rays, QueryScratch&) const override {
        std::size_t hits = 0;
        for (const Ray& ray : rays) hits += reference_.do_intersect(ray) ? 1 : 0;
        return hits;
    }

private:
    const CgalReference& reference_;
};

}  // namespace

std::unique_ptr<Tracer> make_cgal_tracer(const CgalReference& reference) {
    return std::make_unique<CgalTracer>(reference);
}

}  // namespace csgrt::bench
