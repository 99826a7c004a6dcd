#include "benchmarks.h"

namespace csgrt::bench {

void register_csg_benchmarks(const Settings&) {}

}  // namespace csgrt::bench
