#pragma once

#include <cstddef>
#include <vector>

#include "mvog/volume.h"

namespace mvog {

/// boundEvidence for a volume that no volume of the other list overlaps: its mass is at most
/// max_density times its height (what the factor max_density / density gives, without a
/// division).
inline void boundAlone(Volume& volume, double max_density) {
  const double max_mass = max_density * (static_cast<double>(volume.top) - volume.bottom);
  if (volume.mass > max_mass) volume.mass = static_cast<float>(max_mass);
}

/// boundEvidence for a column with both lists.
void boundEvidenceOfBoth(Volume* positive, std::size_t num_positive, Volume* negative,
                         std::size_t num_negative, double max_density, std::vector<double>& work);

/// InsertionConfig::evidence_limit on one column's lists (`positive`, `negative`: sorted, each
/// satisfying Sec. III-A) after an update: a volume whose density and the highest density of
/// the other list's volumes overlapping it (by a positive height) sum to more than `max_density`
/// has its mass multiplied by max_density / that sum (one that nothing overlaps: boundAlone).
/// Every factor is found from the densities before any mass changes, so that two volumes
/// overlapping only each other are scaled alike and p of eq. (9) between them stays. `work` is
/// working memory. Inline for a column of one list (a free column's commonest update).
inline void boundEvidence(Volume* positive, std::size_t num_positive, Volume* negative,
                          std::size_t num_negative, double max_density, std::vector<double>& work) {
  if (num_positive != 0 && num_negative != 0) {
    boundEvidenceOfBoth(positive, num_positive, negative, num_negative, max_density, work);
    return;
  }
  Volume* list = num_positive == 0 ? negative : positive;
  for (std::size_t k = 0; k < num_positive + num_negative; ++k) boundAlone(list[k], max_density);
}

/// A read-only run of volumes (a list, or new volumes for one).
struct VolumeRun {
  const Volume* data = nullptr;
  std::size_t size = 0;

  VolumeRun() = default;
  VolumeRun(const Volume* volumes, std::size_t count) : data(volumes), size(count) {}
  VolumeRun(const std::vector<Volume>& volumes) : data(volumes.data()), size(volumes.size()) {}
  const Volume* begin() const { return data; }
  const Volume* end() const { return data + size; }
};

/// How ListMerger treats a negative list next to the column's positive volumes (ModelRules).
struct FreeSpaceRules {
  /// ModelRules::split_free_space_at_obstacles.
  bool split_at_obstacles = false;
  /// With ModelRules::clip_free_space_at_hits: a gap that eq. (8) closes gets no mass where a
  /// positive volume covers it (the space was seen occupied, not assumed free).
  bool no_gap_mass_over_obstacles = false;
};

/// Sec. III-B.3, the constraint application of Fig. 2, for one list of one column: the volumes
/// it receives at once (one scan's, or another map's) are merged with the volumes already there,
/// overlapping ones (eq. 7: union, masses summed; touching volumes overlap) and those less than
/// kMaxMergeGap apart (eq. 8: the gap is added at density 1, `unit_mass` per unit height). The
/// result depends on the set of volumes only, not on their order.
///
/// `existing` satisfies Sec. III-A (checkColumn); `added` holds volumes at least kMinVolumeHeight
/// high (eq. 6 already applied), in any order, overlapping or not. Masses are in one unit.
///
/// Merging a negative list, `obstacles` is the column's positive list (as this same update left
/// it) and `rules` say how it matters; merging a positive list, both are empty. With
/// `split_at_obstacles`, the merged negative volumes are cut at the bottom and top of every
/// positive volume they overlap, and each piece gets the mass that fell within its heights (a
/// source spanning several pieces shares its mass in proportion to their overlap, as its density
/// is uniform): within a positive volume's heights the negative list holds one piece spanning
/// exactly those heights (Sec. V.C: the free space seen within an obstacle is not averaged with
/// the free column around it); a piece outside them lower than kMinVolumeHeight joins the
/// obstacle's piece next to it.
class ListMerger {
 public:
  /// Writes the merged list to `out` (sorted, satisfying Sec. III-A).
  void merge(VolumeRun existing, VolumeRun added, VolumeRun obstacles, FreeSpaceRules rules,
             float unit_mass, std::vector<Volume>& out);

  /// Whether merge(negative, {}, obstacles, rules, ...) would return `negative` (which satisfies
  /// Sec. III-A) itself, bit for bit: each run of touching volumes is cut as the merge cuts it.
  /// Cheaper than the merge: a column whose update only adds mass within its volumes is then
  /// changed in place (the scan update's commonest case).
  bool keepsUnchanged(VolumeRun negative, VolumeRun obstacles, FreeSpaceRules rules);

  /// Makes `negative` what merge(negative, {}, obstacles, rules, ...) returns: with
  /// `split_at_obstacles`, a volume reaching into an obstacle is cut at its bottom and top (Sec.
  /// III-A allows it whole), pieces that touch where no obstacle is join. `negative` is a list
  /// of Sec. III-A, or one whose obstacles were removed (its volumes touch or lie more than
  /// kMaxMergeGap apart). Every list a map stores is one the merge keeps, which the in-place
  /// updates of insertion suppose.
  void cutAsTheMergeDoes(std::vector<Volume>& negative, VolumeRun obstacles, FreeSpaceRules rules);

 private:
  /// A volume whose mass contributes to the merged list (its density is uniform over it).
  struct Source {
    float bottom;
    float top;
    double mass;
  };
  /// A run of the merged list before it is cut, with the obstacles [first, end) of inside_ in it,
  /// and its sources and gaps (no other source or gap reaches into it).
  struct Component {
    float bottom;
    float top;
    std::size_t first_inside;
    std::size_t end_inside;
    std::size_t first_source;
    std::size_t end_source;
    std::size_t first_gap;
    std::size_t end_gap;
  };
  /// Sorted by every field, so that the sums of the merge run in an order the set alone decides.
  static bool sourceBefore(const Source& a, const Source& b) {
    return a.bottom < b.bottom ||
           (a.bottom == b.bottom && (a.top < b.top || (a.top == b.top && a.mass < b.mass)));
  }
  /// merge() of a list without obstacles (a positive list, or a negative one in a column that
  /// holds none), the added volumes sorted in added_.
  void mergeWithoutObstacles(VolumeRun existing, float unit_mass, std::vector<Volume>& out);
  void sweep();
  /// Appends the pieces of the component [bottom, top] cut at the obstacles within it.
  static void cutAtObstacles(float bottom, float top, const Volume* first_obstacle,
                             const Volume* end_obstacle, std::vector<Volume>& out);
  void addPieces(const Component& component, std::vector<Volume>& out) const;
  /// The mass of `component`'s sources and gaps within [bottom, top].
  double massWithin(const Component& component, float bottom, float top) const;

  std::vector<Source> sources_;        // sorted by (bottom, top, mass)
  std::vector<Source> added_;          // the added volumes, sorted
  std::vector<Source> gaps_;           // gaps closed by eq. (8), upwards
  std::vector<Volume> inside_;         // the obstacles the free space reaches into
  std::vector<Volume> reached_;        // the same, as found by the last sweep
  std::vector<Component> components_;  // upwards
  std::vector<Volume> pieces_;         // keepsUnchanged's cut of one run
  std::vector<Volume> cut_;            // cutAsTheMergeDoes's result
  std::vector<double> gap_masses_;     // mergeWithoutObstacles's gaps of one piece
};

}  // namespace mvog
