#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace csgrt::detail {

/// Four floats operated on at once: SSE where the target has it (every x86-64), else a plain
/// loop with the same IEEE results. Comparisons give lane masks (all bits set or clear) as
/// Float4, which combine with &, | and and_not and reduce to four bits with `mask()`. min and
/// max follow minps/maxps: when either operand is NaN they return the second.
struct Float4 {
#if defined(__SSE2__)
    __m128 v;

    static Float4 load(const float* p) {
        return {_mm_loadu_ps(p)};
    }
    /// p must be 16-byte aligned.
    static Float4 load_aligned(const float* p) {
        return {_mm_load_ps(p)};
    }
    static Float4 broadcast(float x) {
        return {_mm_set1_ps(x)};
    }
    void store(float* p) const {
        _mm_storeu_ps(p, v);
    }
    friend Float4 operator+(Float4 a, Float4 b) {
        return {_mm_add_ps(a.v, b.v)};
    }
    friend Float4 operator-(Float4 a, Float4 b) {
        return {_mm_sub_ps(a.v, b.v)};
    }
    friend Float4 operator*(Float4 a, Float4 b) {
        return {_mm_mul_ps(a.v, b.v)};
    }
    friend Float4 min(Float4 a, Float4 b) {
        return {_mm_min_ps(a.v, b.v)};
    }
    friend Float4 max(Float4 a, Float4 b) {
        return {_mm_max_ps(a.v, b.v)};
    }
    /// |a| (clears the sign bit).
    friend Float4 abs(Float4 a) {
        return {_mm_andnot_ps(_mm_set1_ps(-0.0f), a.v)};
    }
    friend Float4 operator<(Float4 a, Float4 b) {
        return {_mm_cmplt_ps(a.v, b.v)};
    }
    friend Float4 operator>(Float4 a, Float4 b) {
        return {_mm_cmpgt_ps(a.v, b.v)};
    }
    friend Float4 operator<=(Float4 a, Float4 b) {
        return {_mm_cmple_ps(a.v, b.v)};
    }
    friend Float4 equal(Float4 a, Float4 b) {
        return {_mm_cmpeq_ps(a.v, b.v)};
    }
    friend Float4 operator&(Float4 a, Float4 b) {
        return {_mm_and_ps(a.v, b.v)};
    }
    friend Float4 operator|(Float4 a, Float4 b) {
        return {_mm_or_ps(a.v, b.v)};
    }
    /// ~a & b, bitwise.
    friend Float4 and_not(Float4 a, Float4 b) {
        return {_mm_andnot_ps(a.v, b.v)};
    }
    /// Bit i is the sign bit of lane i (for a comparison's result: whether it holds).
    unsigned mask() const {
        return static_cast<unsigned>(_mm_movemask_ps(v));
    }
    /// Lanes 1, 2, 0, 3 (x, y, z -> y, z, x).
    Float4 rotate() const {
        return {_mm_shuffle_ps(v, v, _MM_SHUFFLE(3, 0, 2, 1))};
    }
    /// Lane 0 + lane 1 + lane 2, added in that order.
    float sum3() const {
        const __m128 sum = _mm_add_ss(_mm_add_ss(v, _mm_shuffle_ps(v, v, 1)), _mm_movehl_ps(v, v));
        return _mm_cvtss_f32(sum);
    }
    /// Truncates each lane to an int (lanes must be in int range).
    void truncate(int* out) const {
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_cvttps_epi32(v));
    }
    /// Each lane truncated toward zero, as a float (lanes must be in int range).
    Float4 truncated() const {
        return {_mm_cvtepi32_ps(_mm_cvttps_epi32(v))};
    }
    /// The first three lanes of a, b, c as columns: x = (a0, b0, c0, 0), y = (a1, b1, c1, 0),
    /// z = (a2, b2, c2, 0).
    friend void transpose3(Float4 a, Float4 b, Float4 c, Float4& x, Float4& y, Float4& z) {
        const __m128 zero = _mm_setzero_ps();
        const __m128 ab_low = _mm_unpacklo_ps(a.v, b.v), c_low = _mm_unpacklo_ps(c.v, zero);
        const __m128 ab_high = _mm_unpackhi_ps(a.v, b.v), c_high = _mm_unpackhi_ps(c.v, zero);
        x = {_mm_movelh_ps(ab_low, c_low)};
        y = {_mm_movehl_ps(c_low, ab_low)};
        z = {_mm_movelh_ps(ab_high, c_high)};
    }
#else
    float v[4];

    static Float4 load(const float* p) {
        return {{p[0], p[1], p[2], p[3]}};
    }
    static Float4 load_aligned(const float* p) {
        return load(p);
    }
    static Float4 broadcast(float x) {
        return {{x, x, x, x}};
    }
    void store(float* p) const {
        std::copy_n(v, 4, p);
    }
    template <class Op>
    static Float4 apply(Float4 a, Float4 b, Op op) {
        return {{op(a.v[0], b.v[0]), op(a.v[1], b.v[1]), op(a.v[2], b.v[2]), op(a.v[3], b.v[3])}};
    }
    static float bits(bool condition) {
        return std::bit_cast<float>(condition ? ~0u : 0u);
    }
    template <class Op>
    static Float4 bitwise(Float4 a, Float4 b, Op op) {
        return apply(a, b, [op](float x, float y) {
            return std::bit_cast<float>(
                op(std::bit_cast<std::uint32_t>(x), std::bit_cast<std::uint32_t>(y)));
        });
    }
    friend Float4 operator+(Float4 a, Float4 b) {
        return apply(a, b, [](float x, float y) { return x + y; });
    }
    friend Float4 operator-(Float4 a, Float4 b) {
        return apply(a, b, [](float x, float y) { return x - y; });
    }
    friend Float4 operator*(Float4 a, Float4 b) {
        return apply(a, b, [](float x, float y) { return x * y; });
    }
    friend Float4 min(Float4 a, Float4 b) {
        return apply(a, b, [](float x, float y) { return x < y ? x : y; });
    }
    friend Float4 max(Float4 a, Float4 b) {
        return apply(a, b, [](float x, float y) { return x > y ? x : y; });
    }
    friend Float4 abs(Float4 a) {
        return apply(a, a, [](float x, float) { return x < 0.0f ? -x : x; });
    }
    friend Float4 operator<(Float4 a, Float4 b) {
        return apply(a, b, [](float x, float y) { return bits(x < y); });
    }
    friend Float4 operator>(Float4 a, Float4 b) {
        return apply(a, b, [](float x, float y) { return bits(x > y); });
    }
    friend Float4 operator<=(Float4 a, Float4 b) {
        return apply(a, b, [](float x, float y) { return bits(x <= y); });
    }
    friend Float4 equal(Float4 a, Float4 b) {
        return apply(a, b, [](float x, float y) { return bits(x == y); });
    }
    friend Float4 operator&(Float4 a, Float4 b) {
        return bitwise(a, b, [](std::uint32_t x, std::uint32_t y) { return x & y; });
    }
    friend Float4 operator|(Float4 a, Float4 b) {
        return bitwise(a, b, [](std::uint32_t x, std::uint32_t y) { return x | y; });
    }
    friend Float4 and_not(Float4 a, Float4 b) {
        return bitwise(a, b, [](std::uint32_t x, std::uint32_t y) { return ~x & y; });
    }
    Float4 rotate() const {
        return {{v[1], v[2], v[0], v[3]}};
    }
    float sum3() const {
        return v[0] + v[1] + v[2];
    }
    unsigned mask() const {
        unsigned m = 0;
        for (int i = 0; i < 4; ++i) m |= (std::bit_cast<std::uint32_t>(v[i]) >> 31) << i;
        return m;
    }
    void truncate(int* out) const {
        for (int i = 0; i < 4; ++i) out[i] = static_cast<int>(v[i]);
    }
    Float4 truncated() const {
        Float4 r;
        for (int i = 0; i < 4; ++i) r.v[i] = static_cast<float>(static_cast<int>(v[i]));
        return r;
    }
    friend void transpose3(Float4 a, Float4 b, Float4 c, Float4& x, Float4& y, Float4& z) {
        x = {{a.v[0], b.v[0], c.v[0], 0.0f}};
        y = {{a.v[1], b.v[1], c.v[1], 0.0f}};
        z = {{a.v[2], b.v[2], c.v[2], 0.0f}};
    }
#endif
};

}  // namespace csgrt::detail
