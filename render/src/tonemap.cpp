#include "csgrt/render/tonemap.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"

namespace csgrt {

namespace {

/// Each curve with its name in scene files and on the command line: both directions read it.
struct NamedCurve {
    ToneCurve curve;
    std::string_view name;
};
constexpr NamedCurve kCurveNames[] = {
    {ToneCurve::Clamp, "clamp"}, {ToneCurve::Reinhard, "reinhard"}, {ToneCurve::Filmic, "filmic"}};

}  // namespace

ToneCurve parse_tone_curve(std::string_view name) {
    for (const NamedCurve& named : kCurveNames) {
        if (named.name == name) return named.curve;
    }
    require(false, "ToneMapping", "curve", "one of clamp, reinhard, filmic", std::string(name));
    return ToneCurve::Filmic;
}

std::string_view tone_curve_name(ToneCurve curve) {
    for (const NamedCurve& named : kCurveNames) {
        if (named.curve == curve) return named.name;
    }
    return "filmic";
}

double tone_map(double linear, const ToneMapping& mapping) {
    return ToneMapper(mapping)(linear);
}

ToneMapper::ToneMapper(const ToneMapping& mapping)
    : curve_(mapping.curve), scale_(std::exp2(mapping.exposure_stops)) {}

double ToneMapper::operator()(double linear) const {
    // NaN-safe: a NaN or a negative value becomes 0 before the curve.
    const double x = linear > 0.0 ? linear * scale_ : 0.0;
    switch (curve_) {
        case ToneCurve::Clamp:
            return std::min(x, 1.0);
        case ToneCurve::Reinhard:
            return std::isinf(x) ? 1.0 : x / (1.0 + x);
        case ToneCurve::Filmic: {
            if (std::isinf(x)) return 1.0;
            const double s = 0.6 * x;  // Narkowicz's scale from ACES's input to the fit's
            const double mapped = (s * (2.51 * s + 0.03)) / (s * (2.43 * s + 0.59) + 0.14);
            return std::clamp(mapped, 0.0, 1.0);
        }
    }
    return 0.0;
}

}  // namespace csgrt
