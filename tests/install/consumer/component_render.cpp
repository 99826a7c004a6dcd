// csgrt::render alone: docs/api.md's program (main.cpp) through the render component.
#include "main.cpp"
