#include <stdexcept>

#include "peers.h"

namespace csgrt::bench {

bool embree_available() {
    return false;
}

std::string embree_version() {
    return "not built with Embree";
}

std::unique_ptr<Tracer> make_embree_tracer(const TriangleSet<float>&, bool, int, EmbreeBuild*, bool) {
    throw std::runtime_error("csgrt_bench was built without Embree (find_package(embree 3))");
}

}  // namespace csgrt::bench
