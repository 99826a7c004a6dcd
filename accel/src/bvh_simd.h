#pragma once

#include <algorithm>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace csgrt::detail {

/// Four floats operated on at once: SSE where the target has it (every x86-64), else a plain
/// loop. Only what the BVH builder needs. min and max follow minps/maxps: when either operand
/// is NaN they return the second.
struct Float4 {
#if defined(__SSE2__)
    __m128 v;

    static Float4 load(const float* p) {
        return {_mm_loadu_ps(p)};
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
    /// Truncates each lane to an int (lanes must be in int range).
    void truncate(int* out) const {
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_cvttps_epi32(v));
    }
#else
    float v[4];

    static Float4 load(const float* p) {
        return {{p[0], p[1], p[2], p[3]}};
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
    void truncate(int* out) const {
        for (int i = 0; i < 4; ++i) out[i] = static_cast<int>(v[i]);
    }
#endif
};

}  // namespace csgrt::detail
