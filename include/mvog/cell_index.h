#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace mvog {

/// Cell (i, j) of the grid: i <= s * x < i + 1 and j <= s * y < j + 1 (Sec. III-A).
struct CellIndex {
  std::int32_t x = 0;
  std::int32_t y = 0;

  friend bool operator==(const CellIndex& a, const CellIndex& b) {
    return a.x == b.x && a.y == b.y;
  }
  friend bool operator!=(const CellIndex& a, const CellIndex& b) { return !(a == b); }
};

/// floor(g) as an index, for g whose floor an int32 holds: static_cast<std::int32_t>(std::floor(g))
/// without floor's call (SSE2 has no rounding instruction): the conversion truncates toward
/// zero, one too high for a negative g that is not an integer.
inline std::int32_t floorToIndex(double g) {
  const auto truncated = static_cast<std::int32_t>(g);
  return truncated - static_cast<std::int32_t>(g < static_cast<double>(truncated));
}

/// The cell that grid coordinate (gx, gy) = s * (x, y) projects onto.
inline CellIndex cellAt(double gx, double gy) { return {floorToIndex(gx), floorToIndex(gy)}; }

/// An inclusive rectangle of cells.
struct CellRange {
  CellIndex min;
  CellIndex max;

  bool empty() const { return max.x < min.x || max.y < min.y; }
  std::int64_t width() const { return empty() ? 0 : std::int64_t{max.x} - min.x + 1; }
  std::int64_t height() const { return empty() ? 0 : std::int64_t{max.y} - min.y + 1; }
  bool contains(const CellIndex& c) const {
    return c.x >= min.x && c.x <= max.x && c.y >= min.y && c.y <= max.y;
  }
  bool intersects(const CellRange& other) const {
    return !empty() && !other.empty() && other.max.x >= min.x && other.min.x <= max.x &&
           other.max.y >= min.y && other.min.y <= max.y;
  }
  /// Grows to hold `other` too (an empty `other` changes nothing).
  void extend(const CellRange& other) {
    if (other.empty()) return;
    if (empty()) {
      *this = other;
      return;
    }
    min = {std::min(min.x, other.min.x), std::min(min.y, other.min.y)};
    max = {std::max(max.x, other.max.x), std::max(max.y, other.max.y)};
  }
  void extend(const CellIndex& cell) { extend(CellRange{cell, cell}); }
};

/// The range holding no cell.
constexpr CellRange kNoCells{{0, 0}, {-1, -1}};

}  // namespace mvog
