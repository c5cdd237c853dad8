// The cache's counters to and from CacheStatsResponse, through the one list of them
// (kCacheStatsCounters): each counter goes to the field of its name, found once by reflection.
#include <array>
#include <cassert>
#include <cstddef>

#include "google/protobuf/descriptor.h"
#include "inscribe/wire/convert.h"

namespace inscribe::wire {
namespace {

constexpr std::size_t kCounters = std::size(kCacheStatsCounters);

// The CacheStatsResponse field of each counter, in kCacheStatsCounters' order. Every name is a
// field there (tests/wire/convert_cache_stats_test.cpp checks the list against the message).
const std::array<const google::protobuf::FieldDescriptor*, kCounters>& CounterFields() {
  static const std::array<const google::protobuf::FieldDescriptor*, kCounters> fields = [] {
    std::array<const google::protobuf::FieldDescriptor*, kCounters> found{};
    const google::protobuf::Descriptor* message = v1::CacheStatsResponse::descriptor();
    for (std::size_t i = 0; i < kCounters; ++i) {
      found[i] = message->FindFieldByName(kCacheStatsCounters[i].name);
      assert(found[i] != nullptr &&
             found[i]->type() == google::protobuf::FieldDescriptor::TYPE_INT64);
    }
    return found;
  }();
  return fields;
}

}  // namespace

void CacheStatsToProto(const CacheStats& stats, v1::CacheStatsResponse* out) {
  const google::protobuf::Reflection* reflection = out->GetReflection();
  for (std::size_t i = 0; i < kCounters; ++i) {
    reflection->SetInt64(out, CounterFields()[i], stats.*kCacheStatsCounters[i].value);
  }
}

CacheStats CacheStatsFromProto(const v1::CacheStatsResponse& response) {
  const google::protobuf::Reflection* reflection = response.GetReflection();
  CacheStats stats;
  for (std::size_t i = 0; i < kCounters; ++i) {
    stats.*kCacheStatsCounters[i].value = reflection->GetInt64(response, CounterFields()[i]);
  }
  return stats;
}

}  // namespace inscribe::wire
