#include "csgrt/accel/bvh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <new>
#include <span>
#include <type_traits>

#include "accelerator_base.h"
#include "bvh_simd.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/error.h"

// The AVX2 node test is compiled for x86-64 with GCC or Clang only, as functions with their own
// target attribute: the library itself stays baseline x86-64, and build() picks the AVX2 code
// only on a CPU that has it.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define CSGRT_BVH_AVX2 1
#include <immintrin.h>
#else
#define CSGRT_BVH_AVX2 0
#endif

namespace csgrt {

namespace {

constexpr float kFloatInfinity = std::numeric_limits<float>::infinity();
constexpr double kFloatMax = std::numeric_limits<float>::max();
/// Beyond this a coordinate or reciprocal direction component is not trusted to the float
/// slab test (products could overflow or underflow to denormals).
constexpr double kLargestBoxRayValue = 0x1p100;
constexpr float kSlack = Bvh<TriangleSet<float>>::kSlabSlack;
/// Triangles in a BvhTriangleBlock.
constexpr std::uint32_t kBlockLanes = 4;

/// The largest float <= x (x not NaN).
float round_down(double x) {
    if (x > kFloatMax) return static_cast<float>(kFloatMax);
    if (x < -kFloatMax) return -kFloatInfinity;
    float f = static_cast<float>(x);
    if (double(f) > x) f = std::nextafter(f, -kFloatInfinity);
    return f;
}

/// The smallest float >= x (x not NaN).
float round_up(double x) {
    if (x > kFloatMax) return kFloatInfinity;
    if (x < -kFloatMax) return -static_cast<float>(kFloatMax);
    float f = static_cast<float>(x);
    if (double(f) < x) f = std::nextafter(f, kFloatInfinity);
    return f;
}

/// A primitive's box padded by kPrimitivePadding of its size and magnitude and rounded
/// outward to float.
void pad_box(const Aabb& box, detail::BuildPrimitive& primitive) {
    if (box.is_empty()) {
        for (int axis = 0; axis < 3; ++axis) {
            primitive.lower[axis] = kFloatInfinity;
            primitive.upper[axis] = -kFloatInfinity;
        }
        return;
    }
    const double magnitude =
        std::max(box.lower.cwiseAbs().maxCoeff(), box.upper.cwiseAbs().maxCoeff());
    const double padding =
        Bvh<TriangleSet<float>>::kPrimitivePadding * (magnitude + box.diagonal().maxCoeff());
    for (int axis = 0; axis < 3; ++axis) {
        primitive.lower[axis] = round_down(box.lower[axis] - padding);
        primitive.upper[axis] = round_up(box.upper[axis] + padding);
    }
}

/// pad_box for a triangle of float corners, in float: twice the padding, computed with
/// rounding to nearest, still leaves each bound at least kPrimitivePadding (magnitude + size)
/// beyond the exact one, because the rounding errors are at most a few 2^-24 of the magnitude,
/// far below the padding's 2^-18 of it; the padding is at least the smallest normal float, so
/// tiny coordinates are padded too. Corners that are not all finite take the double path.
void pad_triangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                  detail::BuildPrimitive& primitive) {
    const Eigen::Vector3f lower = a.cwiseMin(b).cwiseMin(c);
    const Eigen::Vector3f upper = a.cwiseMax(b).cwiseMax(c);
    const float magnitude = std::max(lower.cwiseAbs().maxCoeff(), upper.cwiseAbs().maxCoeff());
    if (!(magnitude <= std::numeric_limits<float>::max())) {
        Aabb box;
        for (const Eigen::Vector3f* corner : {&a, &b, &c}) box.extend(corner->cast<double>());
        pad_box(box, primitive);
        return;
    }
    constexpr auto kPadding = static_cast<float>(2.0 * Bvh<TriangleSet<float>>::kPrimitivePadding);
    const float padding = std::max(kPadding * (magnitude + (upper - lower).maxCoeff()),
                                   std::numeric_limits<float>::min());
    for (int axis = 0; axis < 3; ++axis) {
        primitive.lower[axis] = lower[axis] - padding;
        primitive.upper[axis] = upper[axis] + padding;
    }
}

}  // namespace

namespace detail {

/// The ray as the float slab tests see it. The origin is rounded to nearest, as the float
/// triangle test rounds it, so both tests measure t from the same point.
///
/// The slack widens [t_enter, t_exit] by kSlabSlack of its magnitude at both ends. When
/// t_min >= 0 only non-negative distances can matter (a negative t_exit means a miss either
/// way, and rounding never flips a sign), so it is folded into the reciprocals: near planes
/// use (1 - slack) / d, far planes (1 + slack) / d. Otherwise (`signed_interval`) the
/// traversal widens each interval by its magnitude.
struct BoxRay {
    // Lane 3 of each is padding (written as four floats at once).
    float origin[4];
    float inverse_near[4];
    float inverse_far[4];
    /// Whether the direction's sign bit is set (-0 included): the box's upper face is then
    /// the near one, and the products below never form 0 * inf except in a face's plane.
    bool negative[3];
    bool signed_interval;
    /// is_valid(ray), found from the representability test where it can be (see below).
    bool valid;
    float t_min;

    // Inlined into the query: it runs once a ray, and most camera rays never reach a leaf.
    // With SSE2 the representability test and the reciprocals take the components two and
    // four at a time (divps and cvtpd2ps round lane by lane exactly as divss and cvtsd2ss do),
    // and the common case of round_down (t_min a float: 0 or -inf) is taken first.
    [[gnu::always_inline]] explicit BoxRay(const Ray& ray) {
        const float t_min_float = static_cast<float>(ray.t_min);
        t_min = double(t_min_float) <= ray.t_min && t_min_float != kFloatInfinity
                    ? t_min_float
                    : round_down(ray.t_min);
        signed_interval = !(t_min >= 0.0f);
#if defined(__SSE2__)
        const double* o = ray.origin.data();
        const double* d = ray.direction.data();
        // (o0, o1), (o2, d0), (d1, d2).
        const __m128d v0 = _mm_loadu_pd(o), v1 = _mm_set_pd(d[0], o[2]), v2 = _mm_loadu_pd(d + 1);
        const __m128d sign = _mm_set1_pd(-0.0), zero = _mm_setzero_pd();
        const __m128d largest = _mm_set1_pd(kLargestBoxRayValue);
        const __m128d smallest = _mm_set1_pd(1.0 / kLargestBoxRayValue);
        const __m128d a0 = _mm_andnot_pd(sign, v0), a1 = _mm_andnot_pd(sign, v1),
                      a2 = _mm_andnot_pd(sign, v2);
        // Every |component| <= 2^100 (false for NaN); each direction component 0 or >= 2^-100.
        const __m128d small_ok1 =
            _mm_or_pd(_mm_or_pd(_mm_cmpge_pd(a1, smallest), _mm_cmpeq_pd(v1, zero)),
                      _mm_castsi128_pd(_mm_set_epi32(0, 0, -1, -1)));
        const __m128d small_ok2 = _mm_or_pd(_mm_cmpge_pd(a2, smallest), _mm_cmpeq_pd(v2, zero));
        const __m128d ok = _mm_and_pd(
            _mm_and_pd(_mm_cmple_pd(a0, largest), _mm_and_pd(_mm_cmple_pd(a1, largest), small_ok1)),
            _mm_and_pd(_mm_cmple_pd(a2, largest), small_ok2));
        const bool representable = _mm_movemask_pd(ok) == 3;
        const int signs = _mm_movemask_pd(v1) >> 1 | _mm_movemask_pd(v2) << 1;
        for (int axis = 0; axis < 3; ++axis) negative[axis] = (signs >> axis) & 1;
        // A representable ray has a finite origin and direction, and a non-zero direction
        // component is at least 2^-100, so its squared norm (>= 2^-200) is positive exactly
        // when some component is not zero; t_min <= t_max is false for NaN. So is_valid
        // reduces to two tests, and only the rare unrepresentable ray pays for the full one.
        const int zero_direction = _mm_movemask_pd(_mm_cmpeq_pd(v1, zero)) >> 1 |
                                   _mm_movemask_pd(_mm_cmpeq_pd(v2, zero)) << 1;
        valid = representable ? zero_direction != 7 && ray.t_min <= ray.t_max : is_valid(ray);
#else
        bool representable = true;
        for (int axis = 0; axis < 3; ++axis) {
            const double d = ray.direction[axis], magnitude = std::abs(d);
            representable &= (std::abs(ray.origin[axis]) <= kLargestBoxRayValue) &
                             ((d == 0.0) | ((magnitude <= kLargestBoxRayValue) &
                                            (magnitude >= 1.0 / kLargestBoxRayValue)));
            negative[axis] = std::signbit(d);
        }
        valid = is_valid(ray);
#endif
        if (!representable) [[unlikely]] {
            // Every slab distance becomes NaN, which the tests ignore: every box is entered.
            for (int axis = 0; axis < 4; ++axis) {
                origin[axis] = 0.0f;
                inverse_near[axis] = inverse_far[axis] = std::numeric_limits<float>::quiet_NaN();
            }
            t_min = -kFloatInfinity;
            signed_interval = true;
            return;
        }
        const float near_scale = signed_interval ? 1.0f : 1.0f - kSlack;
        const float far_scale = signed_interval ? 1.0f : 1.0f + kSlack;
#if defined(__SSE2__)
        // Lane 3 is padding: origin 0, direction 1.
        const __m128 origin4 = _mm_movelh_ps(_mm_cvtpd_ps(v0), _mm_cvtpd_ps(_mm_move_sd(zero, v1)));
        const __m128 direction4 =
            _mm_movelh_ps(_mm_cvtpd_ps(_mm_shuffle_pd(v1, v2, 1)),
                          _mm_cvtpd_ps(_mm_unpackhi_pd(v2, _mm_set1_pd(1.0))));
        // +-0 gives +-inf, whose products with plane distances are +-inf or NaN.
        const __m128 inverse = _mm_div_ps(_mm_set1_ps(1.0f), direction4);
        _mm_storeu_ps(origin, origin4);
        _mm_storeu_ps(inverse_near, _mm_mul_ps(inverse, _mm_set1_ps(near_scale)));
        _mm_storeu_ps(inverse_far, _mm_mul_ps(inverse, _mm_set1_ps(far_scale)));
#else
        for (int axis = 0; axis < 3; ++axis) {
            origin[axis] = static_cast<float>(ray.origin[axis]);
            // +-0 gives +-inf, whose products with plane distances are +-inf or NaN.
            const float inverse = 1.0f / static_cast<float>(ray.direction[axis]);
            inverse_near[axis] = inverse * near_scale;
            inverse_far[axis] = inverse * far_scale;
        }
#endif
    }
    /// Offsets (in floats) of the rows of WideBvhNode<kWidth>::bounds that hold each axis'
    /// near and far planes.
    int near_row(int axis, int width) const {
        return (2 * axis + (negative[axis] ? 1 : 0)) * width;
    }
    int far_row(int axis, int width) const {
        return (2 * axis + (negative[axis] ? 0 : 1)) * width;
    }
};

/// Conservative slab test of one binary node's box: [t_enter, t_exit] clipped to
/// [t_min, t_max] and widened by the slack; true when it is not empty. An empty box gives an
/// empty interval (or NaN, which compares false).
template <bool kSigned>
bool hit_box(const BvhNode& node, const BoxRay& ray, float t_max, float& t_enter) {
    float t0 = ray.t_min, t1 = t_max;
    for (int axis = 0; axis < 3; ++axis) {
        const float near_plane = ray.negative[axis] ? node.upper[axis] : node.lower[axis];
        const float far_plane = ray.negative[axis] ? node.lower[axis] : node.upper[axis];
        const float t_near = (near_plane - ray.origin[axis]) * ray.inverse_near[axis];
        const float t_far = (far_plane - ray.origin[axis]) * ray.inverse_far[axis];
        // NaN (0 * inf: a ray parallel to the slab, in a face's plane) leaves t0, t1 as they
        // are: the ray is inside that slab for every t.
        t0 = t_near > t0 ? t_near : t0;
        t1 = t_far < t1 ? t_far : t1;
    }
    if constexpr (kSigned) {
        t0 -= std::abs(t0) * kSlack;
        t1 += std::abs(t1) * kSlack;
    }
    t_enter = t0;
    return t0 <= t1;
}

/// The boxes of a wide node, four at a time, with the arithmetic of hit_box lane by lane
/// except for NaN slabs: max and min return their second operand when either is NaN, so a
/// NaN drops one slab (or two), which only widens the interval; t_min and t_max come last, so
/// the result is never NaN.
template <int kWidth>
struct SseNodeTest {
    Float4 origin[3], inverse_near[3], inverse_far[3], t_min;
    int near_row[3], far_row[3];

    explicit SseNodeTest(const BoxRay& ray) {
        for (int axis = 0; axis < 3; ++axis) {
            origin[axis] = Float4::broadcast(ray.origin[axis]);
            inverse_near[axis] = Float4::broadcast(ray.inverse_near[axis]);
            inverse_far[axis] = Float4::broadcast(ray.inverse_far[axis]);
            near_row[axis] = ray.near_row(axis, kWidth);
            far_row[axis] = ray.far_row(axis, kWidth);
        }
        t_min = Float4::broadcast(ray.t_min);
    }

    /// Bit i of the result says child i is entered, at t_enter[i] (16-byte aligned).
    template <bool kSigned>
    unsigned hit(const WideBvhNode<kWidth>& node, float t_max, float* t_enter) const {
        unsigned mask = 0;
        const Float4 t_max4 = Float4::broadcast(t_max);
        for (int group = 0; group < kWidth; group += 4) {
            const float* bounds = node.bounds[0] + group;
            Float4 t_near[3], t_far[3];
            for (int axis = 0; axis < 3; ++axis) {
                t_near[axis] = (Float4::load_aligned(bounds + near_row[axis]) - origin[axis]) *
                               inverse_near[axis];
                t_far[axis] = (Float4::load_aligned(bounds + far_row[axis]) - origin[axis]) *
                              inverse_far[axis];
            }
            Float4 t0 = max(max(t_near[0], t_near[1]), max(t_near[2], t_min));
            Float4 t1 = min(min(t_far[0], t_far[1]), min(t_far[2], t_max4));
            if constexpr (kSigned) {
                const Float4 slack = Float4::broadcast(kSlack);
                t0 = t0 - abs(t0) * slack;
                t1 = t1 + abs(t1) * slack;
            }
            t0.store(t_enter + group);
            mask |= (t0 <= t1).mask() << group;
        }
        return mask;
    }
};

#if CSGRT_BVH_AVX2
// The AVX2 types are aligned explicitly: compiled for baseline x86-64, GCC aligns a struct of
// __m256 members to 16 bytes only, and the AVX2 code's aligned stores to it would fault.

/// SseNodeTest<8> in one 8-lane AVX step: the same operations, lane by lane, in the same order
/// (no fused multiply-add), so the same masks and entry distances.
struct alignas(32) Avx2NodeTest {
    __m256 origin[3], inverse_near[3], inverse_far[3], t_min;
    int near_row[3], far_row[3];

    [[gnu::target("avx2")]] explicit Avx2NodeTest(const BoxRay& ray) {
        for (int axis = 0; axis < 3; ++axis) {
            origin[axis] = _mm256_set1_ps(ray.origin[axis]);
            inverse_near[axis] = _mm256_set1_ps(ray.inverse_near[axis]);
            inverse_far[axis] = _mm256_set1_ps(ray.inverse_far[axis]);
            near_row[axis] = ray.near_row(axis, 8);
            far_row[axis] = ray.far_row(axis, 8);
        }
        t_min = _mm256_set1_ps(ray.t_min);
    }

    /// As SseNodeTest<8>::hit; t_enter must be 32-byte aligned.
    template <bool kSigned>
    [[gnu::target("avx2")]] unsigned hit(const Bvh8Node& node, float t_max, float* t_enter) const {
        const float* bounds = node.bounds[0];
        __m256 t_near[3], t_far[3];
        for (int axis = 0; axis < 3; ++axis) {
            t_near[axis] =
                _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(bounds + near_row[axis]), origin[axis]),
                              inverse_near[axis]);
            t_far[axis] =
                _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(bounds + far_row[axis]), origin[axis]),
                              inverse_far[axis]);
        }
        __m256 t0 =
            _mm256_max_ps(_mm256_max_ps(t_near[0], t_near[1]), _mm256_max_ps(t_near[2], t_min));
        __m256 t1 = _mm256_min_ps(_mm256_min_ps(t_far[0], t_far[1]),
                                  _mm256_min_ps(t_far[2], _mm256_set1_ps(t_max)));
        if constexpr (kSigned) {
            const __m256 sign = _mm256_set1_ps(-0.0f), slack = _mm256_set1_ps(kSlack);
            t0 = _mm256_sub_ps(t0, _mm256_mul_ps(_mm256_andnot_ps(sign, t0), slack));
            t1 = _mm256_add_ps(t1, _mm256_mul_ps(_mm256_andnot_ps(sign, t1), slack));
        }
        _mm256_store_ps(t_enter, t0);
        return static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OQ)));
    }
};
#endif

#if CSGRT_BVH_AVX2
/// The node test of a packet of rays whose directions share their signs, taken as intervals
/// (interval arithmetic culling: Wald, Boulos and Shirley, "Ray Tracing Deformable Scenes
/// Using Dynamic Bounding Volume Hierarchies", ACM TOG 2007). On each axis the rays' origins
/// span [o_low, o_high] and their (slack-scaled) reciprocals [near_low, near_high] and
/// [far_low, far_high], all of one sign. Rounding to nearest is monotone, so fl(b - o) and
/// fl(x * inverse) move the way their exact values do, and each ray's own near distance
/// fl(fl(b - o_r) * near_r) is at least the smaller of fl(fl(b - o) * near_low) and
/// fl(fl(b - o) * near_high) with o the end of the origin interval that makes b - o least
/// along the ray (o_high for a positive direction, o_low for a negative one); likewise each
/// far distance is at most the larger of the two products from the other end. So the
/// packet's [t_enter, t_exit] contains every ray's, and the packet enters every child that
/// one of its rays would enter: the leaves it reaches include each ray's own. Rays that could
/// make a slab distance NaN (a zero direction component, an unrepresentable ray) or need the
/// signed-interval widening are not accepted, nor packets without a common origin; those go
/// one ray at a time.
struct alignas(32) PacketIntervalTest {
    __m256 near_origin[3], far_origin[3], near_low[3], near_high[3], far_low[3], far_high[3];
    __m256 t_min;
    int near_row[3], far_row[3];

    /// Whether the open rays of `lanes` (bits of `open`) can be walked as one; if so, sets the
    /// test up.
    template <class Lanes>
    [[gnu::target("avx2")]] bool accepts(const Lanes& lanes, std::uint32_t open) {
        const BoxRay& first = lanes[std::countr_zero(open)].box;
        float o_low[3], o_high[3], n_low[3], n_high[3], f_low[3], f_high[3];
        float lowest_t_min = kFloatInfinity;
        for (int axis = 0; axis < 3; ++axis) {
            o_low[axis] = n_low[axis] = f_low[axis] = kFloatInfinity;
            o_high[axis] = n_high[axis] = f_high[axis] = -kFloatInfinity;
        }
        for (std::uint32_t m = open; m != 0; m &= m - 1) {
            const BoxRay& ray = lanes[std::countr_zero(m)].box;
            if (ray.signed_interval) return false;
            // One origin (a pinhole camera's rays): see traverse_packet.
            if (!(ray.origin[0] == first.origin[0] && ray.origin[1] == first.origin[1] &&
                  ray.origin[2] == first.origin[2])) {
                return false;
            }
            lowest_t_min = std::min(lowest_t_min, ray.t_min);
            for (int axis = 0; axis < 3; ++axis) {
                // Finite reciprocals (false for the NaN of an unrepresentable ray and for the
                // infinity of a zero component), and one sign per axis.
                if (!(std::abs(ray.inverse_near[axis]) <= std::numeric_limits<float>::max() &&
                      std::abs(ray.inverse_far[axis]) <= std::numeric_limits<float>::max()) ||
                    ray.negative[axis] != first.negative[axis]) {
                    return false;
                }
                o_low[axis] = std::min(o_low[axis], ray.origin[axis]);
                o_high[axis] = std::max(o_high[axis], ray.origin[axis]);
                n_low[axis] = std::min(n_low[axis], ray.inverse_near[axis]);
                n_high[axis] = std::max(n_high[axis], ray.inverse_near[axis]);
                f_low[axis] = std::min(f_low[axis], ray.inverse_far[axis]);
                f_high[axis] = std::max(f_high[axis], ray.inverse_far[axis]);
            }
        }
        for (int axis = 0; axis < 3; ++axis) {
            const bool negative = first.negative[axis];
            near_origin[axis] = _mm256_set1_ps(negative ? o_low[axis] : o_high[axis]);
            far_origin[axis] = _mm256_set1_ps(negative ? o_high[axis] : o_low[axis]);
            near_low[axis] = _mm256_set1_ps(n_low[axis]);
            near_high[axis] = _mm256_set1_ps(n_high[axis]);
            far_low[axis] = _mm256_set1_ps(f_low[axis]);
            far_high[axis] = _mm256_set1_ps(f_high[axis]);
            near_row[axis] = first.near_row(axis, 8);
            far_row[axis] = first.far_row(axis, 8);
        }
        t_min = _mm256_set1_ps(lowest_t_min);
        return true;
    }

    /// As Avx2NodeTest::hit<false> for the whole packet; t_enter must be 32-byte aligned.
    template <bool kSigned>
    [[gnu::target("avx2")]] unsigned hit(const Bvh8Node& node, float t_max, float* t_enter) const {
        static_assert(!kSigned, "packets with signed intervals are walked ray by ray");
        const float* bounds = node.bounds[0];
        __m256 t_near[3], t_far[3];
        for (int axis = 0; axis < 3; ++axis) {
            const __m256 near_distance =
                _mm256_sub_ps(_mm256_load_ps(bounds + near_row[axis]), near_origin[axis]);
            const __m256 far_distance =
                _mm256_sub_ps(_mm256_load_ps(bounds + far_row[axis]), far_origin[axis]);
            t_near[axis] = _mm256_min_ps(_mm256_mul_ps(near_distance, near_low[axis]),
                                         _mm256_mul_ps(near_distance, near_high[axis]));
            t_far[axis] = _mm256_max_ps(_mm256_mul_ps(far_distance, far_low[axis]),
                                        _mm256_mul_ps(far_distance, far_high[axis]));
        }
        const __m256 t0 =
            _mm256_max_ps(_mm256_max_ps(t_near[0], t_near[1]), _mm256_max_ps(t_near[2], t_min));
        const __m256 t1 = _mm256_min_ps(_mm256_min_ps(t_far[0], t_far[1]),
                                        _mm256_min_ps(t_far[2], _mm256_set1_ps(t_max)));
        _mm256_store_ps(t_enter, t0);
        return static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OQ)));
    }
};
#endif

/// Four triangles of a block sheared into the frame of the ray, lane by lane, with their edge
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

/// The first half of TriangleSet<float>'s test on the four triangles of a block at once: the
/// same float operations as TriangleSet::shear and the edge functions of hit_sheared, lane by
/// lane, so the values are the scalar test's bits. A lane whose three edge functions are
/// non-zero and of mixed signs is a miss for the scalar test too (it only recomputes exact
/// zeros).
struct BlockRay {
    /// The origin's and the shear's components, on the permuted axes (x, y, z of the test).
    Float4 origin[3], shear_x, shear_y;
    int axis[3];

    explicit BlockRay(const TriangleSet<float>::PreparedRay& ray)
        : shear_x(Float4::broadcast(ray.shear_x)), shear_y(Float4::broadcast(ray.shear_y)) {
        axis[0] = ray.axis_x;
        axis[1] = ray.axis_y;
        axis[2] = ray.axis_z;
        for (int a = 0; a < 3; ++a) origin[a] = Float4::broadcast(ray.origin[axis[a]]);
    }

    /// The lanes that may hit (bit l for lane l), the block sheared, and in `zeros` the lanes
    /// with an edge function that is exactly zero (left to TriangleSet::hit_sheared, which
    /// recomputes those in double). Every other candidate lane is a hit whose t and
    /// barycentrics BlockHits gives.
    unsigned candidates(const BvhTriangleBlock& block, ShearedBlock& sheared,
                        unsigned& zeros) const {
        for (int k = 0; k < 3; ++k) {
            const Float4 px = Float4::load_aligned(block.corners[k][axis[0]]) - origin[0];
            const Float4 py = Float4::load_aligned(block.corners[k][axis[1]]) - origin[1];
            const Float4 pz = Float4::load_aligned(block.corners[k][axis[2]]) - origin[2];
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
/// BlockRay::candidates on two consecutive blocks at once, lanes 0-3 the first and 4-7 the
/// second, in 8-lane AVX2 steps: the same operations lane by lane (no fused multiply-add), so
/// the same bits. Most leaves hold five to eight triangles, two blocks.
struct alignas(32) Avx2BlockRay {
    __m256 origin[3], shear_x, shear_y;
    int axis[3];

    [[gnu::target("avx2")]] explicit Avx2BlockRay(const BlockRay& ray) {
        for (int a = 0; a < 3; ++a) {
            origin[a] = _mm256_set_m128(ray.origin[a].v, ray.origin[a].v);
            axis[a] = ray.axis[a];
        }
        shear_x = _mm256_set_m128(ray.shear_x.v, ray.shear_x.v);
        shear_y = _mm256_set_m128(ray.shear_y.v, ray.shear_y.v);
    }

    // (Lambdas would not inherit the target attribute: these are functions.)
    [[gnu::target("avx2")]] static __m256 load(const BvhTriangleBlock& first,
                                               const BvhTriangleBlock& second, int k, int a) {
        return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(first.corners[k][a])),
                                    _mm_load_ps(second.corners[k][a]), 1);
    }
    [[gnu::target("avx2")]] static void split(__m256 lanes, Float4& low, Float4& high) {
        low.v = _mm256_castps256_ps128(lanes);
        high.v = _mm256_extractf128_ps(lanes, 1);
    }

    /// As BlockRay::candidates, bits 0-3 for `first` and 4-7 for `second`; `sheared` is
    /// written only when some lane is a candidate.
    [[gnu::target("avx2")]] unsigned candidates(const BvhTriangleBlock& first,
                                                const BvhTriangleBlock& second,
                                                ShearedBlock (&sheared)[2], unsigned& zeros) const {
        __m256 x[3], y[3], z[3];
        for (int k = 0; k < 3; ++k) {
            const __m256 px = _mm256_sub_ps(load(first, second, k, axis[0]), origin[0]);
            const __m256 py = _mm256_sub_ps(load(first, second, k, axis[1]), origin[1]);
            const __m256 pz = _mm256_sub_ps(load(first, second, k, axis[2]), origin[2]);
            x[k] = _mm256_sub_ps(px, _mm256_mul_ps(shear_x, pz));
            y[k] = _mm256_sub_ps(py, _mm256_mul_ps(shear_y, pz));
            z[k] = pz;
        }
        const __m256 u = _mm256_sub_ps(_mm256_mul_ps(x[2], y[1]), _mm256_mul_ps(y[2], x[1]));
        const __m256 v = _mm256_sub_ps(_mm256_mul_ps(x[0], y[2]), _mm256_mul_ps(y[0], x[2]));
        const __m256 w = _mm256_sub_ps(_mm256_mul_ps(x[1], y[0]), _mm256_mul_ps(y[1], x[0]));
        const __m256 zero = _mm256_setzero_ps();
        zeros = static_cast<unsigned>(_mm256_movemask_ps(_mm256_or_ps(
            _mm256_or_ps(_mm256_cmp_ps(u, zero, _CMP_EQ_OQ), _mm256_cmp_ps(v, zero, _CMP_EQ_OQ)),
            _mm256_cmp_ps(w, zero, _CMP_EQ_OQ))));
        const unsigned some_negative =
            static_cast<unsigned>(_mm256_movemask_ps(_mm256_or_ps(_mm256_or_ps(u, v), w)));
        const unsigned all_negative =
            static_cast<unsigned>(_mm256_movemask_ps(_mm256_and_ps(_mm256_and_ps(u, v), w)));
        const unsigned result = (zeros | ~(some_negative & ~all_negative)) & 0xffu;
        if (result != 0) {
            for (int k = 0; k < 3; ++k) {
                split(x[k], sheared[0].x[k], sheared[1].x[k]);
                split(y[k], sheared[0].y[k], sheared[1].y[k]);
                split(z[k], sheared[0].z[k], sheared[1].z[k]);
            }
            split(u, sheared[0].u, sheared[1].u);
            split(v, sheared[0].v, sheared[1].v);
            split(w, sheared[0].w, sheared[1].w);
        }
        return result;
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
    int axis[3];

    /// Whether the open rays' prepared rays share their axes; if so, sets the lanes up.
    [[gnu::target("avx2")]] bool accepts(const TriangleSet<float>::PreparedRay* prepared,
                                         std::uint32_t open) {
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
        shear_x = _mm256_load_ps(values[3]);
        shear_y = _mm256_load_ps(values[4]);
        return true;
    }

    /// The rays (bits of `rays`) for which triangle `lane` of `block` may be hit; where there
    /// are some, `sheared` holds every ray's sheared corners (x, y, z of corners 0, 1, 2).
    [[gnu::target("avx2")]] unsigned candidates(const BvhTriangleBlock& block, int lane,
                                                unsigned rays, float (&sheared)[9][8]) const {
        __m256 x[3], y[3], z[3];
        for (int k = 0; k < 3; ++k) {
            const __m256 px =
                _mm256_sub_ps(_mm256_set1_ps(block.corners[k][axis[0]][lane]), origin[0]);
            const __m256 py =
                _mm256_sub_ps(_mm256_set1_ps(block.corners[k][axis[1]][lane]), origin[1]);
            const __m256 pz =
                _mm256_sub_ps(_mm256_set1_ps(block.corners[k][axis[2]][lane]), origin[2]);
            x[k] = _mm256_sub_ps(px, _mm256_mul_ps(shear_x, pz));
            y[k] = _mm256_sub_ps(py, _mm256_mul_ps(shear_y, pz));
            z[k] = pz;
        }
        const __m256 u = _mm256_sub_ps(_mm256_mul_ps(x[2], y[1]), _mm256_mul_ps(y[2], x[1]));
        const __m256 v = _mm256_sub_ps(_mm256_mul_ps(x[0], y[2]), _mm256_mul_ps(y[0], x[2]));
        const __m256 w = _mm256_sub_ps(_mm256_mul_ps(x[1], y[0]), _mm256_mul_ps(y[1], x[0]));
        const __m256 zero = _mm256_setzero_ps();
        const unsigned zeros = static_cast<unsigned>(_mm256_movemask_ps(_mm256_or_ps(
            _mm256_or_ps(_mm256_cmp_ps(u, zero, _CMP_EQ_OQ), _mm256_cmp_ps(v, zero, _CMP_EQ_OQ)),
            _mm256_cmp_ps(w, zero, _CMP_EQ_OQ))));
        const unsigned some_negative =
            static_cast<unsigned>(_mm256_movemask_ps(_mm256_or_ps(_mm256_or_ps(u, v), w)));
        const unsigned all_negative =
            static_cast<unsigned>(_mm256_movemask_ps(_mm256_and_ps(_mm256_and_ps(u, v), w)));
        const unsigned result = (zeros | ~(some_negative & ~all_negative)) & rays;
        if (result != 0) {
            for (int k = 0; k < 3; ++k) {
                _mm256_store_ps(sheared[k], x[k]);
                _mm256_store_ps(sheared[3 + k], y[k]);
                _mm256_store_ps(sheared[6 + k], z[k]);
            }
        }
        return result;
    }
};
#endif

/// Everything the queries do, for each layout and instruction set; a friend of Bvh.
template <class Set>
struct BvhTraversal {
    using Tree = Bvh<Set>;
    static constexpr bool kBlockSet = std::is_same_v<Set, TriangleSet<float>>;

    struct BinaryEntry {
        std::uint32_t node;
        float t_enter;
    };
    struct WideEntry {
        std::uint32_t first;
        std::uint32_t count;
        float t_enter;
    };

    /// Visits every leaf the ray may hit within [t_min, t_max], nearest entry first. `leaf`
    /// is called as leaf(first, count, t_max) with the leaf's reference (see Bvh::
    /// binary_nodes) and the float upper bound of the interval, which it may lower; it
    /// returns true to stop. kAvx2: the 8-wide tree with the AVX2 node test (run_avx2 only).
    template <bool kCount, bool kAvx2, class Leaf>
    static void traverse(const Tree& bvh, const Ray& ray, const BoxRay& box_ray,
                         TraversalCounters& counters, Leaf& leaf) {
#if CSGRT_BVH_AVX2
        if constexpr (kAvx2) {
            if (box_ray.signed_interval) {
                return traverse_wide<kCount, true, Avx2NodeTest>(bvh, bvh.nodes_8_, box_ray,
                                                                 ray.t_max, counters, leaf);
            }
            return traverse_wide<kCount, false, Avx2NodeTest>(bvh, bvh.nodes_8_, box_ray, ray.t_max,
                                                              counters, leaf);
        }
#endif
        if (bvh.config_.width == 8) {
            if (box_ray.signed_interval) {
                return traverse_wide<kCount, true, SseNodeTest<8>>(bvh, bvh.nodes_8_, box_ray,
                                                                   ray.t_max, counters, leaf);
            }
            return traverse_wide<kCount, false, SseNodeTest<8>>(bvh, bvh.nodes_8_, box_ray,
                                                                ray.t_max, counters, leaf);
        }
        if (bvh.config_.width == 4) {
            if (box_ray.signed_interval) {
                return traverse_wide<kCount, true, SseNodeTest<4>>(bvh, bvh.nodes_4_, box_ray,
                                                                   ray.t_max, counters, leaf);
            }
            return traverse_wide<kCount, false, SseNodeTest<4>>(bvh, bvh.nodes_4_, box_ray,
                                                                ray.t_max, counters, leaf);
        }
        if (box_ray.signed_interval) {
            return traverse_binary<kCount, true>(bvh, box_ray, ray.t_max, counters, leaf);
        }
        traverse_binary<kCount, false>(bvh, box_ray, ray.t_max, counters, leaf);
    }

    /// One query of kind kKind, with the AVX2 node test when kAvx2.
    template <QueryKind kKind, bool kCount, bool kAvx2>
    static bool run(const Tree& bvh, const Ray& ray, QueryAnswer<kKind>& answer,
                    QueryScratch& scratch, TraversalCounters& counters) {
        if constexpr (kKind == QueryKind::kNearest) {
            return intersect<kCount, kAvx2>(bvh, ray, answer, scratch, counters);
        } else if constexpr (kKind == QueryKind::kAny) {
            return occluded<kCount, kAvx2>(bvh, ray, scratch, counters);
        } else {
            const std::size_t before = answer.size();
            all_hits<kAvx2>(bvh, ray, answer, scratch);
            return answer.size() > before;
        }
    }

#if CSGRT_BVH_AVX2
    /// The whole query compiled for AVX2: `flatten` inlines everything it calls (the ray's
    /// set-up, the traversal, the leaf visitor, the triangle test), so all of it is AVX2 code,
    /// here and nowhere else, with no call between the set-up and the traversal.
    template <QueryKind kKind, bool kCount>
    [[gnu::target("avx2"), gnu::flatten]] static bool run_avx2(const Tree& bvh, const Ray& ray,
                                                               QueryAnswer<kKind>& answer,
                                                               QueryScratch& scratch,
                                                               TraversalCounters& counters) {
        return run<kKind, kCount, true>(bvh, ray, answer, scratch, counters);
    }
#endif

    /// Starts loading what a leaf or node the traversal will come back to needs: a node's
    /// cache lines, a leaf's first block, a one-primitive leaf's primitive, or a leaf's
    /// indices.
    template <int kWidth>
    static void prefetch([[maybe_unused]] const Tree& bvh,
                         [[maybe_unused]] const WideBvhNodes<kWidth>& nodes,
                         [[maybe_unused]] std::uint32_t first,
                         [[maybe_unused]] std::uint32_t count) {
#if defined(__SSE2__)
        auto fetch = [](const void* address, std::size_t bytes) {
            const char* p = static_cast<const char*>(address);
            for (std::size_t line = 0; line < bytes; line += 64)
                _mm_prefetch(p + line, _MM_HINT_T0);
        };
        if (count == WideBvhNode<kWidth>::kInterior) {
            fetch(&nodes[first], sizeof(WideBvhNode<kWidth>));
        } else if (!bvh.blocks_.empty()) {
            fetch(&bvh.blocks_[first], sizeof(BvhTriangleBlock) + 32);
        } else if (count == 1) {
            if constexpr (requires { bvh.set_->corner(std::size_t{0}, 0); }) {
                const auto* corners = &bvh.set_->corner(first, 0);
                fetch(corners, 3 * sizeof(*corners));
            }
        } else {
            fetch(&bvh.indices_[first], sizeof(std::uint32_t));
        }
#endif
    }

    template <bool kCount, bool kSigned, class Leaf>
    static void traverse_binary(const Tree& bvh, const BoxRay& box_ray, double ray_t_max,
                                TraversalCounters& counters, Leaf& leaf) {
        const auto& nodes = bvh.binary_nodes_;
        if (nodes.empty()) return;
        float t_max = round_up(ray_t_max);
        float t_enter;
        if constexpr (kCount) ++counters.boxes_tested;
        if (!hit_box<kSigned>(nodes[0], box_ray, t_max, t_enter)) return;

        // Each level pushes at most the far child, so the depth bounds the stack.
        BinaryEntry stack[kMaxDepth + 1];
        int size = 0;
        std::uint32_t index = 0;
        for (;;) {
            const BvhNode& node = nodes[index];
            if constexpr (kCount) ++counters.nodes_visited;
            if (node.is_leaf()) {
                if (leaf(node.offset, node.count, t_max)) return;
            } else {
                if constexpr (kCount) counters.boxes_tested += 2;
                float t_left, t_right;
                const bool left = hit_box<kSigned>(nodes[node.offset], box_ray, t_max, t_left);
                const bool right =
                    hit_box<kSigned>(nodes[node.offset + 1], box_ray, t_max, t_right);
                if (left && right) {
                    const bool right_first = t_right < t_left;
                    stack[size++] = {node.offset + (right_first ? 0 : 1),
                                     right_first ? t_left : t_right};
                    index = node.offset + (right_first ? 1 : 0);
                    continue;
                }
                if (left || right) {
                    index = node.offset + (left ? 0 : 1);
                    continue;
                }
            }
            // Skip entries whose subtree starts beyond the nearest hit found since they were
            // pushed.
            do {
                if (size == 0) return;
                --size;
            } while (stack[size].t_enter > t_max);
            index = stack[size].node;
        }
    }

    template <bool kCount, bool kSigned, class NodeTest, int kWidth, class Leaf>
    static void traverse_wide(const Tree& bvh, const WideBvhNodes<kWidth>& nodes,
                              const BoxRay& box_ray, double ray_t_max, TraversalCounters& counters,
                              Leaf& leaf) {
        if (nodes.empty()) return;
        const NodeTest test(box_ray);
        walk_wide<kCount, kSigned>(bvh, nodes, test, round_up(ray_t_max), counters, leaf);
    }

    /// traverse_wide with its node test made: `test.hit<kSigned>(node, t_max, t_enter)` gives
    /// the mask of the children to enter (a single ray's, or a packet's conservative one).
    template <bool kCount, bool kSigned, class NodeTest, int kWidth, class Leaf>
    static void walk_wide(const Tree& bvh, const WideBvhNodes<kWidth>& nodes, const NodeTest& test,
                          float t_max, TraversalCounters& counters, Leaf& leaf) {
        using Node = WideBvhNode<kWidth>;

        // Each level pushes at most kWidth - 1 children.
        WideEntry stack[(kWidth - 1) * kMaxDepth + 1];
        WideEntry* top = stack;
        std::uint32_t first = 0, count = Node::kInterior;
        alignas(32) float t_enter[kWidth];
        for (;;) {
            // Descend through interior nodes, nearest child first, until a leaf or a dead end.
            while (count == Node::kInterior) {
                const Node& node = nodes[first];
                if constexpr (kCount) {
                    ++counters.nodes_visited;
                    counters.boxes_tested += kWidth;
                }
                unsigned mask = test.template hit<kSigned>(node, t_max, t_enter);
                if (mask == 0) break;
                const int nearest = std::countr_zero(mask);
                mask &= mask - 1;
                first = node.first[nearest];
                count = node.count[nearest];
                if (mask == 0) continue;
                if ((mask & (mask - 1)) == 0) {
                    // Two children (the common case): push the farther, take the nearer; at
                    // equal entries the later slot, as the ordering below would.
                    const int other = std::countr_zero(mask);
                    if (t_enter[other] <= t_enter[nearest]) {
                        *top++ = WideEntry{first, count, t_enter[nearest]};
                        first = node.first[other];
                        count = node.count[other];
                    } else {
                        *top++ = WideEntry{node.first[other], node.count[other], t_enter[other]};
                    }
                    prefetch(bvh, nodes, (top - 1)->first, (top - 1)->count);
                    continue;
                }
                // Three or more children: push them all, then order the pushed entries so that
                // the nearest is on top, and take it. Those left waiting are fetched while the
                // nearest one is traversed.
                WideEntry* pushed = top;
                *top++ = WideEntry{first, count, t_enter[nearest]};
                prefetch(bvh, nodes, first, count);
                do {
                    const int slot = std::countr_zero(mask);
                    mask &= mask - 1;
                    *top++ = WideEntry{node.first[slot], node.count[slot], t_enter[slot]};
                    prefetch(bvh, nodes, node.first[slot], node.count[slot]);
                } while (mask != 0);
                for (WideEntry* i = pushed + 1; i != top; ++i) {
                    const WideEntry entry = *i;
                    WideEntry* j = i;
                    for (; j != pushed && (j - 1)->t_enter < entry.t_enter; --j) *j = *(j - 1);
                    *j = entry;
                }
                --top;
                first = top->first;
                count = top->count;
            }
            // An unused slot (count 0) is entered only by rays the float test cannot
            // represent, which enter every box.
            if (count != Node::kInterior && count != 0) {
                if constexpr (kCount) ++counters.nodes_visited;
                if (leaf(first, count, t_max)) return;
            }
            // Skip entries whose subtree starts beyond the nearest hit found since they were
            // pushed.
            do {
                if (top == stack) return;
                --top;
            } while (top->t_enter > t_max);
            first = top->first;
            count = top->count;
        }
    }

    /// A ray as the leaves test it: the set's prepared ray and, for block leaves, its SIMD
    /// forms, made once per query; kWide adds the 8-lane form of the AVX2 query.
    struct NoBlockRay {
        template <class Any>
        explicit NoBlockRay(const Any&) {}
    };
    using LeafBlockRay = std::conditional_t<kBlockSet, BlockRay, NoBlockRay>;
#if CSGRT_BVH_AVX2
    using WideBlockRay = std::conditional_t<kBlockSet, Avx2BlockRay, NoBlockRay>;
#else
    using WideBlockRay = NoBlockRay;
#endif
    template <bool kWide>
    struct LeafRayOf {
        static constexpr bool kPairs = kWide && kBlockSet && CSGRT_BVH_AVX2;
        typename Set::PreparedRay prepared;
        LeafBlockRay block;
        [[no_unique_address]] std::conditional_t<kWide, WideBlockRay, NoBlockRay> wide;

        LeafRayOf(const Set& set, const Ray& ray, QueryScratch& scratch)
            : prepared(set.prepare(ray, scratch)), block(prepared), wide(block) {}
    };
    using LeafRay = LeafRayOf<false>;

    /// A triangle of a block that the set's test reports as hit on the ray's line, at t with
    /// the barycentrics b1, b2 of corners 1 and 2.
    struct BlockCandidate {
        std::uint32_t index;
        double t, b1, b2;
        const typename Set::PreparedRay& ray;

        bool keep_nearest(HitRecord& record) const {
            return Set::keep_nearest(index, t, b1, b2, ray, record);
        }
        bool occludes() const { return t >= ray.t_min && t <= ray.t_max; }
    };
    /// A primitive of an index leaf, not yet tested: the set's own queries test it.
    struct PrimitiveCandidate {
        const Set& set;
        std::uint32_t index;
        const typename Set::PreparedRay& ray;

        bool keep_nearest(HitRecord& record) const { return set.intersect(index, ray, record); }
        bool occludes() const { return set.occluded(index, ray); }
    };

    /// Calls visit(candidate) for each primitive of the leaf (first, count) that may be hit,
    /// until it returns true; returns whether it did. A candidate answers keep_nearest(record)
    /// (the set's intersect: the hit in [t_min, record.t] that beats record under the tie
    /// rule) and occludes() (the set's occluded). Block leaves test four triangles at once and
    /// hand on only those hit on the ray's line; index leaves hand on every primitive.
    template <bool kCount, bool kWide, class Visit>
    static bool for_each_hit(const Tree& bvh, const LeafRayOf<kWide>& ray, std::uint32_t first,
                             std::uint32_t count, TraversalCounters& counters, Visit&& visit) {
        if constexpr (kBlockSet) {
            if (!bvh.blocks_.empty()) {
                // The candidate lanes of one block, finished by BlockHits (or by the set's
                // test where an edge function is zero) and handed to visit.
                auto visit_block = [&](const BvhTriangleBlock& block, const ShearedBlock& sheared,
                                       unsigned candidates, unsigned zeros) {
                    const BlockHits hits(sheared, ray.prepared.shear_z);
                    do {
                        const int lane = std::countr_zero(candidates);
                        candidates &= candidates - 1;
                        double t = hits.t[lane], b1 = hits.b1[lane], b2 = hits.b2[lane];
                        if ((zeros >> lane & 1u) != 0 &&
                            !TriangleSet<float>::hit_sheared(sheared.lane(lane),
                                                             ray.prepared.shear_z, t, b1, b2)) {
                            continue;
                        }
                        if (visit(BlockCandidate{block.primitive[lane], t, b1, b2, ray.prepared}))
                            return true;
                    } while (candidates != 0);
                    return false;
                };
                const BvhTriangleBlock* block = bvh.blocks_.data() + first;
                std::uint32_t left = count;
                if constexpr (LeafRayOf<kWide>::kPairs) {
                    for (; left > kBlockLanes; block += 2) {
                        const std::uint32_t lanes = std::min(left, 2 * kBlockLanes);
                        left -= lanes;
                        if constexpr (kCount) counters.primitives_tested += lanes;
                        ShearedBlock sheared[2];
                        unsigned zeros;
                        const unsigned candidates =
                            ray.wide.candidates(block[0], block[1], sheared, zeros) &
                            ((1u << lanes) - 1u);
                        if ((candidates & 0xfu) != 0 &&
                            visit_block(block[0], sheared[0], candidates & 0xfu, zeros & 0xfu)) {
                            return true;
                        }
                        if ((candidates >> 4) != 0 &&
                            visit_block(block[1], sheared[1], candidates >> 4, zeros >> 4)) {
                            return true;
                        }
                    }
                }
                for (; left != 0; ++block) {
                    const std::uint32_t lanes = std::min(left, kBlockLanes);
                    left -= lanes;
                    if constexpr (kCount) counters.primitives_tested += lanes;
                    ShearedBlock sheared;
                    unsigned zeros;
                    const unsigned candidates =
                        ray.block.candidates(*block, sheared, zeros) & ((1u << lanes) - 1u);
                    if (candidates != 0 && visit_block(*block, sheared, candidates, zeros))
                        return true;
                }
                return false;
            }
        }
        const Set& set = *bvh.set_;
        if (count == 1) {
            if constexpr (kCount) ++counters.primitives_tested;
            return visit(PrimitiveCandidate{set, first, ray.prepared});
        }
        const std::uint32_t* indices = bvh.indices_.data() + first;
        for (std::uint32_t i = 0; i != count; ++i) {
            if constexpr (kCount) ++counters.primitives_tested;
            if (visit(PrimitiveCandidate{set, indices[i], ray.prepared})) return true;
        }
        return false;
    }

    /// The nearest-hit leaf test: keeps the leaf's best hit in `best` and lowers t_max to it.
    template <bool kCount, bool kWide>
    static bool nearest_in_leaf(const Tree& bvh, const LeafRayOf<kWide>& ray, std::uint32_t first,
                                std::uint32_t count, HitRecord& best, float& t_max,
                                TraversalCounters& counters) {
        bool hit = false;
        for_each_hit<kCount>(bvh, ray, first, count, counters, [&](const auto& candidate) {
            hit |= candidate.keep_nearest(best);
            return false;
        });
        if (hit) t_max = round_up(best.t);
        return hit;
    }

    /// The occlusion leaf test: whether any primitive of the leaf is hit in [t_min, t_max].
    template <bool kCount, bool kWide>
    static bool occluded_in_leaf(const Tree& bvh, const LeafRayOf<kWide>& ray, std::uint32_t first,
                                 std::uint32_t count, TraversalCounters& counters) {
        return for_each_hit<kCount>(bvh, ray, first, count, counters,
                                    [](const auto& candidate) { return candidate.occludes(); });
    }

    template <bool kCount, bool kAvx2>
    static bool intersect(const Tree& bvh, const Ray& ray, HitRecord& record, QueryScratch& scratch,
                          TraversalCounters& counters) {
        if (bvh.set_ == nullptr) return false;
        const BoxRay box_ray(ray);
        if (!box_ray.valid) return false;
        // The leaf ray is made at the first leaf: most camera rays reach none (they miss the
        // mesh's boxes), and for them the set's prepare and the block ray are pure cost.
        // Raw storage rather than std::optional: LeafRay is trivially destructible, so nothing
        // is left to check or destroy on the way out.
        using LeafRay = LeafRayOf<kAvx2>;
        static_assert(std::is_trivially_destructible_v<LeafRay>);
        alignas(LeafRay) unsigned char leaf_ray_storage[sizeof(LeafRay)];
        const LeafRay* leaf_ray = nullptr;
        HitRecord best;
        best.t = ray.t_max;
        bool found = false;
        auto leaf = [&](std::uint32_t first, std::uint32_t count, float& t_max) {
            if (leaf_ray == nullptr) [[unlikely]]
                leaf_ray = new (leaf_ray_storage) LeafRay(*bvh.set_, ray, scratch);
            found |= nearest_in_leaf<kCount>(bvh, *leaf_ray, first, count, best, t_max, counters);
            return false;
        };
        traverse<kCount, kAvx2>(bvh, ray, box_ray, counters, leaf);
        if (found) record = best;
        return found;
    }

    template <bool kCount, bool kAvx2>
    static bool occluded(const Tree& bvh, const Ray& ray, QueryScratch& scratch,
                         TraversalCounters& counters) {
        if (bvh.set_ == nullptr) return false;
        const BoxRay box_ray(ray);
        if (!box_ray.valid) return false;
        // Made up front, unlike intersect's: shadow rays start on a surface and nearly all
        // reach a leaf, and the deferred form cost them 58 instructions a ray (callgrind).
        const LeafRayOf<kAvx2> leaf_ray(*bvh.set_, ray, scratch);
        bool occluded = false;
        auto leaf = [&](std::uint32_t first, std::uint32_t count, float&) {
            return occluded = occluded_in_leaf<kCount>(bvh, leaf_ray, first, count, counters);
        };
        traverse<kCount, kAvx2>(bvh, ray, box_ray, counters, leaf);
        return occluded;
    }

    template <bool kAvx2>
    static void all_hits(const Tree& bvh, const Ray& ray, std::vector<HitRecord>& hits,
                         QueryScratch& scratch) {
        if (bvh.set_ == nullptr) return;
        const BoxRay box_ray(ray);
        if (!box_ray.valid) return;
        const LeafRayOf<kAvx2> leaf_ray(*bvh.set_, ray, scratch);
        TraversalCounters unused;
        auto leaf = [&](std::uint32_t first, std::uint32_t count, float&) {
            return for_each_hit<false>(bvh, leaf_ray, first, count, unused,
                                       [&](const auto& candidate) {
                                           HitRecord record;
                                           record.t = ray.t_max;
                                           if (candidate.keep_nearest(record))
                                               hits.push_back(record);
                                           return false;
                                       });
        };
        traverse<false, kAvx2>(bvh, ray, box_ray, unused, leaf);
    }

#if CSGRT_BVH_AVX2
    template <class NodeTest>
    static constexpr bool kAvx2Test = std::is_same_v<NodeTest, Avx2NodeTest>;
#else
    template <class NodeTest>
    static constexpr bool kAvx2Test = false;
#endif

    /// The rays of a packet: each one's box ray and float upper bound, and, made when first
    /// needed, its node test (the ray-by-ray walk only) and its leaf ray (at its first leaf:
    /// most camera rays reach none).
    template <class NodeTest>
    struct PacketLanes {
        using LeafRayType = LeafRayOf<kAvx2Test<NodeTest>>;
        struct Lane {
            BoxRay box;
            float t_max;
        };
        static_assert(std::is_trivially_destructible_v<Lane> &&
                      std::is_trivially_destructible_v<NodeTest> &&
                      std::is_trivially_destructible_v<LeafRayType>);
        alignas(Lane) unsigned char lane_storage[sizeof(Lane) * Tree::kPacketRays];
        alignas(NodeTest) unsigned char test_storage[sizeof(NodeTest) * Tree::kPacketRays];
        alignas(LeafRayType) unsigned char leaf_storage[sizeof(LeafRayType) * Tree::kPacketRays];
        std::uint32_t leaf_made = 0;

        Lane& operator[](int r) { return reinterpret_cast<Lane*>(lane_storage)[r]; }
        const Lane& operator[](int r) const {
            return reinterpret_cast<const Lane*>(lane_storage)[r];
        }
        void make(int r, const Ray& ray) {
            new (&(*this)[r]) Lane{BoxRay(ray), round_up(ray.t_max)};
        }
        NodeTest& test(int r) { return reinterpret_cast<NodeTest*>(test_storage)[r]; }
        void make_test(int r) { new (&test(r)) NodeTest((*this)[r].box); }
        const LeafRayType& leaf(int r, const Set& set, const Ray& ray, QueryScratch& scratch) {
            LeafRayType* leaves = reinterpret_cast<LeafRayType*>(leaf_storage);
            if ((leaf_made >> r & 1u) == 0) {
                new (&leaves[r]) LeafRayType(set, ray, scratch);
                leaf_made |= 1u << r;
            }
            return leaves[r];
        }
    };
    struct PacketEntry {
        std::uint32_t first;
        std::uint32_t count;
        /// The rays that entered the child (bit r for ray r) and the least of their entries.
        std::uint32_t rays;
        float t_enter;
    };

    /// Traverses the wide tree once for up to kPacketRays rays: every node is tested against
    /// each ray that entered it, exactly as the single-ray traversal tests it (same node test,
    /// same t_max), and a ray enters a child only when its own test says so; a leaf is tested
    /// for each ray that entered it. A ray thus tests every primitive its single-ray traversal
    /// may need (the culling is the single-ray culling, only its order differs), and the tie
    /// rule of the set makes the nearest hit independent of the order: the answers are the
    /// single-ray answers bit for bit. Children are visited nearest first by the least entry
    /// of the rays that entered them. kAny: occlusion (occluded[r]); else nearest hits (best[r],
    /// found[r]). Invalid rays are left out.
    template <bool kAny, class NodeTest, int kWidth>
    static void traverse_packet(const Tree& bvh, const WideBvhNodes<kWidth>& nodes,
                                std::span<const Ray> rays, HitRecord* best, bool* found,
                                QueryScratch& scratch) {
        using Node = WideBvhNode<kWidth>;
        const int n = static_cast<int>(rays.size());
        for (int r = 0; r < n; ++r) found[r] = false;
        if (nodes.empty()) return;
        PacketLanes<NodeTest> lanes;
        std::uint32_t open = 0;
        for (int r = 0; r < n; ++r) {
            lanes.make(r, rays[r]);
            if (!lanes[r].box.valid) continue;
            best[r] = HitRecord{};
            best[r].t = rays[r].t_max;
            open |= 1u << r;
        }
        if (open == 0) return;
#if CSGRT_BVH_AVX2
        if constexpr (kAvx2Test<NodeTest>) {
            PacketIntervalTest interval;
            if (interval.accepts(lanes, open)) {
                return walk_interval_packet<kAny>(bvh, rays, lanes, open, interval, best, found,
                                                  scratch);
            }
            // Rays without a common origin (shadow rays from a surface, incoherent rays): the
            // packet's interval would hold the region between their origins, where each of
            // them tests every leaf near any of them; one at a time is faster.
            TraversalCounters unused;
            for (std::uint32_t m = open; m != 0; m &= m - 1) {
                const int r = std::countr_zero(m);
                if constexpr (kAny) {
                    found[r] = occluded<false, true>(bvh, rays[r], scratch, unused);
                } else {
                    found[r] = intersect<false, true>(bvh, rays[r], best[r], scratch, unused);
                }
            }
            return;
        }
#endif
        for (std::uint32_t m = open; m != 0; m &= m - 1) lanes.make_test(std::countr_zero(m));
        TraversalCounters unused;

        PacketEntry stack[(kWidth - 1) * kMaxDepth + 1];
        PacketEntry* top = stack;
        std::uint32_t first = 0, count = Node::kInterior, active = open;
        for (;;) {
            while (count == Node::kInterior && active != 0) {
                const Node& node = nodes[first];
                std::uint32_t child_rays[kWidth] = {};
                float child_enter[kWidth];
                std::fill_n(child_enter, kWidth, kFloatInfinity);
                unsigned entered = 0;
                for (std::uint32_t m = active; m != 0; m &= m - 1) {
                    const int r = std::countr_zero(m);
                    const auto& lane = lanes[r];
                    const NodeTest& test = lanes.test(r);
                    alignas(32) float t_enter[kWidth];
                    const unsigned mask = lane.box.signed_interval
                                              ? test.template hit<true>(node, lane.t_max, t_enter)
                                              : test.template hit<false>(node, lane.t_max, t_enter);
                    for (unsigned c = mask; c != 0; c &= c - 1) {
                        const int slot = std::countr_zero(c);
                        child_enter[slot] = std::min(child_enter[slot], t_enter[slot]);
                        child_rays[slot] |= 1u << r;
                    }
                    entered |= mask;
                }
                if (entered == 0) break;
                PacketEntry* pushed = top;
                for (unsigned c = entered; c != 0; c &= c - 1) {
                    const int slot = std::countr_zero(c);
                    *top++ = PacketEntry{node.first[slot], node.count[slot], child_rays[slot],
                                         child_enter[slot]};
                    prefetch(bvh, nodes, node.first[slot], node.count[slot]);
                }
                for (PacketEntry* i = pushed + 1; i != top; ++i) {
                    const PacketEntry entry = *i;
                    PacketEntry* j = i;
                    for (; j != pushed && (j - 1)->t_enter < entry.t_enter; --j) *j = *(j - 1);
                    *j = entry;
                }
                --top;
                first = top->first;
                count = top->count;
                active = top->rays;
            }
            if (count != Node::kInterior && count != 0) {
                for (std::uint32_t m = active; m != 0; m &= m - 1) {
                    const int r = std::countr_zero(m);
                    auto& lane = lanes[r];
                    const auto& leaf_ray = lanes.leaf(r, *bvh.set_, rays[r], scratch);
                    if constexpr (kAny) {
                        if (occluded_in_leaf<false>(bvh, leaf_ray, first, count, unused)) {
                            found[r] = true;
                            open &= ~(1u << r);
                        }
                    } else {
                        found[r] |= nearest_in_leaf<false>(bvh, leaf_ray, first, count, best[r],
                                                           lane.t_max, unused);
                    }
                }
                if (open == 0) return;
            }
            // Each entry keeps the rays still open whose own entry may lie within their t_max
            // (their least entry does not exceed it).
            do {
                if (top == stack) return;
                --top;
                active = top->rays & open;
                for (std::uint32_t m = active; m != 0; m &= m - 1) {
                    const int r = std::countr_zero(m);
                    if (top->t_enter > lanes[r].t_max) active &= ~(1u << r);
                }
            } while (active == 0);
            first = top->first;
            count = top->count;
        }
    }

#if CSGRT_BVH_AVX2
    /// traverse_packet with the AVX2 node test, everything inlined and compiled for AVX2.
    template <bool kAny>
    [[gnu::target("avx2"), gnu::flatten]] static void traverse_packet_avx2(
        const Tree& bvh, std::span<const Ray> rays, HitRecord* best, bool* found,
        QueryScratch& scratch) {
        traverse_packet<kAny, Avx2NodeTest>(bvh, bvh.nodes_8_, rays, best, found, scratch);
    }
#endif

#if CSGRT_BVH_AVX2
    /// The nearest hits (or occlusion) of a packet whose rays PacketIntervalTest accepts: the
    /// tree is walked once with the packet's conservative node test, as one ray would walk it,
    /// and every leaf it reaches is tested for each open ray with that ray's own leaf test and
    /// t_max. The upper bound of the walk is the largest t_max of the open rays.
    template <bool kAny>
    [[gnu::target("avx2")]] static void walk_interval_packet(
        const Tree& bvh, std::span<const Ray> rays, PacketLanes<Avx2NodeTest>& lanes,
        std::uint32_t open, const PacketIntervalTest& test, HitRecord* best, bool* found,
        QueryScratch& scratch) {
        TraversalCounters unused;
        auto largest_t_max = [&] {
            float t_max = -kFloatInfinity;
            for (std::uint32_t m = open; m != 0; m &= m - 1)
                t_max = std::max(t_max, lanes[std::countr_zero(m)].t_max);
            return t_max;
        };
        if constexpr (kBlockSet) {
            if (!bvh.blocks_.empty()) {
                // Ray-parallel leaves, when the rays share the triangle test's axes.
                typename Set::PreparedRay prepared[Tree::kPacketRays];
                for (std::uint32_t m = open; m != 0; m &= m - 1) {
                    const int r = std::countr_zero(m);
                    prepared[r] = bvh.set_->prepare(rays[r], scratch);
                }
                PacketTriangleRays triangle_rays;
                if (triangle_rays.accepts(prepared, open)) {
                    auto leaf = [&](std::uint32_t first, std::uint32_t count, float& t_max) {
                        const BvhTriangleBlock* block = bvh.blocks_.data() + first;
                        for (std::uint32_t left = count; left != 0; ++block) {
                            const std::uint32_t block_lanes = std::min(left, kBlockLanes);
                            left -= block_lanes;
                            for (std::uint32_t lane = 0; lane < block_lanes; ++lane) {
                                alignas(32) float sheared[9][8];
                                unsigned candidates = triangle_rays.candidates(
                                    *block, static_cast<int>(lane), open, sheared);
                                while (candidates != 0) {
                                    const int r = std::countr_zero(candidates);
                                    candidates &= candidates - 1;
                                    TriangleSet<float>::ShearedTriangle triangle;
                                    for (int k = 0; k < 3; ++k) {
                                        triangle.x[k] = sheared[k][r];
                                        triangle.y[k] = sheared[3 + k][r];
                                        triangle.z[k] = sheared[6 + k][r];
                                    }
                                    double t, b1, b2;
                                    if (!TriangleSet<float>::hit_sheared(
                                            triangle, prepared[r].shear_z, t, b1, b2)) {
                                        continue;
                                    }
                                    if constexpr (kAny) {
                                        if (t >= prepared[r].t_min && t <= prepared[r].t_max) {
                                            found[r] = true;
                                            open &= ~(1u << r);
                                        }
                                    } else if (Set::keep_nearest(block->primitive[lane], t, b1, b2,
                                                                 prepared[r], best[r])) {
                                        found[r] = true;
                                        lanes[r].t_max = round_up(best[r].t);
                                    }
                                }
                                if (open == 0) return true;
                            }
                        }
                        t_max = largest_t_max();
                        return false;
                    };
                    walk_wide<false, false>(bvh, bvh.nodes_8_, test, largest_t_max(), unused, leaf);
                    return;
                }
            }
        }
        auto leaf = [&](std::uint32_t first, std::uint32_t count, float& t_max) {
            for (std::uint32_t m = open; m != 0; m &= m - 1) {
                const int r = std::countr_zero(m);
                const auto& leaf_ray = lanes.leaf(r, *bvh.set_, rays[r], scratch);
                if constexpr (kAny) {
                    if (occluded_in_leaf<false>(bvh, leaf_ray, first, count, unused)) {
                        found[r] = true;
                        open &= ~(1u << r);
                    }
                } else {
                    found[r] |= nearest_in_leaf<false>(bvh, leaf_ray, first, count, best[r],
                                                       lanes[r].t_max, unused);
                }
            }
            t_max = largest_t_max();
            return open == 0;
        };
        walk_wide<false, false>(bvh, bvh.nodes_8_, test, largest_t_max(), unused, leaf);
    }
#endif

    /// Up to kPacketRays rays through the wide tree (width 4 or 8).
    template <bool kAny>
    static void packet(const Tree& bvh, std::span<const Ray> rays, HitRecord* best, bool* found,
                       QueryScratch& scratch) {
        if (bvh.config_.width == 8) {
#if CSGRT_BVH_AVX2
            if (bvh.use_avx2_) return traverse_packet_avx2<kAny>(bvh, rays, best, found, scratch);
#endif
            return traverse_packet<kAny, SseNodeTest<8>>(bvh, bvh.nodes_8_, rays, best, found,
                                                         scratch);
        }
        traverse_packet<kAny, SseNodeTest<4>>(bvh, bvh.nodes_4_, rays, best, found, scratch);
    }
};

}  // namespace detail

template <class Set>
void Bvh<Set>::build(const Set& set, const BvhConfig& config) {
    require(config.bins >= 2 && config.bins <= 256, "Bvh", "bins", "in [2, 256]", config.bins);
    require(config.max_leaf_size >= 1, "Bvh", "max_leaf_size", ">= 1", config.max_leaf_size);
    require_positive(config.traversal_cost, "Bvh", "traversal_cost");
    require_positive(config.intersection_cost, "Bvh", "intersection_cost");
    require(config.width == 2 || config.width == 4 || config.width == 8, "Bvh", "width",
            "2, 4 or 8", config.width);
    // Node indices (up to twice the primitive count) and leaf counts are 32-bit.
    require(set.size() < (std::size_t{1} << 31), "Bvh", "primitive count", "< 2^31", set.size());
    const auto start = std::chrono::steady_clock::now();
    set_ = &set;
    config_ = config;
    constexpr bool kBlockSet = detail::BvhTraversal<Set>::kBlockSet;
    const bool blocks = kBlockSet && config.triangle_blocks;
    use_avx2_ = false;
#if CSGRT_BVH_AVX2
    use_avx2_ = config.width == 8 && config.avx2 && __builtin_cpu_supports("avx2");
#endif

    // Left uninitialised here (AlignedAllocator default-initialises) and written in parallel
    // below, so that the tasks also take the page faults of the 32 bytes a primitive.
    std::vector<detail::BuildPrimitive, AlignedAllocator<detail::BuildPrimitive>> primitives(
        set.size());
    auto prepare_range = [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            detail::BuildPrimitive& primitive = primitives[i];
            if constexpr (kBlockSet) {
                pad_triangle(set.corner(i, 0), set.corner(i, 1), set.corner(i, 2), primitive);
            } else {
                pad_box(set.bounds(i), primitive);
            }
            primitive.index = static_cast<std::uint32_t>(i);
            primitive.unused = 0.0f;
        }
    };
    const tbb::blocked_range<std::size_t> all(0, set.size(), 4096);
    if (config.parallel) {
        tbb::parallel_for(all, prepare_range);
    } else {
        prepare_range(all);
    }

    detail::BinaryBvh tree =
        detail::build_binary_bvh(primitives, config, blocks ? int(kBlockLanes) : 1);
    primitives = {};

    // Leaves name their contents: blocks of four triangles copied in leaf order, or entries
    // of the index array (a one-primitive leaf names its primitive itself). Leaves cover the
    // index array in order, so blocks are handed out in that order too.
    indices_.clear();
    blocks_.clear();
    if constexpr (kBlockSet) {
        if (blocks) fill_blocks(set, tree, config.parallel);
    }
    if (!blocks) {
        for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
            BvhNode& node = tree.nodes[i];
            if (i != 1 && node.count == 1) node.offset = tree.indices[node.offset];
        }
        indices_ = std::move(tree.indices);
    }

    nodes_4_.clear();
    nodes_8_.clear();
    binary_nodes_.clear();
    if (config.width == 4) {
        nodes_4_ = detail::collapse_to_wide<4>(tree, config.parallel);
    } else if (config.width == 8) {
        nodes_8_ = detail::collapse_to_wide<8>(tree, config.parallel);
    } else {
        binary_nodes_ = std::move(tree.nodes);
        binary_nodes_.shrink_to_fit();
    }

    stats_ = AcceleratorStats{};
    stats_.name = "bvh";
    // The wide nodes are counted by size: collapse_to_wide reserves more address space than it
    // uses, and the pages it never writes are never mapped.
    stats_.bytes = binary_nodes_.capacity() * sizeof(BvhNode) + nodes_4_.size() * sizeof(Bvh4Node) +
                   nodes_8_.size() * sizeof(Bvh8Node) +
                   indices_.capacity() * sizeof(std::uint32_t) +
                   blocks_.capacity() * sizeof(BvhTriangleBlock);
    stats_.nodes = nodes_4_.size() + nodes_8_.size() + binary_nodes_.size();
    stats_.primitives = stats_.references = set.size();
    char details[240];
    std::snprintf(details, sizeof details,
                  "width %d, depth %d, %zu leaves (%.2f primitives each), %zu blocks, SAH cost "
                  "%.2f, %d bins, %.1f bytes per primitive%s",
                  config.width, tree.depth, tree.leaves,
                  tree.leaves ? double(set.size()) / double(tree.leaves) : 0.0, blocks_.size(),
                  tree.sah_cost, config.bins,
                  set.size() ? double(stats_.bytes) / double(set.size()) : 0.0,
                  use_avx2_ ? ", AVX2" : "");
    stats_.details = details;
    stats_.build_milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

template <class Set>
void Bvh<Set>::fill_blocks(const Set& set, detail::BinaryBvh& tree, bool parallel) {
    if (tree.nodes.empty()) return;
    // The leaves in index order: depth first, left child first.
    std::vector<std::uint32_t> leaves, pending{0};
    leaves.reserve(tree.leaves);
    while (!pending.empty()) {
        const std::uint32_t index = pending.back();
        pending.pop_back();
        const BvhNode& node = tree.nodes[index];
        if (node.is_leaf()) {
            leaves.push_back(index);
        } else {
            pending.push_back(node.offset + 1);
            pending.push_back(node.offset);
        }
    }
    std::vector<std::uint32_t> first_block(leaves.size() + 1, 0);
    for (std::size_t k = 0; k < leaves.size(); ++k) {
        first_block[k + 1] =
            first_block[k] + (tree.nodes[leaves[k]].count + kBlockLanes - 1) / kBlockLanes;
    }
    // Every lane of every block is written below: lanes past a leaf's count get zeros and
    // kNoIndex. The storage is left uninitialised until then.
    blocks_.resize(first_block.back());
    auto fill = [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
            BvhNode& node = tree.nodes[leaves[k]];
            for (std::uint32_t slot = 0;
                 slot != (first_block[k + 1] - first_block[k]) * kBlockLanes; ++slot) {
                BvhTriangleBlock& block = blocks_[first_block[k] + slot / kBlockLanes];
                const std::uint32_t lane = slot % kBlockLanes;
                const bool used = slot < node.count;
                const std::uint32_t primitive = used ? tree.indices[node.offset + slot] : kNoIndex;
                block.primitive[lane] = primitive;
                if constexpr (detail::BvhTraversal<Set>::kBlockSet) {
                    for (int corner = 0; corner < 3; ++corner) {
                        for (int axis = 0; axis < 3; ++axis) {
                            block.corners[corner][axis][lane] =
                                used ? set.corner(primitive, corner)[axis] : 0.0f;
                        }
                    }
                }
            }
            node.offset = first_block[k];
        }
    };
    const tbb::blocked_range<std::size_t> all(0, leaves.size(), 1024);
    if (parallel) {
        tbb::parallel_for(all, fill);
    } else {
        fill(all);
    }
    tree.indices = {};
}

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

template <class Set>
template <bool kAny>
std::size_t Bvh<Set>::trace_packets(std::span<const Ray> rays, std::span<HitRecord> records,
                                    std::span<bool> hit, QueryScratch& scratch) const {
    std::size_t hits = 0;
    // Instance paths of a ShapeSet's hits live in the scratch of one query at a time, and the
    // binary tree has no packet traversal: those go one ray at a time.
    if (std::is_same_v<Set, ShapeSet> || config_.width == 2 || set_ == nullptr) {
        for (std::size_t i = 0; i < rays.size(); ++i) {
            if constexpr (kAny) {
                hit[i] = this->occluded(rays[i], scratch);
            } else {
                hit[i] = this->intersect(rays[i], records[i], scratch);
            }
            hits += hit[i] ? 1 : 0;
        }
        return hits;
    }
    if constexpr (!std::is_same_v<Set, ShapeSet>) {
        HitRecord best[kPacketRays];
        bool found[kPacketRays];
        for (std::size_t begin = 0; begin < rays.size(); begin += kPacketRays) {
            const std::size_t n = std::min(kPacketRays, rays.size() - begin);
            detail::BvhTraversal<Set>::template packet<kAny>(*this, rays.subspan(begin, n), best,
                                                             found, scratch);
            for (std::size_t r = 0; r < n; ++r) {
                hit[begin + r] = found[r];
                if constexpr (!kAny) {
                    if (found[r]) records[begin + r] = best[r];
                }
                hits += found[r] ? 1 : 0;
            }
        }
    }
    return hits;
}

template <class Set>
std::size_t Bvh<Set>::intersect_packets(std::span<const Ray> rays, std::span<HitRecord> records,
                                        std::span<bool> hit, QueryScratch& scratch) const {
    require(records.size() == rays.size(), "Bvh::intersect_packets", "records.size()",
            "rays.size()", records.size());
    require(hit.size() == rays.size(), "Bvh::intersect_packets", "hit.size()", "rays.size()",
            hit.size());
    return trace_packets<false>(rays, records, hit, scratch);
}

template <class Set>
std::size_t Bvh<Set>::occluded_packets(std::span<const Ray> rays, std::span<bool> occluded,
                                       QueryScratch& scratch) const {
    require(occluded.size() == rays.size(), "Bvh::occluded_packets", "occluded.size()",
            "rays.size()", occluded.size());
    return trace_packets<true>(rays, {}, occluded, scratch);
}

template class Bvh<TriangleSet<float>>;
template class Bvh<TriangleSet<double>>;
template class Bvh<ShapeSet>;
template class AcceleratorBase<Bvh<TriangleSet<float>>, TriangleSet<float>>;
template class AcceleratorBase<Bvh<TriangleSet<double>>, TriangleSet<double>>;
template class AcceleratorBase<Bvh<ShapeSet>, ShapeSet>;

}  // namespace csgrt
