#pragma once

// The BVH's leaves of TriangleSet<float>: lanes of triangles tested with the triangle test's
// own float operations, four or eight lanes at a time, and the ray-parallel test of a
// packet. Private to accel/src/bvh*.

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "bvh_ray.h"

namespace csgrt::detail {

/// Whether a Bvh over Set may keep its leaves' triangles in blocks (BvhConfig::
/// triangle_blocks): TriangleSet<float> only.
template <class Set>
inline constexpr bool kBlockLeaves = std::is_same_v<Set, TriangleSet<float>>;

/// Four lanes of a leaf sheared into the frame of the ray, lane by lane, with their edge
/// functions.
struct ShearedBlock {
    Float4 x[3], y[3], z[3];
    Float4 u, v, w;

    /// Lane l as the set's scalar test would have computed it.
    TriangleSet<float>::ShearedTriangle lane(int l) const {
        alignas(16) float values[9][4];
        for (int k = 0; k < 3; ++k) {
            x[k].store(values[k]);
            y[k].store(values[3 + k]);
            z[k].store(values[6 + k]);
        }
        TriangleSet<float>::ShearedTriangle triangle;
        for (int k = 0; k < 3; ++k) {
            triangle.x[k] = values[k][l];
            triangle.y[k] = values[3 + k][l];
            triangle.z[k] = values[6 + k][l];
        }
        return triangle;
    }
};

/// t and the barycentrics of corners 1 and 2 of a block's four lanes, from their edge
/// functions: TriangleSet::hit_sheared's double arithmetic after its sign test, lane by lane in
/// the same order (no fused multiply-add), so the same bits for a lane whose edge functions
/// are non-zero and of one sign. Two lanes at a time with SSE2; one division for all four.
struct BlockHits {
    alignas(16) double t[4], b1[4], b2[4];

    BlockHits(const ShearedBlock& block, double shear_z) {
#if defined(__SSE2__)
        const __m128d scale = _mm_set1_pd(shear_z), one = _mm_set1_pd(1.0);
        for (int half = 0; half < 2; ++half) {
            auto widen = [half](Float4 lanes) {
                return _mm_cvtps_pd(half == 0 ? lanes.v : _mm_movehl_ps(lanes.v, lanes.v));
            };
            const __m128d u = widen(block.u), v = widen(block.v), w = widen(block.w);
            const __m128d az = _mm_mul_pd(scale, widen(block.z[0]));
            const __m128d bz = _mm_mul_pd(scale, widen(block.z[1]));
            const __m128d cz = _mm_mul_pd(scale, widen(block.z[2]));
            const __m128d scaled_t =
                _mm_add_pd(_mm_add_pd(_mm_mul_pd(u, az), _mm_mul_pd(v, bz)), _mm_mul_pd(w, cz));
            const __m128d inverse = _mm_div_pd(one, _mm_add_pd(_mm_add_pd(u, v), w));
            _mm_store_pd(t + 2 * half, _mm_mul_pd(scaled_t, inverse));
            _mm_store_pd(b1 + 2 * half, _mm_mul_pd(v, inverse));
            _mm_store_pd(b2 + 2 * half, _mm_mul_pd(w, inverse));
        }
#else
        alignas(16) float u[4], v[4], w[4], z[3][4];
        block.u.store(u);
        block.v.store(v);
        block.w.store(w);
        for (int k = 0; k < 3; ++k) block.z[k].store(z[k]);
        for (int l = 0; l < 4; ++l) {
            const double az = shear_z * double(z[0][l]), bz = shear_z * double(z[1][l]),
                         cz = shear_z * double(z[2][l]);
            const double scaled_t = double(u[l]) * az + double(v[l]) * bz + double(w[l]) * cz;
            const double inverse = 1.0 / (double(u[l]) + double(v[l]) + double(w[l]));
            t[l] = scaled_t * inverse;
            b1[l] = double(v[l]) * inverse;
            b2[l] = double(w[l]) * inverse;
        }
#endif
    }
};

/// Floats a lane takes in BvhLeafTriangles: nine corner coordinates and the triangle index.
inline constexpr std::size_t kLaneFloats = 10;

/// The triangle test's axis a (0, 1, 2: x, y, z) when z is kAxisZ: the axes follow cyclically,
/// as TriangleSet::prepare permutes them. The leaf tests are compiled for each kAxisZ, so that
/// the rows they read lie at constant offsets.
template <int kAxisZ>
constexpr std::ptrdiff_t test_axis(int a) {
    return (kAxisZ + 1 + a) % 3;
}

/// The first half of TriangleSet<float>'s test on four lanes of a leaf at once: the same float
/// operations as TriangleSet::shear and the edge functions of hit_sheared, lane by lane, so the
/// values are the scalar test's bits. A lane whose three edge functions are non-zero and of
/// mixed signs is a miss for the scalar test too (it only recomputes exact zeros).
struct BlockRay {
    /// The origin's and the shear's components, on the permuted axes (x, y, z of the test).
    Float4 origin[3], shear_x, shear_y;
    /// The test's axes x, y, z.
    std::ptrdiff_t axis[3];

    explicit BlockRay(const TriangleSet<float>::PreparedRay& ray)
        : shear_x(Float4::broadcast(ray.shear_x)), shear_y(Float4::broadcast(ray.shear_y)) {
        axis[0] = ray.axis_x;
        axis[1] = ray.axis_y;
        axis[2] = ray.axis_z;
        for (int a = 0; a < 3; ++a) origin[a] = Float4::broadcast(ray.origin[axis[a]]);
    }

    /// The four lanes from `lanes` of a group of kWidth lanes (BvhLeafTriangles; 16-byte
    /// aligned) that may hit (bit l for lane l), the lanes sheared, and in `zeros` the lanes
    /// with an edge function that is exactly zero (left to TriangleSet::hit_sheared, which
    /// recomputes those in double). Every other candidate lane is a hit whose t and
    /// barycentrics BlockHits gives.
    /// kAxisZ is axis[2] (the rows' offsets are then constants).
    template <int kAxisZ, std::ptrdiff_t kWidth>
    unsigned candidates(const float* lanes, ShearedBlock& sheared, unsigned& zeros) const {
        for (int k = 0; k < 3; ++k) {
            const float* row = lanes + 3 * k * kWidth;
            const Float4 px = Float4::load_aligned(row + test_axis<kAxisZ>(0) * kWidth) - origin[0];
            const Float4 py = Float4::load_aligned(row + test_axis<kAxisZ>(1) * kWidth) - origin[1];
            const Float4 pz = Float4::load_aligned(row + test_axis<kAxisZ>(2) * kWidth) - origin[2];
            sheared.x[k] = px - shear_x * pz;
            sheared.y[k] = py - shear_y * pz;
            sheared.z[k] = pz;
        }
        const Float4* x = sheared.x;
        const Float4* y = sheared.y;
        const Float4 u = sheared.u = x[2] * y[1] - y[2] * x[1];
        const Float4 v = sheared.v = x[0] * y[2] - y[0] * x[2];
        const Float4 w = sheared.w = x[1] * y[0] - y[1] * x[0];
        const Float4 zero = Float4::broadcast(0.0f);
        zeros = (equal(u, zero) | equal(v, zero) | equal(w, zero)).mask();
        // Non-zero numbers' signs are their sign bits: mixed when some but not all are set.
        // (A lane with a NaN gets a NaN t, kept or dropped here, and no query keeps it.)
        const unsigned some_negative = (u | v | w).mask(), all_negative = (u & v & w).mask();
        return (zeros | ~(some_negative & ~all_negative)) & 0xfu;
    }
};

#if CSGRT_BVH_AVX2
/// Eight lanes of TriangleSet<float>'s test at once (eight triangles against one ray, or one
/// triangle against eight rays): the corners' coordinates on the test's axes relative to the
/// origin, sheared, and the edge functions, with the float operations of TriangleSet::shear
/// and hit_sheared lane by lane (no fused multiply-add), so each lane holds the scalar test's
/// bits.
struct Avx2ShearedLanes {
    __m256 x[3], y[3], z[3], u, v, w;
    /// Lanes with an edge function that is exactly zero (hit_sheared recomputes those).
    unsigned zeros;

    /// corners[k][a]: corner k on the test's axis a (x, y, z), lane by lane.
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] Avx2ShearedLanes(const __m256 (&corners)[3][3],
                                                            const __m256 (&origin)[3],
                                                            __m256 shear_x, __m256 shear_y) {
        __m256 relative[3][3];
        for (int k = 0; k < 3; ++k) {
            for (int a = 0; a < 3; ++a) relative[k][a] = _mm256_sub_ps(corners[k][a], origin[a]);
        }
        shear(relative, shear_x, shear_y);
    }
    /// From the corners relative to the origin already (corner - origin in float, as above).
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] Avx2ShearedLanes(const __m256 (&relative)[3][3],
                                                            __m256 shear_x, __m256 shear_y) {
        shear(relative, shear_x, shear_y);
    }

    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] void shear(const __m256 (&relative)[3][3],
                                                      __m256 shear_x, __m256 shear_y) {
        for (int k = 0; k < 3; ++k) {
            const __m256 px = relative[k][0], py = relative[k][1], pz = relative[k][2];
            x[k] = _mm256_sub_ps(px, _mm256_mul_ps(shear_x, pz));
            y[k] = _mm256_sub_ps(py, _mm256_mul_ps(shear_y, pz));
            z[k] = pz;
        }
        u = _mm256_sub_ps(_mm256_mul_ps(x[2], y[1]), _mm256_mul_ps(y[2], x[1]));
        v = _mm256_sub_ps(_mm256_mul_ps(x[0], y[2]), _mm256_mul_ps(y[0], x[2]));
        w = _mm256_sub_ps(_mm256_mul_ps(x[1], y[0]), _mm256_mul_ps(y[1], x[0]));
        const __m256 zero = _mm256_setzero_ps();
        zeros = static_cast<unsigned>(_mm256_movemask_ps(_mm256_or_ps(
            _mm256_or_ps(_mm256_cmp_ps(u, zero, _CMP_EQ_OQ), _mm256_cmp_ps(v, zero, _CMP_EQ_OQ)),
            _mm256_cmp_ps(w, zero, _CMP_EQ_OQ))));
    }

    /// Lanes 4 half .. 4 half + 3 as BlockRay::candidates leaves them in its ShearedBlock.
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] ShearedBlock half(int half) const {
        ShearedBlock block;
        for (int k = 0; k < 3; ++k) {
            block.x[k] = part(x[k], half);
            block.y[k] = part(y[k], half);
            block.z[k] = part(z[k], half);
        }
        block.u = part(u, half);
        block.v = part(v, half);
        block.w = part(w, half);
        return block;
    }
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] static Float4 part(__m256 lanes, int half) {
        return {half == 0 ? _mm256_castps256_ps128(lanes) : _mm256_extractf128_ps(lanes, 1)};
    }

    /// The lanes that may hit: as BlockRay::candidates, a lane is dropped only when its edge
    /// functions are non-zero and of mixed signs (read off their sign bits).
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] unsigned candidates() const {
        const unsigned some_negative =
            static_cast<unsigned>(_mm256_movemask_ps(_mm256_or_ps(_mm256_or_ps(u, v), w)));
        const unsigned all_negative =
            static_cast<unsigned>(_mm256_movemask_ps(_mm256_and_ps(_mm256_and_ps(u, v), w)));
        return (zeros | ~(some_negative & ~all_negative)) & 0xffu;
    }
};
#endif

#if CSGRT_BVH_AVX2
/// BlockRay::candidates on a group of eight lanes at once, in 8-lane AVX2 steps: the same
/// operations lane by lane (no fused multiply-add), so the same bits. Most leaves hold five to
/// eight triangles, one such group.
struct alignas(32) Avx2BlockRay {
    __m256 origin[3], shear_x, shear_y;
    std::ptrdiff_t axis[3];

    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] explicit Avx2BlockRay(const BlockRay& ray) {
        for (int a = 0; a < 3; ++a) {
            origin[a] = _mm256_set_m128(ray.origin[a].v, ray.origin[a].v);
            axis[a] = ray.axis[a];
        }
        shear_x = _mm256_set_m128(ray.shear_x.v, ray.shear_x.v);
        shear_y = _mm256_set_m128(ray.shear_y.v, ray.shear_y.v);
    }

    /// The group of eight lanes at `lanes` (32-byte aligned) sheared, with its edge functions:
    /// its candidates() are BlockRay::candidates' of its two halves (bits 0-3 and 4-7).
    template <int kAxisZ>
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] Avx2ShearedLanes shear(const float* lanes) const {
        __m256 corners[3][3];
        for (int k = 0; k < 3; ++k) {
            for (int a = 0; a < 3; ++a)
                corners[k][a] = _mm256_load_ps(lanes + 24 * k + 8 * test_axis<kAxisZ>(a));
        }
        return Avx2ShearedLanes(corners, origin, shear_x, shear_y);
    }
};
#endif

#if CSGRT_BVH_AVX2
/// The rays of a packet as TriangleSet<float>'s test sees them, lane r holding ray r, for
/// packets whose rays share the test's axis permutation: each triangle of a leaf is sheared
/// into every ray's frame at once with the float operations of TriangleSet::shear and the edge
/// functions of hit_sheared, lane by lane, so each lane holds its ray's own values (the
/// ray-parallel leaf test of Wald et al., "Interactive Rendering with Coherent Ray Tracing",
/// 2001). Lanes the sign test rules out are misses for the scalar test too; the others finish
/// with TriangleSet::hit_sheared on their own values.
struct alignas(32) PacketTriangleRays {
    __m256 origin[3], shear_x, shear_y;
    std::ptrdiff_t axis[3];
    /// The rays' common origin in float, on the axes x, y, z.
    float origin_point[3];

    /// Whether the open rays' prepared rays share their axes; if so, sets the lanes up.
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] bool accepts(
        const TriangleSet<float>::PreparedRay* prepared, std::uint32_t open) {
        const auto& first = prepared[std::countr_zero(open)];
        alignas(32) float values[5][8] = {};
        for (std::uint32_t m = open; m != 0; m &= m - 1) {
            const int r = std::countr_zero(m);
            const auto& ray = prepared[r];
            if (ray.axis_z != first.axis_z) return false;
            values[0][r] = ray.origin[ray.axis_x];
            values[1][r] = ray.origin[ray.axis_y];
            values[2][r] = ray.origin[ray.axis_z];
            values[3][r] = ray.shear_x;
            values[4][r] = ray.shear_y;
        }
        axis[0] = first.axis_x;
        axis[1] = first.axis_y;
        axis[2] = first.axis_z;
        for (int a = 0; a < 3; ++a) origin[a] = _mm256_load_ps(values[a]);
        for (int k = 0; k < 3; ++k) origin_point[k] = first.origin[k];
        shear_x = _mm256_load_ps(values[3]);
        shear_y = _mm256_load_ps(values[4]);
        return true;
    }

    /// accepts for a packet's rays (1 to 8) all open, with their prepared rays made here,
    /// for packets that PacketIntervalTest::accepts_rays takes (finite rays, no zero direction
    /// component): TriangleSet::prepare's operations lane by lane (the axes of max_dimension,
    /// divpd, cvtpd2ps), so the same prepared rays, written to prepared[0, n). False, with
    /// nothing made, when the rays do not share their axes.
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] bool accepts_rays(
        const PacketRayColumns& packet, int n, TriangleSet<float>::PreparedRay* prepared) {
        const auto& rows = packet.rows;
        // max_dimension's choice, the first largest |d| in x, y, z order.
        const __m256d sign = _mm256_set1_pd(-0.0);
        unsigned on_x = 0, on_y = 0;
        for (int half = 0; half < 2; ++half) {
            const __m256d ax = _mm256_andnot_pd(sign, _mm256_load_pd(rows[3] + 4 * half));
            const __m256d ay = _mm256_andnot_pd(sign, _mm256_load_pd(rows[4] + 4 * half));
            const __m256d az = _mm256_andnot_pd(sign, _mm256_load_pd(rows[5] + 4 * half));
            const __m256d x_over_y = _mm256_cmp_pd(ax, ay, _CMP_GE_OQ);
            const __m256d x = _mm256_and_pd(x_over_y, _mm256_cmp_pd(ax, az, _CMP_GE_OQ));
            const __m256d y = _mm256_andnot_pd(x_over_y, _mm256_cmp_pd(ay, az, _CMP_GE_OQ));
            on_x |= static_cast<unsigned>(_mm256_movemask_pd(x)) << (4 * half);
            on_y |= static_cast<unsigned>(_mm256_movemask_pd(y)) << (4 * half);
        }
        int axis_z;
        if (on_x == 0xffu) {
            axis_z = 0;
        } else if (on_y == 0xffu) {
            axis_z = 1;
        } else if ((on_x | on_y) == 0) {
            axis_z = 2;
        } else {
            return false;
        }
        axis[2] = axis_z;
        axis[0] = axis_z == 2 ? 0 : axis_z + 1;
        axis[1] = axis[0] == 2 ? 0 : axis[0] + 1;
        alignas(32) float origin_lanes[3][8], shear_lanes[2][8];
        alignas(32) double scale[8];
        for (int half = 0; half < 2; ++half) {
            const __m256d dz = _mm256_load_pd(rows[3 + axis[2]] + 4 * half);
            const __m256d inverse = _mm256_div_pd(_mm256_set1_pd(1.0), dz);
            _mm256_store_pd(scale + 4 * half, inverse);
            for (int a = 0; a < 2; ++a) {
                const __m256d ratio =
                    _mm256_div_pd(_mm256_load_pd(rows[3 + axis[a]] + 4 * half), dz);
                _mm_store_ps(shear_lanes[a] + 4 * half, _mm256_cvtpd_ps(ratio));
            }
            for (int k = 0; k < 3; ++k)
                _mm_store_ps(origin_lanes[k] + 4 * half,
                             _mm256_cvtpd_ps(_mm256_load_pd(rows[k] + 4 * half)));
        }
        for (int a = 0; a < 3; ++a) origin[a] = _mm256_load_ps(origin_lanes[axis[a]]);
        for (int k = 0; k < 3; ++k) origin_point[k] = origin_lanes[k][0];
        shear_x = _mm256_load_ps(shear_lanes[0]);
        shear_y = _mm256_load_ps(shear_lanes[1]);
        for (int r = 0; r < n; ++r) {
            TriangleSet<float>::PreparedRay& ray = prepared[r];
            for (int k = 0; k < 3; ++k) ray.origin[k] = origin_lanes[k][r];
            ray.axis_x = static_cast<int>(axis[0]);
            ray.axis_y = static_cast<int>(axis[1]);
            ray.axis_z = axis_z;
            ray.shear_x = shear_lanes[0][r];
            ray.shear_y = shear_lanes[1][r];
            ray.shear_z = scale[r];
            ray.t_min = rows[6][r];
            ray.t_max = rows[7][r];
        }
        return true;
    }

    /// The corners of a group of kWidth lanes at `group` (BvhLeafTriangles; 4 or 8 lanes,
    /// aligned to their width) relative to the packet's origin, one subtraction for the whole
    /// group where each triangle against each ray would take one: relative[3 k + a][lane] is
    /// corner k's on axis a, fl(corner - origin) as Avx2ShearedLanes forms it. The rays of
    /// every packet PacketIntervalTest accepts share their origin.
    template <std::ptrdiff_t kWidth>
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] void relative_corners(const float* group,
                                                                 float (&relative)[9][8]) const {
        for (int row = 0; row < 9; ++row) {
            const float o = origin_point[row % 3];
            if constexpr (kWidth == 8) {
                _mm256_store_ps(relative[row],
                                _mm256_sub_ps(_mm256_load_ps(group + 8 * row), _mm256_set1_ps(o)));
            } else {
                static_assert(kWidth == 4);
                _mm_store_ps(relative[row],
                             _mm_sub_ps(_mm_load_ps(group + 4 * row), _mm_set1_ps(o)));
            }
        }
    }

    /// The rays (bits of `rays`) for which the triangle of lane `lane` of a group whose corners
    /// relative_corners gave may be hit; where there are some, `sheared` holds every ray's
    /// sheared corners (x, y, z of corners 0, 1, 2).
    template <int kAxisZ>
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] unsigned candidates(const float (&relative)[9][8],
                                                               std::ptrdiff_t lane, unsigned rays,
                                                               float (&sheared)[9][8]) const {
        __m256 corners[3][3];
        for (int k = 0; k < 3; ++k) {
            for (int a = 0; a < 3; ++a)
                corners[k][a] = _mm256_set1_ps(relative[3 * k + test_axis<kAxisZ>(a)][lane]);
        }
        const Avx2ShearedLanes lanes(corners, shear_x, shear_y);
        const unsigned result = lanes.candidates() & rays;
        if (result != 0) {
            for (int k = 0; k < 3; ++k) {
                _mm256_store_ps(sheared[k], lanes.x[k]);
                _mm256_store_ps(sheared[3 + k], lanes.y[k]);
                _mm256_store_ps(sheared[6 + k], lanes.z[k]);
            }
        }
        return result;
    }
};
#endif

}  // namespace csgrt::detail
