#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "mvog/cell_index.h"

namespace mvog {

/// Occupancy of a point or a cell, by a probability threshold (Sec. III-C).
enum class OccupancyState : std::uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

/// A row-major 2D grid over a rectangle of cells: value(x, y) belongs to cell
/// (cells.min.x + x, cells.min.y + y). Rows run along +x, starting at the lowest y.
template <class T>
struct Grid2D {
  double resolution = 0.0;
  CellRange cells = kNoCells;
  std::vector<T> values;

  std::size_t width() const { return static_cast<std::size_t>(cells.width()); }
  std::size_t height() const { return static_cast<std::size_t>(cells.height()); }
  const T& at(std::size_t x, std::size_t y) const { return values[y * width() + x]; }
  /// World coordinates (m) of the corner of the grid's first cell.
  double originX() const { return cells.min.x * resolution; }
  double originY() const { return cells.min.y * resolution; }
};

/// Eq. (9) over a horizontal plane: probability of occupancy, NaN where unknown (Fig. 5).
using CrossSection = Grid2D<float>;
/// Occupancy over a height band: occupied, free or unknown per cell (see Map::projection).
using Projection = Grid2D<OccupancyState>;

}  // namespace mvog
