// heightColour (mvog/height_colour.h): the colour map of the occupied-space markers and of
// mvog_export's rendering.
#include <gtest/gtest.h>

#include <cmath>

#include "mvog/height_colour.h"

namespace mvog {
namespace {

::testing::AssertionResult colourIs(const Rgb& colour, float r, float g, float b) {
  if (std::fabs(colour.r - r) < 1e-6f && std::fabs(colour.g - g) < 1e-6f &&
      std::fabs(colour.b - b) < 1e-6f) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "(" << colour.r << ", " << colour.g << ", " << colour.b
                                       << "), expected (" << r << ", " << g << ", " << b << ")";
}

TEST(HeightColour, RunsFromBlueThroughCyanGreenAndYellowToRed) {
  EXPECT_TRUE(colourIs(heightColour(0.0), 0, 0, 1));
  EXPECT_TRUE(colourIs(heightColour(0.25), 0, 1, 1));
  EXPECT_TRUE(colourIs(heightColour(0.5), 0, 1, 0));
  EXPECT_TRUE(colourIs(heightColour(0.75), 1, 1, 0));
  EXPECT_TRUE(colourIs(heightColour(1.0), 1, 0, 0));
  EXPECT_TRUE(colourIs(heightColour(-3.0), 0, 0, 1));  // clamped
  EXPECT_TRUE(colourIs(heightColour(7.0), 1, 0, 0));
}

TEST(HeightColour, ChangesLittleForALittleChangeOfHeight) {
  for (int k = 0; k < 1000; ++k) {
    const Rgb a = heightColour(k / 1000.0);
    const Rgb b = heightColour((k + 1) / 1000.0);
    EXPECT_LT(std::fabs(a.r - b.r) + std::fabs(a.g - b.g) + std::fabs(a.b - b.b), 0.01f) << k;
  }
}

}  // namespace
}  // namespace mvog
