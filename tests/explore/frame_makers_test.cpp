// The explore verb of the registered representations: every source plan_frame can choose has
// exactly one maker, so the Explorer never finds none (a representation added without its maker)
// nor two (a source claimed twice, drawn by whichever comes first).
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "explore/frame_maker.hpp"
#include "representation/representation.hpp"

namespace insitu::detail {
namespace {

TEST(FrameMakers, EverySourceHasExactlyOneRegisteredMaker) {
    std::vector<std::unique_ptr<FrameMaker>> makers;
    // No frame is made here, so the makers need no device.
    for (const auto& representation : representations()) {
        makers.push_back(representation->frame_maker(nullptr));
        ASSERT_NE(makers.back(), nullptr);
    }
    for (const FrameSource source : {FrameSource::light_field, FrameSource::fused,
                                     FrameSource::proxies, FrameSource::volume}) {
        int claimed = 0;
        for (const auto& maker : makers) claimed += maker->makes(source) ? 1 : 0;
        EXPECT_EQ(claimed, 1) << "frame source " << static_cast<int>(source);
    }
}

}  // namespace
}  // namespace insitu::detail
