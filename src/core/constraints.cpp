#include "mvog/constraints.h"

#include <algorithm>

namespace mvog {

namespace {

/// Length of [bottom, top] that the sorted, disjoint `volumes` cover.
double coveredLength(float bottom, float top, VolumeRun volumes) {
  double covered = 0.0;
  for (const Volume& v : volumes) {
    if (v.bottom >= top) break;
    const double overlap = static_cast<double>(std::min(top, v.top)) - std::max(bottom, v.bottom);
    if (overlap > 0.0) covered += overlap;
  }
  return covered;
}

bool overlaps(float bottom, float top, const Volume& v) { return v.bottom < top && bottom < v.top; }

}  // namespace

void ListMerger::merge(VolumeRun existing, VolumeRun added, VolumeRun obstacles,
                       FreeSpaceRules rules, float unit_mass, std::vector<Volume>& out) {
  out.clear();
  sources_.clear();
  inside_.clear();
  // The existing list is sorted; the added volumes mostly are too (one scan's are).
  added_.clear();
  for (const Volume& v : added) added_.push_back({v.bottom, v.top, v.mass});
  if (!std::is_sorted(added_.begin(), added_.end(), sourceBefore)) {
    std::sort(added_.begin(), added_.end(), sourceBefore);
  }
  if (obstacles.size == 0) {
    mergeWithoutObstacles(existing, unit_mass, out);
    return;
  }
  std::size_t next_added = 0;
  for (const Volume& v : existing) {
    const Source s{v.bottom, v.top, v.mass};
    while (next_added < added_.size() && sourceBefore(added_[next_added], s)) {
      sources_.push_back(added_[next_added++]);
    }
    sources_.push_back(s);
  }
  sources_.insert(sources_.end(), added_.begin() + static_cast<std::ptrdiff_t>(next_added),
                  added_.end());
  if (sources_.empty()) return;
  // With splitting, the obstacles that the free space reaches into join it (their heights are
  // its pieces), which may join runs that were apart: sweep until no new obstacle is reached.
  for (;;) {
    sweep();
    if (!rules.split_at_obstacles || obstacles.size == 0) break;
    reached_.clear();
    std::size_t c = 0;
    for (const Volume& obstacle : obstacles) {
      while (c < components_.size() && components_[c].top <= obstacle.bottom) ++c;
      if (c < components_.size() && overlaps(components_[c].bottom, components_[c].top, obstacle)) {
        reached_.push_back(obstacle);
      }
    }
    if (reached_.size() == inside_.size()) break;  // inside_ is a subset of reached_
    inside_.swap(reached_);
  }
  for (Source& gap : gaps_) {
    double free_length = static_cast<double>(gap.top) - gap.bottom;
    if (rules.no_gap_mass_over_obstacles)
      free_length -= coveredLength(gap.bottom, gap.top, obstacles);
    gap.mass = free_length * unit_mass;
  }
  for (const Component& component : components_) addPieces(component, out);
}

void ListMerger::mergeWithoutObstacles(VolumeRun existing, float unit_mass,
                                       std::vector<Volume>& out) {
  // What sweep() and addPieces() give when there are no obstacles: each component is one piece,
  // whose mass sums, from 0.0, its sources in their order, then its gaps upwards (as massWithin
  // does, so that even a mass of -0 comes out as it does there). In one pass, without the
  // sources' list.
  auto source_of = [](const Volume& v) { return Source{v.bottom, v.top, v.mass}; };
  const Volume* next_existing = existing.begin();
  const Source* next_added = added_.data();
  const Source* const end_added = next_added + added_.size();
  out.reserve(existing.size + added_.size());
  Source piece{0.0f, 0.0f, 0.0};
  bool open = false;
  auto close_piece = [&] {
    double mass = piece.mass;
    for (double gap_mass : gap_masses_) mass += gap_mass;
    out.push_back({piece.bottom, piece.top, static_cast<float>(mass)});
    gap_masses_.clear();
  };
  gap_masses_.clear();
  while (next_existing != existing.end() || next_added != end_added) {
    const bool take_added =
        next_added != end_added &&
        (next_existing == existing.end() || sourceBefore(*next_added, source_of(*next_existing)));
    const Source s = take_added ? *next_added++ : source_of(*next_existing++);
    if (open && mustMerge(piece.top, s.bottom)) {
      // Eq. (8): the gap's free length at density 1 (no obstacle covers any of it).
      if (s.bottom > piece.top) {
        gap_masses_.push_back((static_cast<double>(s.bottom) - piece.top) * unit_mass);
      }
      piece.top = std::max(piece.top, s.top);
      piece.mass += s.mass;
      continue;
    }
    if (open) close_piece();
    piece = {s.bottom, s.top, 0.0 + s.mass};
    open = true;
  }
  if (open) close_piece();
}

void ListMerger::sweep() {
  // Upwards over the sources and the obstacles joined: overlaps join (eq. 7), gaps of at most
  // kMaxMergeGap are closed (eq. 8). Sorted by bottom, no later volume can reach into a gap once
  // the sweep has passed it. A gap eq. (8) fills is a stretch between sources that no source
  // covers, at most kMaxMergeGap high (an obstacle bridging a wider one adds no free mass).
  components_.clear();
  gaps_.clear();
  std::size_t next_source = 0;
  std::size_t next_inside = 0;
  float sources_top = 0.0f;  // top of the sources of the current component so far
  bool has_source = false;
  while (next_source < sources_.size() || next_inside < inside_.size()) {
    const bool take_inside = next_inside < inside_.size() &&
                             (next_source == sources_.size() ||
                              inside_[next_inside].bottom < sources_[next_source].bottom);
    const float bottom = take_inside ? inside_[next_inside].bottom : sources_[next_source].bottom;
    const float top = take_inside ? inside_[next_inside].top : sources_[next_source].top;
    if (components_.empty() || !mustMerge(components_.back().top, bottom)) {
      components_.push_back({bottom, top, next_inside, next_inside, next_source, next_source,
                             gaps_.size(), gaps_.size()});
      has_source = false;
    } else {
      components_.back().top = std::max(components_.back().top, top);
    }
    if (take_inside) {
      components_.back().end_inside = ++next_inside;
      continue;
    }
    if (has_source && bottom > sources_top && mustMerge(sources_top, bottom)) {
      gaps_.push_back({sources_top, bottom, 0.0});
      components_.back().end_gap = gaps_.size();
    }
    sources_top = has_source ? std::max(sources_top, top) : top;
    has_source = true;
    components_.back().end_source = ++next_source;
  }
}

void ListMerger::cutAtObstacles(float bottom, float top, const Volume* first_obstacle,
                                const Volume* end_obstacle, std::vector<Volume>& out) {
  if (first_obstacle == end_obstacle) {
    out.push_back({bottom, top, 0.0f});
    return;
  }
  // Cut at the obstacles' heights: outside, inside, outside, ... Obstacles lie more than
  // kMaxMergeGap apart, so only a first or last outside piece can be too low: it joins its
  // obstacle's piece.
  float below = bottom;
  for (const Volume* obstacle = first_obstacle; obstacle != end_obstacle; ++obstacle) {
    if (obstacle->bottom > below &&
        (obstacle != first_obstacle || obstacle->bottom - below >= kMinVolumeHeight)) {
      out.push_back({below, obstacle->bottom, 0.0f});
      below = obstacle->bottom;
    }
    out.push_back({below, obstacle->top, 0.0f});
    below = obstacle->top;
  }
  if (below < top) {
    if (top - below < kMinVolumeHeight) {
      out.back().top = top;
    } else {
      out.push_back({below, top, 0.0f});
    }
  }
}

void ListMerger::addPieces(const Component& component, std::vector<Volume>& out) const {
  const std::size_t first_piece = out.size();
  cutAtObstacles(component.bottom, component.top, inside_.data() + component.first_inside,
                 inside_.data() + component.end_inside, out);
  for (std::size_t k = first_piece; k < out.size(); ++k) {
    out[k].mass = static_cast<float>(massWithin(component, out[k].bottom, out[k].top));
  }
}

bool ListMerger::keepsUnchanged(VolumeRun negative, VolumeRun obstacles, FreeSpaceRules rules) {
  if (!rules.split_at_obstacles) obstacles = {};
  std::size_t next_obstacle = 0;
  for (std::size_t first = 0; first < negative.size;) {
    // A run of volumes the sweep joins into one component: in a list that satisfies Sec. III-A,
    // volumes that touch (no gap of kMaxMergeGap or less lies between two).
    std::size_t end = first + 1;
    while (end < negative.size && negative.data[end].bottom == negative.data[end - 1].top) ++end;
    const float bottom = negative.data[first].bottom;
    const float top = negative.data[end - 1].top;
    // The obstacles the run reaches into must lie within it, else they widen its component.
    while (next_obstacle < obstacles.size && obstacles.data[next_obstacle].top <= bottom) {
      ++next_obstacle;
    }
    std::size_t end_obstacle = next_obstacle;
    for (; end_obstacle < obstacles.size && obstacles.data[end_obstacle].bottom < top;
         ++end_obstacle) {
      if (obstacles.data[end_obstacle].bottom < bottom || obstacles.data[end_obstacle].top > top) {
        return false;
      }
    }
    // And the run's volumes must be the pieces the merge would cut: each is then one source,
    // whose mass it keeps.
    pieces_.clear();
    cutAtObstacles(bottom, top, obstacles.data + next_obstacle, obstacles.data + end_obstacle,
                   pieces_);
    const auto same_bounds = [](const Volume& a, const Volume& b) {
      return a.bottom == b.bottom && a.top == b.top;
    };
    if (!std::equal(pieces_.begin(), pieces_.end(), negative.data + first, negative.data + end,
                    same_bounds)) {
      return false;
    }
    next_obstacle = end_obstacle;
    first = end;
  }
  return true;
}

namespace {

/// The factor of boundEvidence for a volume of density `density` whose densest overlapping
/// volume of the other list has density `densest`; 0 where that is 0 (the volume is bounded
/// alone, boundAlone).
double evidenceFactor(double density, double densest, double max_density) {
  if (densest == 0.0) return 0.0;
  const double sum = density + densest;
  return sum > max_density ? max_density / sum : 1.0;
}

/// Writes to factors[k] the factor of list[k] against the volumes of `other`, whose densities
/// are other_density[0, other_size).
void evidenceFactors(const Volume* list, const double* density, std::size_t size,
                     const Volume* other, const double* other_density, std::size_t other_size,
                     double max_density, double* factors) {
  std::size_t first = 0;  // the first volume of `other` that may overlap the current one
  for (std::size_t k = 0; k < size; ++k) {
    while (first < other_size && other[first].top <= list[k].bottom) ++first;
    double densest = 0.0;
    for (std::size_t j = first; j < other_size && other[j].bottom < list[k].top; ++j) {
      densest = std::max(densest, other_density[j]);
    }
    factors[k] = evidenceFactor(density[k], densest, max_density);
  }
}

/// Scales `volume`'s mass by `factor`, or bounds it alone where the factor is 0 (nothing of the
/// other list overlaps it).
void scaleMass(Volume& volume, double factor, double max_density) {
  if (factor == 0.0) {
    boundAlone(volume, max_density);
  } else if (factor != 1.0) {
    volume.mass = static_cast<float>(volume.mass * factor);
  }
}

}  // namespace

void boundEvidenceOfBoth(Volume* positive, std::size_t num_positive, Volume* negative,
                         std::size_t num_negative, double max_density, std::vector<double>& work) {
  if (num_positive == 1 && num_negative == 1) {
    // A column of one obstacle and one free volume (a 2D laser's wall, mostly): no memory.
    Volume& p = positive[0];
    Volume& n = negative[0];
    if (!(p.bottom < n.top && n.bottom < p.top)) {
      boundAlone(p, max_density);
      boundAlone(n, max_density);
      return;
    }
    const double p_density = p.density();
    const double n_density = n.density();
    scaleMass(p, evidenceFactor(p_density, n_density, max_density), max_density);
    scaleMass(n, evidenceFactor(n_density, p_density, max_density), max_density);
    return;
  }
  // Every density once, then every factor from them, then the masses.
  const std::size_t size = num_positive + num_negative;
  work.resize(2 * size);
  double* density = work.data();
  double* factor = density + size;
  for (std::size_t k = 0; k < num_positive; ++k) density[k] = positive[k].density();
  for (std::size_t k = 0; k < num_negative; ++k) density[num_positive + k] = negative[k].density();
  evidenceFactors(positive, density, num_positive, negative, density + num_positive, num_negative,
                  max_density, factor);
  evidenceFactors(negative, density + num_positive, num_negative, positive, density, num_positive,
                  max_density, factor + num_positive);
  for (std::size_t k = 0; k < num_positive; ++k) scaleMass(positive[k], factor[k], max_density);
  for (std::size_t k = 0; k < num_negative; ++k) {
    scaleMass(negative[k], factor[num_positive + k], max_density);
  }
}

void ListMerger::cutAsTheMergeDoes(std::vector<Volume>& negative, VolumeRun obstacles,
                                   FreeSpaceRules rules) {
  if (keepsUnchanged(negative, obstacles, rules)) return;
  // Nothing is added and the volumes touch or lie more than kMaxMergeGap apart: no gap closes,
  // so no gap mass is needed.
  merge(negative, {}, obstacles, rules, 0.0f, cut_);
  negative.swap(cut_);
}

double ListMerger::massWithin(const Component& component, float bottom, float top) const {
  // Only the component's own sources and gaps: the others lie more than kMaxMergeGap away and
  // would add nothing, while a column of many components would make the merge quadratic.
  double mass = 0.0;
  auto add_within = [&](const std::vector<Source>& list, std::size_t first, std::size_t end) {
    for (std::size_t k = first; k < end; ++k) {
      const Source& s = list[k];
      if (s.bottom >= top) break;  // the list runs upwards
      if (s.bottom >= bottom && s.top <= top) {
        mass += s.mass;
        continue;
      }
      const double overlap = static_cast<double>(std::min(top, s.top)) - std::max(bottom, s.bottom);
      if (overlap > 0.0) mass += s.mass * overlap / (static_cast<double>(s.top) - s.bottom);
    }
  };
  add_within(sources_, component.first_source, component.end_source);
  add_within(gaps_, component.first_gap, component.end_gap);
  return mass;
}

}  // namespace mvog
