#include "csgrt/render/tonemap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "csgrt/core/error.h"

namespace csgrt {
namespace {

constexpr ToneMapping kReinhard{ToneCurve::Reinhard, 0.0};
constexpr ToneMapping kFilmic{ToneCurve::Filmic, 0.0};
constexpr ToneMapping kClamp{ToneCurve::Clamp, 0.0};

TEST(ToneMap, ReinhardIsXOverOnePlusX) {
    // Closed form: 1 -> 1/2, 3 -> 3/4, 0.25 -> 0.2; exact up to one rounding of the division.
    EXPECT_DOUBLE_EQ(tone_map(1.0, kReinhard), 0.5);
    EXPECT_DOUBLE_EQ(tone_map(3.0, kReinhard), 0.75);
    EXPECT_DOUBLE_EQ(tone_map(0.25, kReinhard), 0.2);
    // Never clips: a thousand is still below one, and larger inputs stay larger.
    EXPECT_LT(tone_map(1000.0, kReinhard), 1.0);
    EXPECT_LT(tone_map(1000.0, kReinhard), tone_map(2000.0, kReinhard));
}

TEST(ToneMap, FilmicFollowsNarkowiczsFit) {
    // The fit evaluated by hand at x = 1 (s = 0.6): 0.6 * 1.536 / (0.6 * 2.048 + 0.14).
    const double s = 0.6;
    EXPECT_DOUBLE_EQ(tone_map(1.0, kFilmic),
                     s * (2.51 * s + 0.03) / (s * (2.43 * s + 0.59) + 0.14));
    EXPECT_EQ(tone_map(0.0, kFilmic), 0.0);
    EXPECT_EQ(tone_map(100.0, kFilmic), 1.0);  // the shoulder saturates
    // Monotone over the range a render produces.
    double previous = 0.0;
    for (int i = 1; i <= 2000; ++i) {
        const double value = tone_map(i / 100.0, kFilmic);
        EXPECT_GE(value, previous) << i;
        previous = value;
    }
}

TEST(ToneMap, ExposureScalesByPowersOfTwoBeforeTheCurve) {
    const ToneMapping up_one{ToneCurve::Reinhard, 1.0};
    const ToneMapping down_two{ToneCurve::Clamp, -2.0};
    EXPECT_DOUBLE_EQ(tone_map(0.5, up_one), 0.5);  // 0.5 * 2 = 1 -> 1/2
    EXPECT_DOUBLE_EQ(tone_map(2.0, down_two), 0.5);
}

TEST(ToneMap, BadValuesAreDefined) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (const ToneMapping& mapping : {kClamp, kReinhard, kFilmic}) {
        EXPECT_EQ(tone_map(nan, mapping), 0.0);
        EXPECT_EQ(tone_map(-3.0, mapping), 0.0);
        EXPECT_EQ(tone_map(inf, mapping), 1.0);
    }
    EXPECT_EQ(tone_map(0.3, kClamp), 0.3);
    EXPECT_EQ(tone_map(7.0, kClamp), 1.0);
}

TEST(ToneMap, CurvesAreNamed) {
    for (ToneCurve curve : {ToneCurve::Clamp, ToneCurve::Reinhard, ToneCurve::Filmic}) {
        EXPECT_EQ(parse_tone_curve(tone_curve_name(curve)), curve);
    }
    EXPECT_THROW(parse_tone_curve("aces"), InvalidParameter);
    EXPECT_EQ(ToneMapping{}.curve, ToneCurve::Filmic);  // the documented default
}

}  // namespace
}  // namespace csgrt
