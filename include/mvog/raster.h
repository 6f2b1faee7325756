#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "mvog/cell_index.h"

namespace mvog {

/// Where a ray walk is: its cell, moved one step at a time along x or y (walkRayWith).
struct CellCursor {
  CellIndex cell;
  void moveTo(const CellIndex& c) { cell = c; }
  void stepX(int step) { cell.x += step; }
  void stepY(int step) { cell.y += step; }
};

/// Rasterization of Sec. III-B.1: walks every cell that the xy-projection of the segment
/// start -> end (grid units) crosses, in order, with the heights at which the segment enters and
/// leaves the space above it (Amanatides-Woo in 2D). `cursor` keeps the cell (CellCursor's
/// moveTo, stepX and stepY: a cursor may keep more, e.g. where the cell is stored); at every
/// cell crossed, with the cursor there, calls
///   visit(double z_enter, double z_exit, bool is_last)
/// The last cell is the one holding `end` (its z_exit is end's height); the first cell's entry
/// height is start's height. Decisions where the paper is silent:
///  - a cell that the projection only touches in one point (a ray through a grid corner, or a
///    start lying on the wall it leaves through) is not crossed and is not visited, unless it is
///    the last cell;
///  - a purely vertical segment (dx = dy = 0) crosses exactly one cell, its last;
///  - the walk takes exactly |di| + |dj| steps, so it always ends in end's cell whatever the
///    rounding, and never divides by a zero component.
template <class Cursor, class Visitor>
void walkRayWith(Cursor& cursor, double start_x, double start_y, double start_z, double end_x,
                 double end_y, double end_z, Visitor&& visit) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double dx = end_x - start_x;
  const double dy = end_y - start_y;
  const double dz = end_z - start_z;
  const CellIndex cell = cellAt(start_x, start_y);
  const CellIndex end_cell = cellAt(end_x, end_y);
  cursor.moveTo(cell);
  const int step_x = dx > 0 ? 1 : -1;
  const int step_y = dy > 0 ? 1 : -1;
  long remaining_x = std::labs(long{end_cell.x} - cell.x);
  long remaining_y = std::labs(long{end_cell.y} - cell.y);
  // Ray parameter t in [0, 1] at which the next x (y) wall is reached, and between two walls.
  double t_next_x =
      remaining_x > 0 ? ((step_x > 0 ? cell.x + 1.0 : double(cell.x)) - start_x) / dx : kInf;
  double t_next_y =
      remaining_y > 0 ? ((step_y > 0 ? cell.y + 1.0 : double(cell.y)) - start_y) / dy : kInf;
  const double t_delta_x = remaining_x > 0 ? 1.0 / std::fabs(dx) : kInf;
  const double t_delta_y = remaining_y > 0 ? 1.0 / std::fabs(dy) : kInf;

  double t_enter = 0.0;
  double z_enter = start_z;
  while (remaining_x > 0 || remaining_y > 0) {
    const bool along_x = remaining_y == 0 || (remaining_x > 0 && t_next_x <= t_next_y);
    const double t_exit = std::min(1.0, std::max(t_enter, along_x ? t_next_x : t_next_y));
    const double z_exit = start_z + t_exit * dz;
    if (t_exit > t_enter) visit(z_enter, z_exit, false);
    if (along_x) {
      cursor.stepX(step_x);
      t_next_x += t_delta_x;
      --remaining_x;
    } else {
      cursor.stepY(step_y);
      t_next_y += t_delta_y;
      --remaining_y;
    }
    t_enter = t_exit;
    z_enter = z_exit;
  }
  visit(z_enter, end_z, true);
}

/// walkRayWith with the cell alone: calls
///   visit(CellIndex cell, double z_enter, double z_exit, bool is_last)
template <class Visitor>
void walkRay(double start_x, double start_y, double start_z, double end_x, double end_y,
             double end_z, Visitor&& visit) {
  CellCursor cursor;
  walkRayWith(cursor, start_x, start_y, start_z, end_x, end_y, end_z,
              [&](double z_enter, double z_exit, bool is_last) {
                visit(cursor.cell, z_enter, z_exit, is_last);
              });
}

}  // namespace mvog
