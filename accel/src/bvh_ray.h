#pragma once

// The BVH's ray against boxes: the ray as the float slab tests see it (BoxRay) and the node
// tests of one ray (binary, 4 and 8 wide, SSE and AVX2) and of a packet with one origin.
// Private to accel/src/bvh*.

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "bvh_simd.h"
#include "csgrt/accel/bvh.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/ray.h"

// The AVX2 node test is compiled for x86-64 with GCC or Clang only, as functions with their own
// target attribute: the library itself stays baseline x86-64, and build() picks the AVX2 code
// only on a CPU that has it.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define CSGRT_BVH_AVX2 1
/// The target of every AVX2 function of the BVH: AVX2 and FMA, and the bit instructions every
/// AVX2 CPU also has (BMI1/2 and POPCNT: the walk's child masks take tzcnt and blsr rather
/// than bsf with a zero test), which build() checks the CPU for with the others.
#define CSGRT_BVH_AVX2_TARGET "avx2,fma,bmi,bmi2,popcnt"
/// There is no second compilation of the AVX2 code with AVX-512 allowed: it was made until
/// 2026-12-07 and measured no faster (docs/benchmarks.md, "AVX-512 compilation"), while it doubled
/// the compile time of the two sources that hold the queries.
#include <immintrin.h>
#else
#define CSGRT_BVH_AVX2 0
#endif

namespace csgrt::detail {

inline constexpr float kFloatInfinity = std::numeric_limits<float>::infinity();
inline constexpr double kFloatMax = std::numeric_limits<float>::max();
/// Beyond this a coordinate or reciprocal direction component is not trusted to the float
/// slab test (products could overflow or underflow to denormals).
inline constexpr double kLargestBoxRayValue = 0x1p100;
inline constexpr float kSlack = Bvh<TriangleSet<float>>::kSlabSlack;
/// Lanes of a leaf's lane group (BvhLeafTriangles): the SSE leaf test's width.
inline constexpr std::uint32_t kBlockLanes = kBvhLeafLaneGroup;

/// std::nextafter(f, up ? +inf : -inf) for a finite f, from its bits (no library call: the
/// nearest-hit query rounds every hit's t up).
inline float next_float(float f, bool up) {
    const std::uint32_t bits = std::bit_cast<std::uint32_t>(f);
    if (f == 0.0f) {
        const float smallest = std::numeric_limits<float>::denorm_min();
        return up ? smallest : -smallest;
    }
    // Away from zero the magnitude grows by one ulp, toward zero it shrinks by one.
    return std::bit_cast<float>((f > 0.0f) == up ? bits + 1u : bits - 1u);
}

/// The largest float <= x (x not NaN).
inline float round_down(double x) {
    if (x > kFloatMax) return static_cast<float>(kFloatMax);
    if (x < -kFloatMax) return -kFloatInfinity;
    float f = static_cast<float>(x);
    if (double(f) > x) f = next_float(f, false);
    return f;
}

/// The smallest float >= x (x not NaN).
inline float round_up(double x) {
    if (x > kFloatMax) return kFloatInfinity;
    if (x < -kFloatMax) return -static_cast<float>(kFloatMax);
    float f = static_cast<float>(x);
    if (double(f) < x) f = next_float(f, true);
    return f;
}

#if CSGRT_BVH_AVX2
/// (*low, *high) read as two 8-byte loads, which the compiler would otherwise merge into one
/// 16-byte load when they are adjacent. The single-ray query reads its ray this way because
/// the caller has often just written it with 8-byte stores (a Ray built from the caller's
/// arrays, as a user's loop and the batch queries build it), and one load across two pending
/// stores cannot take its value from the store buffer: it waits until they reach the cache.
/// Incoherent rays built just before the query lost 8-9% of their rate to that wait
/// (docs/benchmarks.md, "Rays written just before the query").
inline __m128d load_two(const double* low, const double* high) {
    // The compiler cannot see through this empty step where `high` points, so it keeps the
    // loads apart (an opaque step on the vector itself costs a register move in an encoding
    // Debian 12's valgrind cannot decode).
    asm("" : "+r"(high));
    return _mm_loadh_pd(_mm_load_sd(low), high);
}
#endif

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
        // (o2, 0) as o2's float beside a zero float rather than (o2, 0.0) converted: GCC makes
        // the latter a vmovq between registers, which Debian 12's valgrind cannot decode.
        const __m128 origin4 =
            _mm_movelh_ps(_mm_cvtpd_ps(v0), _mm_move_ss(_mm_setzero_ps(), _mm_cvtpd_ps(v1)));
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
    /// Few enough values to live in registers while descending (BvhTraversal::walk_wide).
    static constexpr bool kCopyForDescent = true;
    /// Whether the walk runs in AVX2 code and may use it for its own steps (walk_wide).
    static constexpr bool kAvx2 = false;
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
    static constexpr bool kCopyForDescent = true;
    static constexpr bool kAvx2 = true;
    __m256 origin[3], inverse_near[3], inverse_far[3], t_min;
    int near_row[3], far_row[3];

    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] explicit Avx2NodeTest(const BoxRay& ray) {
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
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] unsigned hit(const Bvh8Node& node, float t_max,
                                                        float* t_enter) const {
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
/// The node test of a ray with BoxRay::fused: each slab distance in one fused multiply-subtract,
/// fl(b r - fl(o r)) with r = fl(1 / d) (as Embree does), where SseNodeTest rounds twice,
/// fl(fl(b - o) r'). It is conservative for the same reasons (docs/structures.md): rounding
/// fl(o r) is the exact product for an origin moved by at most 2^-24 |o| along the axis, and
/// |o| <= |p| + t |d| for any point p = o + t d of the box, so the move splits into at most
/// 2^-24 of the box's coordinates (far inside the primitive padding of 2^-18) and at most 2^-24
/// of the distance t, which with the final rounding and that of r is a relative error of a few
/// 2^-24 in t. The slack is applied once, at the entry end: t_enter is fl(t0 (1 - 2 kSlabSlack))
/// with t0 >= t_min >= 0, which widens the interval by 2^-17 of t0, as much as SseNodeTest's
/// two ends together, far more than the few ulps of error at both ends. No NaN arises: every
/// r is finite (no direction component is zero), so is fl(o r), and the unused slots' infinite
/// planes give infinite distances of the right signs.
struct alignas(32) Avx2FusedNodeTest {
    static constexpr bool kCopyForDescent = true;
    static constexpr bool kAvx2 = true;
    __m256 reciprocal[3], origin_reciprocal[3], t_min;
    /// Byte offsets in a node of the rows of each axis' near and far planes.
    std::ptrdiff_t near_row[3], far_row[3];

    /// What make() made of a ray.
    enum class Setup { kTaken, kInvalid, kGeneral };

    /// Sets the test up for `ray` when it qualifies (kTaken): its origin and direction in float
    /// have every |o| <= 2^100 and every |d| in [2^-100, 2^100] (no zero component), t_min >= 0,
    /// and each fl(o r) is zero exactly when o is, else a normal float of magnitude at most
    /// 2^120. Such a ray has a finite origin and a finite non-zero direction, so it is valid
    /// exactly when t_min <= t_max (kInvalid when not). Any other ray (kGeneral) takes BoxRay,
    /// which decides its validity, and Avx2NodeTest. Most rays qualify, and this set-up is a
    /// few dozen instructions in registers.
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] Setup make(const Ray& ray) {
        // Every component read with an 8-byte load (load_two says why).
        const double* ray_o = ray.origin.data();
        const double* ray_d = ray.direction.data();
        const __m256d origin4 = _mm256_insertf128_pd(
            _mm256_castpd128_pd256(load_two(ray_o, ray_o + 1)), _mm_load_sd(ray_o + 2), 1);
        const __m256d direction4 = _mm256_insertf128_pd(
            _mm256_castpd128_pd256(load_two(ray_d, ray_d + 1)), load_two(ray_d + 2, &ray.t_min), 1);
        // Lane 3: origin 0, and t_min rounded to nearest in place of a direction component.
        const __m128 origin = _mm256_cvtpd_ps(origin4);
        const __m128 direction = _mm256_cvtpd_ps(direction4);
        const __m128 r = _mm_div_ps(_mm_set1_ps(1.0f), direction);
        const __m128 origin_r = _mm_mul_ps(origin, r);
        const __m128 sign = _mm_set1_ps(-0.0f);
        const __m128 d = _mm_andnot_ps(sign, direction), o = _mm_andnot_ps(sign, origin),
                     product = _mm_andnot_ps(sign, origin_r);
        // Each comparison is false for NaN.
        const __m128 ok = _mm_and_ps(
            _mm_and_ps(_mm_and_ps(_mm_cmpge_ps(d, _mm_set1_ps(0x1p-100f)),
                                  _mm_cmple_ps(d, _mm_set1_ps(0x1p100f))),
                       _mm_and_ps(_mm_cmple_ps(o, _mm_set1_ps(0x1p100f)),
                                  _mm_cmple_ps(product, _mm_set1_ps(0x1p120f)))),
            _mm_or_ps(_mm_cmpge_ps(product, _mm_set1_ps(std::numeric_limits<float>::min())),
                      _mm_cmpeq_ps(origin, _mm_setzero_ps())));
        if ((_mm_movemask_ps(ok) & 7) != 7 || !(ray.t_min >= 0.0)) return Setup::kGeneral;
        if (!(ray.t_min <= ray.t_max)) return Setup::kInvalid;
        // The largest float <= t_min: round_down's result. If rounding to nearest went up,
        // the float below, whose bits are one less (the rounded value is positive).
        float lowest = _mm_cvtss_f32(_mm_shuffle_ps(direction, direction, 3));
        if (double(lowest) > ray.t_min)
            lowest = std::bit_cast<float>(std::bit_cast<std::uint32_t>(lowest) - 1u);
        t_min = _mm256_set1_ps(lowest);
        // Rows 2 axis (lower) and 2 axis + 1 (upper) of 32 bytes; a negative component makes
        // the upper plane the near one. One table row for each of the eight sign patterns.
        static constexpr auto kRows = [] {
            std::array<std::array<std::ptrdiff_t, 6>, 8> rows{};
            for (int signs = 0; signs < 8; ++signs) {
                for (int axis = 0; axis < 3; ++axis) {
                    const std::ptrdiff_t flip = ((signs >> axis) & 1) * 32;
                    rows[signs][axis] = 64 * axis + flip;
                    rows[signs][3 + axis] = 64 * axis + 32 - flip;
                }
            }
            return rows;
        }();
        const auto& rows = kRows[_mm_movemask_ps(direction) & 7];
        for (int axis = 0; axis < 3; ++axis) {
            near_row[axis] = rows[axis];
            far_row[axis] = rows[3 + axis];
        }
        const __m256 r8 = _mm256_castps128_ps256(r), origin_r8 = _mm256_castps128_ps256(origin_r);
        reciprocal[0] = _mm256_permutevar8x32_ps(r8, _mm256_set1_epi32(0));
        reciprocal[1] = _mm256_permutevar8x32_ps(r8, _mm256_set1_epi32(1));
        reciprocal[2] = _mm256_permutevar8x32_ps(r8, _mm256_set1_epi32(2));
        origin_reciprocal[0] = _mm256_permutevar8x32_ps(origin_r8, _mm256_set1_epi32(0));
        origin_reciprocal[1] = _mm256_permutevar8x32_ps(origin_r8, _mm256_set1_epi32(1));
        origin_reciprocal[2] = _mm256_permutevar8x32_ps(origin_r8, _mm256_set1_epi32(2));
        return Setup::kTaken;
    }

    /// The eight children's distances to the planes of row `row` along `axis`.
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] __m256 distance(const Bvh8Node& node, std::ptrdiff_t row,
                                                           int axis) const {
        const float* plane =
            reinterpret_cast<const float*>(reinterpret_cast<const char*>(node.bounds) + row);
        return _mm256_fmsub_ps(_mm256_load_ps(plane), reciprocal[axis], origin_reciprocal[axis]);
    }

    /// As Avx2NodeTest::hit<false>; t_enter must be 32-byte aligned.
    template <bool kSigned>
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] unsigned hit(const Bvh8Node& node, float t_max,
                                                        float* t_enter) const {
        static_assert(!kSigned, "rays with signed intervals take Avx2NodeTest");
        // Accumulated plane by plane, which keeps few values live at once.
        __m256 t0 = _mm256_max_ps(distance(node, near_row[0], 0), t_min);
        t0 = _mm256_max_ps(t0, distance(node, near_row[1], 1));
        t0 = _mm256_max_ps(t0, distance(node, near_row[2], 2));
        __m256 t1 = _mm256_min_ps(distance(node, far_row[0], 0), _mm256_set1_ps(t_max));
        t1 = _mm256_min_ps(t1, distance(node, far_row[1], 1));
        t1 = _mm256_min_ps(t1, distance(node, far_row[2], 2));
        t0 = _mm256_mul_ps(t0, _mm256_set1_ps(1.0f - 2.0f * kSlack));
        _mm256_store_ps(t_enter, t0);
        return static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OQ)));
    }
};
#endif

#if CSGRT_BVH_AVX2
/// Up to eight rays as columns: row k of column r is ray r's origin (k = 0-2), direction
/// (3-5), t_min (6) and t_max (7). Columns past the packet's size repeat ray 0, which changes
/// no minimum, maximum or common value the packet tests take of them.
struct PacketRayColumns {
    alignas(32) double rows[8][8];

    // A Ray is these eight doubles in this order, so four rays are two 4x4 transposes.
    static_assert(std::is_standard_layout_v<Ray> && sizeof(Ray) == 8 * sizeof(double) &&
                  offsetof(Ray, direction) == 3 * sizeof(double) &&
                  offsetof(Ray, t_min) == 6 * sizeof(double) &&
                  offsetof(Ray, t_max) == 7 * sizeof(double));

    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] PacketRayColumns(const Ray* rays, int n) {
        for (int block = 0; block < 2; ++block) {
            const double* ray[4];
            for (int k = 0; k < 4; ++k) {
                const int r = 4 * block + k;
                ray[k] = reinterpret_cast<const double*>(&rays[r < n ? r : 0]);
            }
            for (int half = 0; half < 2; ++half) {
                const __m256d a = _mm256_loadu_pd(ray[0] + 4 * half);
                const __m256d b = _mm256_loadu_pd(ray[1] + 4 * half);
                const __m256d c = _mm256_loadu_pd(ray[2] + 4 * half);
                const __m256d d = _mm256_loadu_pd(ray[3] + 4 * half);
                const __m256d ab_even = _mm256_unpacklo_pd(a, b), ab_odd = _mm256_unpackhi_pd(a, b);
                const __m256d cd_even = _mm256_unpacklo_pd(c, d), cd_odd = _mm256_unpackhi_pd(c, d);
                double* row = rows[4 * half] + 4 * block;
                _mm256_store_pd(row, _mm256_permute2f128_pd(ab_even, cd_even, 0x20));
                _mm256_store_pd(row + 8, _mm256_permute2f128_pd(ab_odd, cd_odd, 0x20));
                _mm256_store_pd(row + 16, _mm256_permute2f128_pd(ab_even, cd_even, 0x31));
                _mm256_store_pd(row + 24, _mm256_permute2f128_pd(ab_odd, cd_odd, 0x31));
            }
        }
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
    /// Nineteen vectors: more than the registers hold, so a descent reads them where they are.
    static constexpr bool kCopyForDescent = false;
    static constexpr bool kAvx2 = true;
    __m256 near_origin[3], far_origin[3], near_low[3], near_high[3], far_low[3], far_high[3];
    __m256 t_min;
    int near_row[3], far_row[3];

    /// Whether the open rays of `lanes` (bits of `open`) can be walked as one; if so, sets the
    /// test up.
    template <class Lanes>
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] bool accepts(const Lanes& lanes, std::uint32_t open) {
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
        set(o_low, o_high, n_low, n_high, f_low, f_high, first.negative, lowest_t_min);
        return true;
    }

    /// accepts for a packet's rays (1 to 8) all open, in the common case only: every ray
    /// representable and valid (as BoxRay finds them), t_min a float >= 0, no zero direction
    /// component, one origin, one sign per axis, finite reciprocals. The rays' BoxRay values
    /// are made eight at a time with BoxRay's own float operations lane by lane (cvtpd2ps,
    /// divps, mulps), so the test is the very one accepts would make from the rays' BoxRays.
    /// False, with nothing set, for any other packet: accepts then decides from BoxRays.
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] bool accepts_rays(const PacketRayColumns& packet) {
        const auto& columns = packet.rows;
        const __m256d sign = _mm256_set1_pd(-0.0);
        const __m256d largest = _mm256_set1_pd(kLargestBoxRayValue);
        const __m256d smallest = _mm256_set1_pd(1.0 / kLargestBoxRayValue);
        __m128 t_min_half[2];
        unsigned common = 0xffu;
        int signs[3] = {0, 0, 0};
        for (int half = 0; half < 2; ++half) {
            __m256d ok = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
            for (int axis = 0; axis < 3; ++axis) {
                const __m256d o = _mm256_load_pd(columns[axis] + 4 * half);
                const __m256d d = _mm256_load_pd(columns[3 + axis] + 4 * half);
                const __m256d magnitude = _mm256_andnot_pd(sign, d);
                // BoxRay's representability without its zero case (false for NaN), and one
                // origin, compared in double.
                ok = _mm256_and_pd(ok,
                                   _mm256_cmp_pd(_mm256_andnot_pd(sign, o), largest, _CMP_LE_OQ));
                ok = _mm256_and_pd(ok, _mm256_cmp_pd(magnitude, largest, _CMP_LE_OQ));
                ok = _mm256_and_pd(ok, _mm256_cmp_pd(magnitude, smallest, _CMP_GE_OQ));
                ok = _mm256_and_pd(ok,
                                   _mm256_cmp_pd(o, _mm256_set1_pd(columns[axis][0]), _CMP_EQ_OQ));
                signs[axis] |= _mm256_movemask_pd(d) << (4 * half);
            }
            const __m256d ray_t_min = _mm256_load_pd(columns[6] + 4 * half);
            const __m256d ray_t_max = _mm256_load_pd(columns[7] + 4 * half);
            // Valid (t_min <= t_max, false for NaN), and BoxRay's t_min the float itself (it is
            // exact and finite) and not negative, so that the interval is not signed.
            t_min_half[half] = _mm256_cvtpd_ps(ray_t_min);
            const __m256d back = _mm256_cvtps_pd(t_min_half[half]);
            ok = _mm256_and_pd(ok, _mm256_cmp_pd(ray_t_min, ray_t_max, _CMP_LE_OQ));
            ok = _mm256_and_pd(ok, _mm256_cmp_pd(back, ray_t_min, _CMP_LE_OQ));
            ok = _mm256_and_pd(ok, _mm256_cmp_pd(back, _mm256_set1_pd(kInfinity), _CMP_NEQ_OQ));
            ok = _mm256_and_pd(ok, _mm256_cmp_pd(back, _mm256_setzero_pd(), _CMP_GE_OQ));
            common &= static_cast<unsigned>(_mm256_movemask_pd(ok)) << (4 * half) |
                      (half == 0 ? 0xf0u : 0x0fu);
        }
        if (common != 0xffu) return false;
        bool negative[3];
        float o_point[3], n_low[3], n_high[3], f_low[3], f_high[3];
        const __m256 float_max = _mm256_set1_ps(std::numeric_limits<float>::max());
        const __m256 float_sign = _mm256_set1_ps(-0.0f);
        for (int axis = 0; axis < 3; ++axis) {
            if (signs[axis] != 0 && signs[axis] != 0xff) return false;
            negative[axis] = signs[axis] != 0;
            const __m256 direction =
                _mm256_set_m128(_mm256_cvtpd_ps(_mm256_load_pd(columns[3 + axis] + 4)),
                                _mm256_cvtpd_ps(_mm256_load_pd(columns[3 + axis])));
            const __m256 inverse = _mm256_div_ps(_mm256_set1_ps(1.0f), direction);
            const __m256 near = _mm256_mul_ps(inverse, _mm256_set1_ps(1.0f - kSlack));
            const __m256 far = _mm256_mul_ps(inverse, _mm256_set1_ps(1.0f + kSlack));
            const __m256 finite = _mm256_and_ps(
                _mm256_cmp_ps(_mm256_andnot_ps(float_sign, near), float_max, _CMP_LE_OQ),
                _mm256_cmp_ps(_mm256_andnot_ps(float_sign, far), float_max, _CMP_LE_OQ));
            if (_mm256_movemask_ps(finite) != 0xff) return false;
            o_point[axis] = static_cast<float>(columns[axis][0]);
            n_low[axis] = smallest_lane(near);
            n_high[axis] = -smallest_lane(_mm256_xor_ps(near, float_sign));
            f_low[axis] = smallest_lane(far);
            f_high[axis] = -smallest_lane(_mm256_xor_ps(far, float_sign));
        }
        set(o_point, o_point, n_low, n_high, f_low, f_high, negative,
            smallest_lane(_mm256_set_m128(t_min_half[1], t_min_half[0])));
        return true;
    }

    /// The test of a packet whose origins span [o_low, o_high] and reciprocals [n_low,
    /// n_high] and [f_low, f_high] on each axis, with one sign per axis (negative), and whose
    /// least t_min is lowest_t_min.
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] void set(const float* o_low, const float* o_high,
                                                    const float* n_low, const float* n_high,
                                                    const float* f_low, const float* f_high,
                                                    const bool* negative, float lowest_t_min) {
        for (int axis = 0; axis < 3; ++axis) {
            near_origin[axis] = _mm256_set1_ps(negative[axis] ? o_low[axis] : o_high[axis]);
            far_origin[axis] = _mm256_set1_ps(negative[axis] ? o_high[axis] : o_low[axis]);
            near_low[axis] = _mm256_set1_ps(n_low[axis]);
            near_high[axis] = _mm256_set1_ps(n_high[axis]);
            far_low[axis] = _mm256_set1_ps(f_low[axis]);
            far_high[axis] = _mm256_set1_ps(f_high[axis]);
            // BoxRay::near_row and far_row of a width-8 node.
            near_row[axis] = (2 * axis + (negative[axis] ? 1 : 0)) * 8;
            far_row[axis] = (2 * axis + (negative[axis] ? 0 : 1)) * 8;
        }
        t_min = _mm256_set1_ps(lowest_t_min);
    }

    /// The least of eight floats, none of them NaN.
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] static float smallest_lane(__m256 values) {
        __m128 least = _mm_min_ps(_mm256_castps256_ps128(values), _mm256_extractf128_ps(values, 1));
        least = _mm_min_ps(least, _mm_movehl_ps(least, least));
        least = _mm_min_ss(least, _mm_shuffle_ps(least, least, 1));
        return _mm_cvtss_f32(least);
    }

    /// As Avx2NodeTest::hit<false> for the whole packet; t_enter must be 32-byte aligned.
    template <bool kSigned>
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] unsigned hit(const Bvh8Node& node, float t_max,
                                                        float* t_enter) const {
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

}  // namespace csgrt::detail
