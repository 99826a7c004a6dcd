// The mesh component is csgrt::accel today (docs/api.md); the same program as accel's.
#include "component_accel.cpp"
