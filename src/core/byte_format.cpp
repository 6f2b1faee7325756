#include "byte_format.h"

#include "tile_block.h"

namespace mvog {
namespace detail {
namespace {

constexpr std::uint32_t kClipBit = 1u << 0;
constexpr std::uint32_t kPerScanBit = 1u << 1;
constexpr std::uint32_t kSplitBit = 1u << 2;
static_assert((kClipBit | kPerScanBit | kSplitBit) == kAllRuleBits, "every rule has its bit");

}  // namespace

std::uint32_t rulesBits(const ModelRules& rules) {
  return (rules.clip_free_space_at_hits ? kClipBit : 0u) |
         (rules.mass_counting == MassCounting::kPerScan ? kPerScanBit : 0u) |
         (rules.split_free_space_at_obstacles ? kSplitBit : 0u);
}

ModelRules rulesOf(std::uint32_t bits) {
  ModelRules rules = ModelRules::paper();
  rules.clip_free_space_at_hits = (bits & kClipBit) != 0;
  rules.mass_counting =
      (bits & kPerScanBit) != 0 ? MassCounting::kPerScan : MassCounting::kPerReading;
  rules.split_free_space_at_obstacles = (bits & kSplitBit) != 0;
  return rules;
}

void writeCell(Writer& writer, const CellIndex& cell, const Volume* positive,
               std::uint32_t num_positive, const Volume* negative, std::uint32_t num_negative) {
  writer.i32(cell.x);
  writer.i32(cell.y);
  writer.u32(num_positive);
  writer.u32(num_negative);
  auto write = [&](const Volume* list, std::uint32_t count) {
    for (const Volume* v = list; v != list + count; ++v) {
      writer.f32(v->bottom);
      writer.f32(v->top);
      writer.f32(v->mass);
    }
  };
  write(positive, num_positive);
  write(negative, num_negative);
}

std::string readCell(Reader& reader, std::uint64_t volumes_left, CellIndex& cell,
                     CellVolumes& volumes) {
  cell = CellIndex{reader.i32(), reader.i32()};
  const std::uint64_t num_positive = reader.u32();
  const std::uint64_t num_negative = reader.u32();
  // Every cell of a file or an update passes here: its name is made only for a message.
  if (num_positive + num_negative == 0) return cellName(cell).append(" holds no volume");
  if (num_positive + num_negative > volumes_left) {
    return cellName(cell).append(" holds more volumes than the header counts");
  }
  volumes.positive.resize(num_positive);
  volumes.negative.resize(num_negative);
  for (std::vector<Volume>* list : {&volumes.positive, &volumes.negative}) {
    for (Volume& v : *list) v = Volume{reader.f32(), reader.f32(), reader.f32()};
  }
  return {};
}

}  // namespace detail
}  // namespace mvog
