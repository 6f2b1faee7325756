#pragma once

#include <algorithm>
#include <cmath>

namespace mvog {

/// A colour, each channel in [0, 1].
struct Rgb {
  float r = 0.0f;
  float g = 0.0f;
  float b = 0.0f;
};

/// The colour map of heights shared by the occupied-space markers and mvog_export's rendering:
/// blue at `fraction` <= 0 through cyan, green and yellow to red at `fraction` >= 1.
inline Rgb heightColour(double fraction) {
  const double h = std::clamp(fraction, 0.0, 1.0) * 4.0;  // 0..4
  const int band = std::min(3, static_cast<int>(h));
  const auto f = static_cast<float>(h - band);
  switch (band) {
    case 0:
      return {0, f, 1};
    case 1:
      return {0, 1, 1 - f};
    case 2:
      return {f, 1, 0};
    default:
      return {1, 1 - f, 0};
  }
}

}  // namespace mvog
