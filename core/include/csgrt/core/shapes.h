#pragma once

// Every shape of the geometry kernel, for code that wants them all (the scene loader, tests).
#include "csgrt/core/annulus.h"
#include "csgrt/core/box.h"
#include "csgrt/core/cone.h"
#include "csgrt/core/cylinder.h"
#include "csgrt/core/disk.h"
#include "csgrt/core/half_space.h"
#include "csgrt/core/instance.h"
#include "csgrt/core/part_cylinder.h"
#include "csgrt/core/part_sphere.h"
#include "csgrt/core/part_torus.h"
#include "csgrt/core/plane.h"
#include "csgrt/core/rectangle.h"
#include "csgrt/core/sphere.h"
#include "csgrt/core/torus.h"
#include "csgrt/core/triangle.h"
