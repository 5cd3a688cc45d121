// Pure geometry of models/geometry.h on hand-computed cases.
#include "models/geometry.h"

#include <gtest/gtest.h>

namespace linetrack {
namespace {

TEST(ImageGeometry, ClipKeepsThePartInsideTheImage) {
  Segment2 s{{-100.0, 240.0}, {800.0, 240.0}};
  ASSERT_TRUE(ClipSegmentToImage(640, 480, &s));
  EXPECT_NEAR(s.a.x(), 0.0, 1e-9);
  EXPECT_NEAR(s.b.x(), 639.0, 1e-9);
  Segment2 outside{{-10.0, -10.0}, {-1.0, 500.0}};
  EXPECT_FALSE(ClipSegmentToImage(640, 480, &outside));
  Segment2 diagonal{{-50.0, -50.0}, {50.0, 50.0}};
  ASSERT_TRUE(ClipSegmentToImage(640, 480, &diagonal));
  EXPECT_LT(diagonal.a.norm(), 1e-9);
}

}  // namespace
}  // namespace linetrack
