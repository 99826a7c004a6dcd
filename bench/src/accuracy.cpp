#include "benchmarks.h"

namespace csgrt::bench {

void register_accuracy_benchmarks(Workloads&, const Settings&) {}

}  // namespace csgrt::bench
