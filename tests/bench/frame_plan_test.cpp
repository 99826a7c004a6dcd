#include "csgrt/bench/frame_plan.h"

#include <gtest/gtest.h>

namespace csgrt::bench {
namespace {

TEST(PlanFrame, TheFullFrameWhenItFitsTheBudget) {
    // 512 x 512 pixels, 3 rays a pixel, 14 objects: 1.1e7 object tests, within 1e8.
    const FramePlan plan = plan_frame(512, 14, 3, 1e8);
    EXPECT_EQ(plan.width, 512);
    EXPECT_EQ(plan.scale, 1.0);
    EXPECT_FALSE(plan.extrapolated());
}

TEST(PlanFrame, ASmallerFrameWithinTheBudgetScaledByThePixels) {
    // 10,001 objects, 3 rays a pixel, budget 1e8: 1e8 / 30003 = 3333 pixels, so a 57 x 57
    // frame (3249 pixels; 58 x 58 = 3364 would exceed it), scaled by 512^2 / 57^2.
    const FramePlan plan = plan_frame(512, 10001, 3, 1e8);
    EXPECT_EQ(plan.width, 57);
    EXPECT_DOUBLE_EQ(plan.scale, 512.0 * 512.0 / (57.0 * 57.0));
    EXPECT_TRUE(plan.extrapolated());
    EXPECT_LE(57.0 * 57.0 * 3.0 * 10001.0, 1e8);
    EXPECT_GT(58.0 * 58.0 * 3.0 * 10001.0, 1e8);
}

TEST(PlanFrame, NeverBelowTheMinimumWidth) {
    // A budget that affords less than one pixel still renders min_width x min_width.
    const FramePlan plan = plan_frame(512, 1e9, 3, 1e6, 16);
    EXPECT_EQ(plan.width, 16);
    EXPECT_DOUBLE_EQ(plan.scale, 1024.0);
    // A requested frame already at or below the minimum is rendered as asked.
    EXPECT_EQ(plan_frame(8, 1e9, 3, 1.0, 16).width, 8);
    EXPECT_EQ(plan_frame(8, 1e9, 3, 1.0, 16).scale, 1.0);
}

}  // namespace
}  // namespace csgrt::bench
