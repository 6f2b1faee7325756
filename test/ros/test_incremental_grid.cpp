// IncrementalGrid (mvog_ros/visualization.h): a 2D layer of the map kept up to date tile by
// tile, laid out over whole tiles around the map with a margin, re-laid out when the map
// outgrows it, refused beyond its largest size; and the tiles it is given (tilesChangedSince,
// mvog_ros/publications/change_publication.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

#include "mvog/map.h"
#include "mvog_ros/publications/change_publication.h"
#include "mvog_ros/visualization.h"

namespace mvog_ros {
namespace {

constexpr double kGridResolution = 0.1;
constexpr double kHeight = 1.0;  // m, of the cross-section
constexpr std::int64_t kTile = mvog::Map::kTileSize;
constexpr std::int64_t kMarginTiles = 4;  // the layout's margin around the map's tiles

mvog::Map emptyMap() {
  mvog::MapConfig config;
  config.resolution = kGridResolution;
  return mvog::Map(config);
}

/// An obstacle reading at kHeight from (x0, y) to (x1, y).
void mapReading(mvog::Map& map, double x0, double x1, double y) {
  map.insertReading({x0, y, kHeight}, {x1, y, kHeight}, mvog::ReadingKind::kObstacle);
}

IncrementalGrid crossSectionGrid(std::int64_t max_cells = 16000000) {
  return IncrementalGrid(kHeight, max_cells, [](const mvog::Map& map, const mvog::CellRange& c) {
    return toOccupancyGrid(map.crossSection(kHeight, c), kHeight, "", ros::Time()).data;
  });
}

/// A map holding one reading, along row 0 of tile (0, 0), and `grid` laid out over it.
mvog::Map oneReadingLaidOut(IncrementalGrid& grid) {
  mvog::Map map = emptyMap();
  mapReading(map, 0.05, 1.05, 0.05);
  bool relaid_out = false;
  grid.update(map, map.tilesModifiedSince(0), relaid_out);
  return map;
}

/// The grid's data as the map's cross-section over the grid's own cells says it should be.
nav_msgs::OccupancyGrid::_data_type expectedData(const mvog::Map& map,
                                                 const IncrementalGrid& grid) {
  return toOccupancyGrid(map.crossSection(kHeight, grid.cells()), kHeight, "", ros::Time()).data;
}

TEST(IncrementalGrid, AnEmptyMapHasNoGrid) {
  const mvog::Map map = emptyMap();
  IncrementalGrid grid = crossSectionGrid();
  bool relaid_out = true;
  EXPECT_TRUE(grid.update(map, {}, relaid_out).empty());
  EXPECT_FALSE(relaid_out);
  EXPECT_TRUE(grid.cells().empty());
  EXPECT_TRUE(grid.grid().data.empty());
}

TEST(IncrementalGrid, TheFirstUpdateLaysOutWholeTilesAroundTheMapWithAMargin) {
  mvog::Map map = emptyMap();
  mapReading(map, 0.05, 1.05, 0.05);  // cells 0..10 of row 0: tile (0, 0)
  IncrementalGrid grid = crossSectionGrid();
  bool relaid_out = false;
  const mvog::CellRange touched = grid.update(map, map.tilesModifiedSince(0), relaid_out);
  EXPECT_TRUE(relaid_out);
  const mvog::CellRange cells = grid.cells();
  EXPECT_EQ(touched.min, cells.min);
  EXPECT_EQ(touched.max, cells.max);
  EXPECT_EQ(cells.min, (mvog::CellIndex{static_cast<std::int32_t>(-kMarginTiles * kTile),
                                        static_cast<std::int32_t>(-kMarginTiles * kTile)}));
  EXPECT_EQ(cells.width(), (2 * kMarginTiles + 1) * kTile);
  EXPECT_EQ(cells.height(), (2 * kMarginTiles + 1) * kTile);
  const nav_msgs::OccupancyGrid& message = grid.grid();
  EXPECT_EQ(message.info.width, static_cast<std::uint32_t>(cells.width()));
  EXPECT_EQ(message.info.height, static_cast<std::uint32_t>(cells.height()));
  EXPECT_NEAR(message.info.origin.position.x, cells.min.x * kGridResolution, 1e-9);
  EXPECT_NEAR(message.info.origin.position.y, cells.min.y * kGridResolution, 1e-9);
  EXPECT_EQ(message.info.origin.position.z, kHeight);
  EXPECT_EQ(message.data, expectedData(map, grid));
}

TEST(IncrementalGrid, ChangesInsideTheLayoutUpdateOnlyTheirTiles) {
  IncrementalGrid grid = crossSectionGrid();
  mvog::Map map = oneReadingLaidOut(grid);
  bool relaid_out = false;
  const mvog::CellRange layout = grid.cells();

  const std::uint64_t revision = map.revision();
  mapReading(map, 0.05, 2.05, 0.55);  // row 5, cells 0..20: tiles (0, 0) and (1, 0)
  const std::vector<mvog::TileIndex> changed = map.tilesModifiedSince(revision);
  const mvog::CellRange touched = grid.update(map, changed, relaid_out);
  EXPECT_FALSE(relaid_out);
  EXPECT_EQ(grid.cells().min, layout.min);  // no re-layout
  EXPECT_EQ(grid.cells().max, layout.max);
  EXPECT_EQ(touched.min, (mvog::CellIndex{0, 0}));  // the union of the changed tiles
  EXPECT_EQ(touched.max, (mvog::CellIndex{2 * kTile - 1, kTile - 1}));
  EXPECT_EQ(grid.grid().data, expectedData(map, grid));

  // The update message is that rectangle of the grid, relative to the grid.
  const map_msgs::OccupancyGridUpdate update = grid.updateOf(touched);
  EXPECT_EQ(update.x, touched.min.x - layout.min.x);
  EXPECT_EQ(update.y, touched.min.y - layout.min.y);
  EXPECT_EQ(update.width, static_cast<std::uint32_t>(touched.width()));
  EXPECT_EQ(update.height, static_cast<std::uint32_t>(touched.height()));
  ASSERT_EQ(update.data.size(), std::size_t{update.width} * update.height);
  const nav_msgs::OccupancyGrid& whole = grid.grid();
  for (std::uint32_t row = 0; row < update.height; ++row) {
    for (std::uint32_t column = 0; column < update.width; ++column) {
      ASSERT_EQ(update.data[row * update.width + column],
                whole.data[(update.y + row) * whole.info.width + update.x + column]);
    }
  }

  bool unchanged_relaid_out = true;
  EXPECT_TRUE(grid.update(map, {}, unchanged_relaid_out).empty());  // nothing changed
  EXPECT_FALSE(unchanged_relaid_out);
}

TEST(IncrementalGrid, RemovedTilesBecomeUnknownAndAnEmptiedMapKeepsItsLayout) {
  IncrementalGrid grid = crossSectionGrid();
  mvog::Map map = oneReadingLaidOut(grid);
  const mvog::CellRange layout = grid.cells();
  std::uint64_t revision = map.revision();
  mapReading(map, 0.05, 3.05, 1.65);  // tiles (0, 1) and (1, 1)
  bool relaid_out = false;
  grid.update(map, map.tilesModifiedSince(revision), relaid_out);
  ASSERT_FALSE(relaid_out);
  revision = map.revision();
  map.clearBox({0.0, 1.6, -10.0}, {3.2, 3.2, 10.0});  // tiles (0, 1) and (1, 1) go
  std::vector<mvog::TileIndex> removed = *map.tilesRemovedSince(revision);
  ASSERT_EQ(removed.size(), 2u);
  grid.update(map, removed, relaid_out);
  EXPECT_FALSE(relaid_out);
  EXPECT_EQ(grid.grid().data, expectedData(map, grid));

  revision = map.revision();
  map.clearBox({-10.0, -10.0, -10.0}, {10.0, 10.0, 10.0});
  ASSERT_TRUE(map.empty());
  removed = *map.tilesRemovedSince(revision);
  const mvog::CellRange touched = grid.update(map, removed, relaid_out);
  EXPECT_FALSE(relaid_out);
  EXPECT_EQ(grid.cells().min, layout.min);
  EXPECT_EQ(grid.cells().max, layout.max);
  EXPECT_EQ(touched.min, mvog::Map::tileCells({0, 0}).min);
  EXPECT_EQ(touched.max, mvog::Map::tileCells({0, 0}).max);
  EXPECT_TRUE(std::all_of(grid.grid().data.begin(), grid.grid().data.end(),
                          [](std::int8_t value) { return value == -1; }));
}

TEST(IncrementalGrid, PassesOverTilesOutsideItsLayout) {
  IncrementalGrid grid = crossSectionGrid();
  mvog::Map map = oneReadingLaidOut(grid);
  const nav_msgs::OccupancyGrid::_data_type before = grid.grid().data;
  bool relaid_out = false;
  // A tile that came and went between two updates, far outside the layout.
  const mvog::CellRange touched = grid.update(map, {{100, 100}}, relaid_out);
  EXPECT_FALSE(relaid_out);
  EXPECT_TRUE(touched.empty());
  EXPECT_EQ(grid.grid().data, before);
}

TEST(IncrementalGrid, AMapOutgrowingTheLayoutIsLaidOutAgain) {
  IncrementalGrid grid = crossSectionGrid();
  mvog::Map map = oneReadingLaidOut(grid);
  bool relaid_out = false;
  const std::uint64_t revision = map.revision();
  mapReading(map, 0.05, 10.05, 0.05);  // to cell 100, tile 6: beyond the margin of 4 tiles
  const mvog::CellRange touched = grid.update(map, map.tilesModifiedSince(revision), relaid_out);
  EXPECT_TRUE(relaid_out);
  EXPECT_TRUE(grid.cells().contains(map.bounds().min));
  EXPECT_TRUE(grid.cells().contains(map.bounds().max));
  EXPECT_EQ(touched.min, grid.cells().min);
  EXPECT_EQ(touched.max, grid.cells().max);
  EXPECT_EQ(grid.grid().data, expectedData(map, grid));
}

TEST(IncrementalGrid, RefusesAMapWiderThanItsLargestSizeAndForgetsItsGrid) {
  const std::int64_t one_layout = (2 * kMarginTiles + 1) * kTile * (2 * kMarginTiles + 1) * kTile;
  IncrementalGrid grid = crossSectionGrid(one_layout);
  mvog::Map map = oneReadingLaidOut(grid);
  bool relaid_out = false;
  ASSERT_FALSE(grid.cells().empty());
  const std::uint64_t revision = map.revision();
  mapReading(map, 0.05, 10.05, 0.05);  // needs a layout two tiles wider
  EXPECT_THROW(grid.update(map, map.tilesModifiedSince(revision), relaid_out), GridTooLarge);
  EXPECT_TRUE(grid.cells().empty());
  EXPECT_TRUE(grid.grid().data.empty());
}

TEST(IncrementalGrid, ClearForgetsTheLayout) {
  IncrementalGrid grid = crossSectionGrid();
  mvog::Map map = oneReadingLaidOut(grid);
  bool relaid_out = false;
  grid.clear();
  EXPECT_TRUE(grid.cells().empty());
  EXPECT_TRUE(grid.grid().data.empty());
  grid.update(map, {}, relaid_out);  // the next update lays it out afresh, whatever changed
  EXPECT_TRUE(relaid_out);
  EXPECT_EQ(grid.grid().data, expectedData(map, grid));
}

TEST(IncrementalGrid, ARemovedTileBecomesUnknownAndTilesOutsideArePassedOver) {
  IncrementalGrid grid = crossSectionGrid();
  mvog::Map map = oneReadingLaidOut(grid);
  mapReading(map, 0.05, 2.05, 0.55);  // tiles (0, 0) and (1, 0)
  bool relaid_out = false;
  grid.update(map, map.tilesModifiedSince(0), relaid_out);
  const std::uint64_t revision = map.revision();
  // Every cell of tile (1, 0) emptied: the map removes the tile, which tilesModifiedSince does
  // not list, tilesChangedSince does.
  std::vector<mvog::Map::CellAssignment> emptied;
  for (std::int32_t y = 0; y < kTile; ++y) {
    for (std::int32_t x = kTile; x < 2 * kTile; ++x) emptied.push_back({{x, y}, {}});
  }
  map.setCellVolumes(emptied);
  EXPECT_TRUE(map.tilesModifiedSince(revision).empty());
  const std::optional<std::vector<mvog::TileIndex>> changed = tilesChangedSince(map, revision);
  ASSERT_TRUE(changed.has_value());
  ASSERT_EQ(changed->size(), 1u);
  EXPECT_EQ(changed->front(), (mvog::TileIndex{1, 0}));
  const mvog::CellRange touched = grid.update(map, *changed, relaid_out);
  EXPECT_FALSE(relaid_out);
  EXPECT_EQ(touched.min, (mvog::CellIndex{kTile, 0}));
  EXPECT_EQ(grid.grid().data, expectedData(map, grid));
  // A tile beyond the layout has nothing to show.
  const nav_msgs::OccupancyGrid::_data_type before = grid.grid().data;
  EXPECT_TRUE(grid.update(map, {{1000, 1000}, {-1000, 3}}, relaid_out).empty());
  EXPECT_EQ(grid.grid().data, before);
}

TEST(TilesChangedSince, ModifiedAndRemovedTilesInRowsFromTheLowestOrNothingAfterAClear) {
  mvog::Map map = emptyMap();
  mapReading(map, -1.55, 1.55, 0.05);        // tiles (-1, 0) and (0, 0)
  mapReading(map, 0.05, 0.05 + 1.0, -1.05);  // tile (0, -1)
  const std::uint64_t revision = map.revision();
  map.setCellVolumes({5, -11}, {});                // tile (0, -1) keeps other cells: modified
  mapReading(map, 2.05, 2.55, 2.05);               // tile (1, 1), new
  std::vector<mvog::Map::CellAssignment> emptied;  // tile (-1, 0) removed
  for (std::int32_t y = 0; y < kTile; ++y) {
    for (std::int32_t x = -kTile; x < 0; ++x) emptied.push_back({{x, y}, {}});
  }
  map.setCellVolumes(emptied);
  const std::optional<std::vector<mvog::TileIndex>> changed = tilesChangedSince(map, revision);
  ASSERT_TRUE(changed.has_value());
  EXPECT_EQ(*changed, (std::vector<mvog::TileIndex>{{0, -1}, {-1, 0}, {1, 1}}));
  EXPECT_EQ(tilesChangedSince(map, map.revision()), std::vector<mvog::TileIndex>{});
  map.clear();  // the map no longer knows which tiles went
  EXPECT_FALSE(tilesChangedSince(map, revision).has_value());
}

}  // namespace
}  // namespace mvog_ros
