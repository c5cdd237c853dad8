// The cache's counters on the wire: the one list (kCacheStatsCounters) names every field of
// CacheStatsResponse, in its order, and the conversions put each counter in its own field,
// checked against the generated accessors (which share no code with the list).
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <string>

#include "google/protobuf/descriptor.h"
#include "inscribe/wire/cache_stats.h"
#include "inscribe/wire/convert.h"

namespace inscribe::wire {
namespace {

TEST(CacheStatsConvert, TheListIsEveryFieldOfTheMessageInItsOrder) {
  const google::protobuf::Descriptor* message = v1::CacheStatsResponse::descriptor();
  ASSERT_EQ(static_cast<std::size_t>(message->field_count()), std::size(kCacheStatsCounters));
  for (int i = 0; i < message->field_count(); ++i) {
    const google::protobuf::FieldDescriptor* field = message->field(i);
    EXPECT_EQ(field->name(), kCacheStatsCounters[i].name) << "field " << i;
    EXPECT_EQ(field->type(), google::protobuf::FieldDescriptor::TYPE_INT64) << field->name();
  }
}

TEST(CacheStatsConvert, EveryCounterGoesToItsOwnFieldAndBack) {
  CacheStats stats;
  stats.entries = 1;
  stats.bytes = 2;
  stats.memory_hits = 3;
  stats.disk_hits = 4;
  stats.hits = 5;
  stats.misses = 6;
  stats.computations = 7;
  stats.joined = 8;
  stats.evictions = 9;
  stats.disk_entries = 10;
  stats.disk_bytes = 11;
  stats.disk_errors = 12;
  stats.shared_hits = 13;
  stats.shared_misses = 14;
  stats.shared_errors = 15;
  stats.shared_writes = 16;
  stats.shared_write_errors = 17;
  stats.shared_skipped = 18;
  stats.shared_corrupt = 19;
  stats.shared_available = 20;
  stats.disk_write_errors = 21;
  stats.disk_writes_skipped = 22;
  stats.disk_available = 23;
  stats.disk_bytes_limit = std::int64_t{1} << 40;  // past 32 bits
  stats.disk_evictions = 25;
  stats.disk_evicted_bytes = 26;
  stats.disk_writes_too_large = 27;

  v1::CacheStatsResponse wire;
  CacheStatsToProto(stats, &wire);
  EXPECT_EQ(wire.entries(), 1);
  EXPECT_EQ(wire.bytes(), 2);
  EXPECT_EQ(wire.memory_hits(), 3);
  EXPECT_EQ(wire.disk_hits(), 4);
  EXPECT_EQ(wire.hits(), 5);
  EXPECT_EQ(wire.misses(), 6);
  EXPECT_EQ(wire.computations(), 7);
  EXPECT_EQ(wire.joined(), 8);
  EXPECT_EQ(wire.evictions(), 9);
  EXPECT_EQ(wire.disk_entries(), 10);
  EXPECT_EQ(wire.disk_bytes(), 11);
  EXPECT_EQ(wire.disk_errors(), 12);
  EXPECT_EQ(wire.shared_hits(), 13);
  EXPECT_EQ(wire.shared_misses(), 14);
  EXPECT_EQ(wire.shared_errors(), 15);
  EXPECT_EQ(wire.shared_writes(), 16);
  EXPECT_EQ(wire.shared_write_errors(), 17);
  EXPECT_EQ(wire.shared_skipped(), 18);
  EXPECT_EQ(wire.shared_corrupt(), 19);
  EXPECT_EQ(wire.shared_available(), 20);
  EXPECT_EQ(wire.disk_write_errors(), 21);
  EXPECT_EQ(wire.disk_writes_skipped(), 22);
  EXPECT_EQ(wire.disk_available(), 23);
  EXPECT_EQ(wire.disk_bytes_limit(), std::int64_t{1} << 40);
  EXPECT_EQ(wire.disk_evictions(), 25);
  EXPECT_EQ(wire.disk_evicted_bytes(), 26);
  EXPECT_EQ(wire.disk_writes_too_large(), 27);

  const CacheStats back = CacheStatsFromProto(wire);
  for (const CacheStatsCounter& counter : kCacheStatsCounters) {
    EXPECT_EQ(back.*counter.value, stats.*counter.value) << counter.name;
  }
  // An empty message (an older server's missing fields) reads as zeros.
  const CacheStats none = CacheStatsFromProto(v1::CacheStatsResponse());
  for (const CacheStatsCounter& counter : kCacheStatsCounters) {
    EXPECT_EQ(none.*counter.value, 0) << counter.name;
  }
}

}  // namespace
}  // namespace inscribe::wire
