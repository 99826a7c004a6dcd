#pragma once

#include <string>
#include <string_view>

namespace csgrt {

/// The curve that maps linear scene radiance to display values in [0, 1] for the PNG preview
/// (docs/rendering.md). The EXR always keeps the unmapped linear radiance.
enum class ToneCurve {
    /// min(x, 1): values above 1 saturate (the preview before tone mapping existed).
    Clamp,
    /// x / (1 + x) per channel (Reinhard, Stark, Shirley and Ferwerda, "Photographic Tone
    /// Reproduction for Digital Images", SIGGRAPH 2002, eq. 3): never reaches 1, so never clips.
    Reinhard,
    /// Narkowicz's fit of the ACES reference rendering transform, "ACES Filmic Tone Mapping
    /// Curve" (2016): x' = 0.6 x, (x'(2.51 x' + 0.03)) / (x'(2.43 x' + 0.59) + 0.14), clamped
    /// to [0, 1]. A toe and a shoulder like film's; reaches 1 near x = 10.
    Filmic,
};

/// What the preview applies before the curve: linear * 2^exposure_stops.
struct ToneMapping {
    ToneCurve curve = ToneCurve::Filmic;
    double exposure_stops = 0.0;
};

/// "clamp", "reinhard", "filmic"; throws InvalidParameter naming the accepted names otherwise.
ToneCurve parse_tone_curve(std::string_view name);
std::string_view tone_curve_name(ToneCurve curve);

/// The display-linear value in [0, 1] for a linear value (NaN and negative values give 0).
double tone_map(double linear, const ToneMapping& mapping);

/// tone_map with the exposure's power of two computed once, for the pixels of a whole image:
/// gives tone_map's values exactly.
class ToneMapper {
public:
    explicit ToneMapper(const ToneMapping& mapping);
    double operator()(double linear) const;

private:
    ToneCurve curve_;
    double scale_;
};

}  // namespace csgrt
