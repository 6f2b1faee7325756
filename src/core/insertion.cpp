// The second half of the scan update of Fig. 2: the constraints applied once to every list the
// scan modified (Sec. III-B.3), with the model's rules (Sec. V.B, V.C).
#include <algorithm>
#include <memory>
#include <tuple>

#include "map_storage.h"
#include "mvog/constraints.h"
#include "mvog/map.h"
#include "scan_scratch.h"

namespace mvog {
namespace {

using detail::ColumnWork;
using detail::ScanInterval;

/// A run of volumes to change.
struct VolumeSpan {
  Volume* data;
  std::uint32_t size;
  Volume* begin() const { return data; }
  Volume* end() const { return data + size; }
};

/// The mass, in the map's stored unit, of the part [bottom, top] of a scan's interval: per scan,
/// density 1 over the union of the heights seen; per reading (the paper), each reading's mass,
/// kept in proportion where a part of the union is cut away.
float massOf(const ScanInterval& i, float bottom, float top, bool per_scan, float unit_mass) {
  const double height = static_cast<double>(top) - bottom;
  const double mass = per_scan || (bottom == i.bottom && top == i.top)
                          ? (per_scan ? height : i.mass)
                          : i.mass * height / (static_cast<double>(i.top) - i.bottom);
  return static_cast<float>(mass * unit_mass);
}

/// The new volumes of one column, as the model's rules make them from what one scan saw there
/// (`free` and `hits`: sorted, disjoint), masses in the map's stored unit; the free space clipped
/// around `clip_at` (sorted by bottom: the scan's hits, and with
/// InsertionConfig::hit_memory_scans the latest scans' too).
void addedVolumes(const std::vector<ScanInterval>& free, const std::vector<ScanInterval>& hits,
                  const std::vector<ScanInterval>& clip_at, const ModelRules& rules,
                  float unit_mass, CellVolumes& added) {
  added.positive.clear();
  added.negative.clear();
  const bool per_scan = rules.mass_counting == MassCounting::kPerScan;
  auto mass_of = [&](const ScanInterval& i, float bottom, float top) {
    return massOf(i, bottom, top, per_scan, unit_mass);
  };
  for (const ScanInterval& i : hits)
    added.positive.push_back({i.bottom, i.top, mass_of(i, i.bottom, i.top)});
  for (const ScanInterval& i : free) {
    if (!rules.clip_free_space_at_hits) {
      added.negative.push_back({i.bottom, i.top, mass_of(i, i.bottom, i.top)});
      continue;
    }
    // Sec. V.B: the parts of the free interval outside the scan's own obstacle volumes (and
    // its group's); a part lower than kMinVolumeHeight (a sliver beside a hit) is dropped.
    float below = i.bottom;
    auto keep = [&](float bottom, float top) {
      if (top - bottom >= kMinVolumeHeight)
        added.negative.push_back({bottom, top, mass_of(i, bottom, top)});
    };
    for (const ScanInterval& hit : clip_at) {
      if (hit.top <= below) continue;
      if (hit.bottom >= i.top) break;
      keep(below, std::min(hit.bottom, i.top));
      below = std::max(below, hit.top);
    }
    if (below < i.top) keep(below, i.top);
  }
}

/// Whether hit a comes before hit b: by cell, then by height.
bool hitBefore(const detail::TileHit& a, const detail::TileHit& b) {
  return std::tie(a.local, a.bottom, a.top) < std::tie(b.local, b.bottom, b.top);
}

/// Gathers what the scan's scratches hold for tile `key`: its parts, and its hits by cell, each
/// cell's by height.
void gatherTile(std::uint64_t key, const std::vector<detail::ScanScratch>& scratches,
                ColumnWork& work) {
  work.parts.clear();
  work.hits.clear();
  std::fill(std::begin(work.reached), std::end(work.reached), std::uint64_t{0});
  for (const detail::ScanScratch& scratch : scratches) {
    const detail::ScratchTile* part = scratch.find(key);
    if (part != nullptr && !part->reachedNone()) {
      work.parts.emplace_back(&scratch, part);
      work.hits.insert(work.hits.end(), part->hits.begin(), part->hits.end());
      for (std::size_t w = 0; w < std::size(work.reached); ++w) {
        work.reached[w] |= part->reached[w] | part->level_free[w];
      }
    }
  }
  // A tile mostly holds a few hits: sorted as they are. Many (a dense camera's) are first
  // counted by cell, which costs a pass over the tile's cells.
  constexpr std::size_t kFewHits = 32;
  if (work.hits.size() <= kFewHits) {
    std::sort(work.hits.begin(), work.hits.end(), hitBefore);
    return;
  }
  std::uint32_t cell_start[detail::kCellsPerTile + 1] = {};
  for (const detail::TileHit& hit : work.hits) ++cell_start[hit.local + 1];
  for (unsigned local = 0; local < detail::kCellsPerTile; ++local) {
    cell_start[local + 1] += cell_start[local];
  }
  work.sorted_hits.resize(work.hits.size());
  for (const detail::TileHit& hit : work.hits) work.sorted_hits[cell_start[hit.local]++] = hit;
  std::swap(work.hits, work.sorted_hits);
  // cell_start[local] is now where cell local + 1 starts.
  auto first = work.hits.begin();
  for (unsigned local = 0; local < detail::kCellsPerTile; ++local) {
    const auto last = work.hits.begin() + cell_start[local];
    if (last - first > 1 && !std::is_sorted(first, last, hitBefore))
      std::sort(first, last, hitBefore);
    first = last;
  }
}

/// A cell's hits: a run of gatherTile's list.
struct HitRun {
  const detail::TileHit* first;
  const detail::TileHit* last;
  bool empty() const { return first == last; }
  const detail::TileHit* begin() const { return first; }
  const detail::TileHit* end() const { return last; }
};

/// The hits of the cells a tile's update visits in increasing local order (gatherTile's list,
/// sorted by cell, holds only cells the scan reached): each cell's start where the previous
/// cell's end.
class HitCursor {
 public:
  explicit HitCursor(const std::vector<detail::TileHit>& hits)
      : next_(hits.data()), end_(hits.data() + hits.size()) {}
  HitRun next(unsigned local) {
    const detail::TileHit* first = next_;
    while (next_ != end_ && next_->local == local) ++next_;
    return {first, next_};
  }

 private:
  const detail::TileHit* next_;
  const detail::TileHit* end_;
};

/// What the scan saw in cell `local`: its free intervals and its hits, each joined.
void scanColumn(unsigned local, HitRun hits, float join_gap, ColumnWork& work) {
  work.free.clear();
  for (const auto& [scratch, part] : work.parts) scratch->appendFree(*part, local, work.free);
  if (work.parts.size() > 1) {
    // Each thread's part is joined already; join the parts. The masses are exact sums
    // (ScanInterval), so the union is the same as one thread's, bit for bit.
    std::sort(work.free.begin(), work.free.end(), [](const ScanInterval& a, const ScanInterval& b) {
      return std::tie(a.bottom, a.top, a.mass) < std::tie(b.bottom, b.top, b.mass);
    });
    detail::joinSorted(work.free, join_gap);
  }
  work.positive.clear();
  for (const detail::TileHit& hit : hits) {
    const double mass = static_cast<double>(hit.top) - hit.bottom;  // density 1 (eq. 5)
    if (!work.positive.empty() && detail::joins(work.positive.back().top, hit.bottom, join_gap)) {
      work.positive.back().top = std::max(work.positive.back().top, hit.top);
      work.positive.back().mass += mass;
    } else {
      work.positive.push_back({hit.bottom, hit.top, mass});
    }
  }
}

/// addCoveredFreeSpace when an added volume is not within one negative volume: each added volume
/// must lie within one run of touching negative volumes, among which its mass is shared.
[[gnu::noinline]] bool addSpanningFreeSpace(VolumeRun added, Volume* negative,
                                            std::uint32_t num_negative) {
  if (num_negative == 0) return false;
  // Every added volume lies within one run of touching negative volumes.
  for (const Volume& a : added) {
    std::uint32_t k = 0;
    while (k < num_negative && negative[k].top < a.bottom) ++k;
    if (k == num_negative || negative[k].bottom > a.bottom) return false;
    while (negative[k].top < a.top) {
      if (k + 1 == num_negative || negative[k + 1].bottom != negative[k].top) return false;
      ++k;
    }
  }
  for (Volume& v : VolumeSpan{negative, num_negative}) {
    double mass = v.mass;
    for (const Volume& a : added) {
      if (a.bottom >= v.top) break;
      if (a.bottom >= v.bottom && a.top <= v.top) {
        mass += a.mass;
        continue;
      }
      const double overlap =
          static_cast<double>(std::min(v.top, a.top)) - std::max(v.bottom, a.bottom);
      if (overlap > 0.0) mass += a.mass * overlap / (static_cast<double>(a.top) - a.bottom);
    }
    v.mass = static_cast<float>(mass);
  }
  return true;
}

/// The commonest update by far once a place has been seen: free space where the column already
/// holds free space, and no hit. The lists keep their volumes and bounds; each negative volume
/// gains the mass that falls within it (what ListMerger gives: no gap closes, no obstacle is
/// newly reached, so its pieces stay). Returns false, changing nothing, in any other case.
inline bool addCoveredFreeSpace(VolumeRun added, Volume* negative, std::uint32_t num_negative) {
  if (added.size == 1) {
    // Mostly one added volume within one negative volume: its mass added there, inline (the
    // same double sum as below).
    for (Volume& v : VolumeSpan{negative, num_negative}) {
      if (v.top < added.data[0].top) continue;
      if (v.bottom > added.data[0].bottom) break;
      v.mass = static_cast<float>(static_cast<double>(v.mass) + added.data[0].mass);
      return true;
    }
  }
  return addSpanningFreeSpace(added, negative, num_negative);
}

/// Free space that reaches beyond one run of touching negative volumes (the pieces of one free
/// volume, split at obstacles) at one end or both, by overlap or across a gap of at most
/// kMaxMergeGap, and no other run: the run's end piece grows to take it in. What ListMerger
/// gives (on a list it keeps, as every stored one is) when no obstacle lies within the grown
/// piece: no cut moves, no piece appears; the grown piece sums its own and the added mass (both
/// wholly within it), then the gap's of eq. (8), as the merge sums them. Returns false, changing
/// nothing, in any other case.
bool extendFreeRun(const Volume& added, Volume* negative, std::uint32_t num_negative,
                   VolumeRun obstacles, float unit_mass) {
  // The first volume within kMaxMergeGap of the added one, and the run it belongs to. Those
  // before it end more than kMaxMergeGap below the added one.
  std::uint32_t first = 0;
  while (first < num_negative && !mustMerge(negative[first].top, added.bottom)) ++first;
  if (first == num_negative || !mustMerge(added.top, negative[first].bottom)) return false;
  std::uint32_t run_begin = first;
  while (run_begin > 0 && negative[run_begin - 1].top == negative[run_begin].bottom) --run_begin;
  std::uint32_t run_end = first + 1;
  while (run_end < num_negative && negative[run_end].bottom == negative[run_end - 1].top) {
    ++run_end;
  }
  const float run_bottom = negative[run_begin].bottom;
  const float run_top = negative[run_end - 1].top;
  const bool below = added.bottom < run_bottom;
  const bool above = added.top > run_top;
  if (!below && !above) return false;  // within the run: addCoveredFreeSpace's case
  Volume& piece = below ? negative[run_begin] : negative[run_end - 1];
  const float bottom = std::min(piece.bottom, added.bottom);
  const float top = std::max(piece.top, added.top);
  // Pieces of a run meet only at an obstacle's bottom or top, and each obstacle the run reaches
  // lies within it: heights that overlap no obstacle lie within one piece of the grown run.
  for (const Volume& obstacle : obstacles) {
    if (obstacle.bottom >= top) break;
    if (bottom < obstacle.top) return false;
  }
  // Growing upwards, it must not come within kMaxMergeGap of the next run (the one before lies
  // further below the added volume).
  if (run_end < num_negative && mustMerge(top, negative[run_end].bottom)) return false;
  double gap = 0.0;
  if (below && added.top < run_bottom) gap = static_cast<double>(run_bottom) - added.top;
  if (above && added.bottom > run_top) gap = static_cast<double>(added.bottom) - run_top;
  double mass = static_cast<double>(piece.mass) + added.mass;
  if (gap > 0.0) mass += gap * unit_mass;
  piece = {bottom, top, static_cast<float>(mass)};
  return true;
}

/// The commonest update of a column with hits once its surface has been seen: each hit within a
/// positive volume of its own, the free space (if any) within the negative list's runs, and a
/// negative list that the merge keeps as it is (ListMerger::keepsUnchanged). What ListMerger
/// gives then: no bound moves, no gap closes, no obstacle is newly reached; each volume gains the
/// mass that falls within it. Returns false, changing nothing, in any other case.
bool addWithinExistingVolumes(const CellVolumes& added, const detail::ColumnRef& existing,
                              const FreeSpaceRules& free_space_rules, ListMerger& merger) {
  Volume* positive = const_cast<Volume*>(existing.positive);
  Volume* negative = const_cast<Volume*>(existing.negative);
  // Visits the positive volume that holds each hit; false if one has none, or holds two hits
  // (three masses summed: their order would matter).
  auto for_each_holder = [&](auto&& visit) {
    std::uint32_t k = 0;
    bool holds_one = false;
    for (const Volume& hit : added.positive) {
      for (; k < existing.num_positive && positive[k].top < hit.top; ++k) holds_one = false;
      if (k == existing.num_positive || positive[k].bottom > hit.bottom || holds_one) return false;
      holds_one = true;
      visit(positive[k], hit);
    }
    return true;
  };
  if (!for_each_holder([](Volume&, const Volume&) {}) ||
      !merger.keepsUnchanged(VolumeRun(negative, existing.num_negative),
                             VolumeRun(positive, existing.num_positive), free_space_rules)) {
    return false;
  }
  if (!added.negative.empty() &&
      !addCoveredFreeSpace(added.negative, negative, existing.num_negative)) {
    return false;
  }
  for_each_holder([](Volume& holder, const Volume& hit) {
    holder.mass = static_cast<float>(static_cast<double>(holder.mass) + hit.mass);
  });
  return true;
}

/// The merge of a column's lists with new volumes that touch none of them (nor come within
/// kMaxMergeGap), where the merged free list is one the merge keeps (ListMerger::keepsUnchanged:
/// no free volume newly reaches an obstacle, or a hit one): both lists interleaved, each volume
/// its own source with its own mass, which is what ListMerger gives then. A new column's lists,
/// or a free volume or a hit at new heights, mostly. Returns false in any other case.
bool mergeWithoutContact(const detail::ColumnRef& existing, const CellVolumes& added,
                         const FreeSpaceRules& free_space_rules, ListMerger& merger,
                         CellVolumes& merged) {
  // Interleaves a list with its new volumes by bottom; consecutive volumes must be more than
  // kMaxMergeGap apart (or touch, where `may_touch`: pieces of a free volume cut at obstacles).
  auto interleave = [](const Volume* list, std::uint32_t count, const std::vector<Volume>& new_ones,
                       bool may_touch, std::vector<Volume>& out) {
    out.resize(count + new_ones.size());
    std::merge(list, list + count, new_ones.begin(), new_ones.end(), out.begin(),
               [](const Volume& a, const Volume& b) { return a.bottom < b.bottom; });
    for (std::size_t k = 1; k < out.size(); ++k) {
      if (mustMerge(out[k - 1].top, out[k].bottom) &&
          !(may_touch && out[k].bottom == out[k - 1].top)) {
        return false;
      }
    }
    return true;
  };
  return interleave(existing.positive, existing.num_positive, added.positive, false,
                    merged.positive) &&
         interleave(existing.negative, existing.num_negative, added.negative, true,
                    merged.negative) &&
         merger.keepsUnchanged(merged.negative, merged.positive, free_space_rules);
}

/// InsertionConfig::evidence_limit (`max_density`, in the tile's unit; infinite: none) on a
/// column's lists as the update leaves them.
void boundColumn(Volume* positive, std::size_t num_positive, Volume* negative,
                 std::size_t num_negative, double max_density, std::vector<double>& work) {
  if (!std::isinf(max_density)) {
    boundEvidence(positive, num_positive, negative, num_negative, max_density, work);
  }
}

/// boundColumn on a column changed in place.
void boundStoredColumn(const detail::ColumnRef& column, double max_density,
                       std::vector<double>& work) {
  boundColumn(const_cast<Volume*>(column.positive), column.num_positive,
              const_cast<Volume*>(column.negative), column.num_negative, max_density, work);
}

/// Merges what the scan saw in cell `local` of a tile (`hits`, and its scratches' free space)
/// into the cell's lists `existing`, in place where their lengths stay, else into the tile's
/// rewrite. Out of line: the loop over a tile's cells then keeps the commonest case's values in
/// registers.
[[gnu::noinline]] void updateColumn(unsigned local, HitRun hits, detail::ColumnRef existing,
                                    const ModelRules& rules, float unit_mass, double max_density,
                                    CellIndex origin, ColumnWork& work) {
  Volume* stored = const_cast<Volume*>(existing.positive);
  scanColumn(local, hits, detail::joinGapOf(rules), work);
  const std::vector<ScanInterval>* clip_at = &work.positive;
  if (work.column_remembered) {
    // Sec. V.B's scan groups: the latest scans' hits clip the free space as the scan's own do,
    // joined as a scan's own are (whichever scan saw them).
    work.clip_at.assign(work.positive.begin(), work.positive.end());
    work.recent_hits->append(*work.remembered_tile, local, work.hit_memory_scans, work.clip_at);
    std::sort(work.clip_at.begin(), work.clip_at.end(),
              [](const ScanInterval& a, const ScanInterval& b) { return a.bottom < b.bottom; });
    detail::joinSorted(work.clip_at, detail::joinGapOf(rules));
    clip_at = &work.clip_at;
  }
  addedVolumes(work.free, work.positive, *clip_at, rules, unit_mass, work.added);
  const FreeSpaceRules free_space_rules = detail::freeSpaceRulesOf(rules);
  if (work.added.positive.empty()
          ? addCoveredFreeSpace(work.added.negative, stored + existing.num_positive,
                                existing.num_negative) ||
                (work.added.negative.size() == 1 &&
                 extendFreeRun(work.added.negative[0], stored + existing.num_positive,
                               existing.num_negative,
                               VolumeRun(existing.positive, existing.num_positive), unit_mass))
          : addWithinExistingVolumes(work.added, existing, free_space_rules, work.merger)) {
    boundStoredColumn(existing, max_density, work.evidence_factors);
    return;
  }
  // A column without obstacles, before and after, is merged in one pass by ListMerger: no need
  // to try mergeWithoutContact first.
  const bool without_obstacles = existing.num_positive == 0 && work.added.positive.empty();
  if (without_obstacles ||
      !mergeWithoutContact(existing, work.added, free_space_rules, work.merger, work.merged)) {
    const VolumeRun existing_positive(existing.positive, existing.num_positive);
    if (work.added.positive.empty()) {
      work.merged.positive.assign(existing_positive.begin(), existing_positive.end());
    } else {
      work.merger.merge(existing_positive, work.added.positive, {}, {}, unit_mass,
                        work.merged.positive);
    }
    work.merger.merge(VolumeRun(existing.negative, existing.num_negative), work.added.negative,
                      work.merged.positive, free_space_rules, unit_mass, work.merged.negative);
  }
  const auto num_positive = static_cast<std::uint32_t>(work.merged.positive.size());
  const auto num_negative = static_cast<std::uint32_t>(work.merged.negative.size());
  boundColumn(work.merged.positive.data(), num_positive, work.merged.negative.data(), num_negative,
              max_density, work.evidence_factors);
  if (!existing.empty() && num_positive == existing.num_positive &&
      num_negative == existing.num_negative) {
    // Mostly every list keeps its length (new volumes merge into those there).
    std::copy(work.merged.positive.begin(), work.merged.positive.end(), stored);
    std::copy(work.merged.negative.begin(), work.merged.negative.end(), stored + num_positive);
    return;
  }
  work.rewrite.set(local, work.merged.positive, work.merged.negative);
  if (existing.empty() && num_positive + num_negative > 0)
    work.grown.extend(detail::cellInTile(origin, local));
}

/// Merges the new volumes of the scan's scratches into the columns of tile `key`.
MVOG_ALSO_FOR_POPCNT void updateTile(detail::TileBlock& tile, std::uint64_t key,
                                     const std::vector<detail::ScanScratch>& scratches,
                                     const ModelRules& rules, float unit_mass, double max_density,
                                     double rescale, std::int32_t exponent, std::uint64_t revision,
                                     ColumnWork& work) {
  gatherTile(key, scratches, work);
  // The tile was written before a decay step: bring its masses to the current unit first.
  if (rescale != 1.0) tile.scaleMasses(rescale, exponent);
  work.rewrite.clear();
  const CellIndex origin = detail::tileOrigin(key);
  const bool per_scan = rules.mass_counting == MassCounting::kPerScan;
  HitCursor hit_cursor(work.hits);
  // With one thread's part, a cell's free space may be one interval read from it directly;
  // not in a column where InsertionConfig::hit_memory_scans's recent hits may clip it
  // (updateColumn).
  work.remembered_tile =
      work.recent_hits != nullptr ? work.recent_hits->tile(key, work.hit_memory_scans) : nullptr;
  const auto* only_part = work.parts.size() == 1 ? &work.parts[0] : nullptr;
  const detail::TileBlock::Layout layout(tile);
  for (std::size_t word = 0; word < std::size(work.reached); ++word) {
    for (std::uint64_t bits = work.reached[word]; bits != 0; bits &= bits - 1) {
      const auto local = static_cast<unsigned>(64 * word + detail::lowestBit(bits));
      const HitRun hits = hit_cursor.next(local);
      const detail::ColumnRef existing = layout.column(local);
      work.column_remembered =
          work.remembered_tile != nullptr && work.remembered_tile->mayHold(local);
      ScanInterval single;
      if (hits.empty() && only_part != nullptr && !work.column_remembered &&
          only_part->first->singleFree(*only_part->second, local, single)) {
        // The commonest cases without a vector in between: one free interval, no hit, changed
        // in the tile's own storage, or a cell's first volume.
        const Volume added{single.bottom, single.top,
                           massOf(single, single.bottom, single.top, per_scan, unit_mass)};
        if (existing.empty()) {
          // No evidence limit to apply: a cell's first volume holds one scan (density 1, the
          // limit being at least 1; with per-reading masses there is no limit).
          // What the merge makes of one free volume and empty lists: that volume (a scan's free
          // interval is at least kMinVolumeHeight high, so no rule cuts it, and its mass, a sum
          // of heights times the unit, is never -0, which the merge's 0.0 + mass would make +0).
          work.rewrite.set(local, {nullptr, 0, &added, 1});
          work.grown.extend(detail::cellInTile(origin, local));
          continue;
        }
        Volume* negative = const_cast<Volume*>(existing.negative);
        if (addCoveredFreeSpace(VolumeRun(&added, 1), negative, existing.num_negative)) {
          boundStoredColumn(existing, max_density, work.evidence_factors);
          continue;
        }
      }
      updateColumn(local, hits, existing, rules, unit_mass, max_density, origin, work);
    }
  }
  if (work.rewrite.empty()) {
    tile.setModifiedRevision(revision);
    return;
  }
  // Some list changed its length: the tile is built anew, its other cells copied.
  tile = work.rewrite.apply(tile, exponent, revision);
}

}  // namespace

InsertionResult Map::insertScan(const Scan& scan, const InsertionConfig& config) {
  if (own_update_ == nullptr) own_update_ = std::make_unique<ScanUpdate>();
  own_update_->prepare(scan, config_, config);
  return apply(*own_update_);
}

InsertionResult Map::insertDepthImage(const DepthFrame& frame, const InsertionConfig& config) {
  if (own_update_ == nullptr) own_update_ = std::make_unique<ScanUpdate>();
  own_update_->prepare(frame, config_, config);
  return apply(*own_update_);
}

InsertionResult Map::insertReading(const Eigen::Vector3d& origin, const Eigen::Vector3d& end,
                                   ReadingKind kind, const InsertionConfig& config) {
  Scan scan;
  scan.origin = origin;
  (kind == ReadingKind::kObstacle ? scan.hits : scan.out_of_range).push_back(end.cast<float>());
  return insertScan(scan, config);
}

InsertionResult Map::apply(ScanUpdate& update) {
  ScanUpdate::Impl& impl = *update.impl_;
  if (!update.preparedFor(config_)) {
    throw ConfigError("update: prepared for another map configuration");
  }
  std::vector<std::uint64_t> keys;
  for (const detail::ScanScratch& scratch : impl.scratches) {
    for (const auto& [key, tile] : scratch.tiles()) {
      if (!tile->reachedNone()) keys.push_back(key);
    }
  }
  // A scan that inserts no reading (none given, or every one rejected) changes nothing: not the
  // map, nor the hits kept (a burst of bad messages does not empty them).
  if (impl.result.inserted() == 0) return impl.result;
  // InsertionConfig::hit_memory_scans: the latest scans' hits clip this one's free space too; a
  // scan outside hit_memory_scope is a group of its own (Sec. V.B), and the hits kept are
  // forgotten.
  const int hit_memory_scans =
      impl.joins_hit_memory ? impl.insertion.appliedHitMemoryScans(config_.rules) : 0;
  std::unique_ptr<detail::RecentHits>& recent_hits = storage_->recent_hits;
  if (hit_memory_scans == 0) {
    recent_hits.reset();
  } else if (recent_hits == nullptr) {
    recent_hits = std::make_unique<detail::RecentHits>();
  }
  if (keys.empty()) {
    if (recent_hits != nullptr) recent_hits->endScan(impl.scratches, hit_memory_scans);
    return impl.result;
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  ++revision_;
  // Every tile the scan reaches exists before the threads start: they then only write the
  // tiles they are given, and never change the index.
  std::vector<detail::TileBlock*> tiles(keys.size());
  for (std::size_t k = 0; k < keys.size(); ++k) tiles[k] = &storage_->tiles[keys[k]];

  const float unit_mass = static_cast<float>(1.0 / mass_unit_);
  // InsertionConfig::evidence_limit in the unit masses are stored in (a scan's density 1 is
  // unit_mass).
  const double max_density = impl.insertion.appliedEvidenceLimit(impl.map_config.rules) * unit_mass;
  const auto exponent = static_cast<std::int32_t>(unit_exponent_);
  const std::size_t num_threads = impl.scratches.size();
  std::vector<ColumnWork>& work = impl.column_work;
  if (work.size() < num_threads) work.resize(num_threads);
  for (ColumnWork& w : work) {
    w.grown = kNoCells;
    w.recent_hits = recent_hits.get();
    w.hit_memory_scans = hit_memory_scans;
  }
  auto update_tile = [&](std::size_t worker, std::size_t k) {
    detail::TileBlock& tile = *tiles[k];
    const double rescale = tile.empty() ? 1.0 : rescaleOf(tile.exponent());
    updateTile(tile, keys[k], impl.scratches, config_.rules, unit_mass, max_density, rescale,
               exponent, revision_, work[worker]);
  };
  if (detail::ThreadPool* pool = impl.threads(num_threads)) {
    pool->run(keys.size(), update_tile);
  } else {
    for (std::size_t k = 0; k < keys.size(); ++k) update_tile(0, k);
  }
  for (std::size_t k = 0; k < keys.size(); ++k) {
    if (tiles[k]->empty()) storage_->tiles.erase(keys[k]);
  }
  for (const ColumnWork& w : work) bounds_.extend(w.grown);
  if (recent_hits != nullptr) recent_hits->endScan(impl.scratches, hit_memory_scans);
  return impl.result;
}

}  // namespace mvog
