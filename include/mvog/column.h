#pragma once

#include <vector>

#include "mvog/map.h"

namespace mvog {

/// A stretch of a column over which eq. (9) is constant. Heights in grid units.
struct ColumnSegment {
  float bottom = 0.0f;
  float top = 0.0f;
  float probability = 0.0f;
};

/// Eq. (9) along a whole column: the known part of the column (where some volume lies) cut into
/// segments of constant probability, bottom to top, adjacent segments of equal probability
/// joined. Used to draw occupied space (Fig. 4, right) without sampling heights.
std::vector<ColumnSegment> columnProfile(const CellVolumes& volumes);
/// The same from a column as the map stores it (Map::column), into `segments` (cleared first,
/// its capacity reused): for queries over many cells.
void columnProfile(const ColumnView& column, std::vector<ColumnSegment>& segments);

}  // namespace mvog
