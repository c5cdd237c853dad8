// RouteKey and RendezvousOrder: which digits route a key; rendezvous balance (chi-square),
// minimal disruption when a replica leaves or joins (against recomputation from the full
// order), independence from the order replicas are listed in, and pinned orders (computed with
// Python's hashlib) so that a change of hash cannot pass unnoticed.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "inscribe/client/routing.h"
#include "inscribe/wire/keys.h"

namespace inscribe::client {
namespace {

using ::testing::ElementsAre;

std::string RandomHex(std::mt19937_64& bits, int digits) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string hex;
  for (int i = 0; i < digits; ++i) hex += kDigits[bits() & 15];
  return hex;
}

TEST(RouteKey, IsTheMeshDigitsOfMeshAndSetKeys) {
  const std::string hex = "0123456789abcdef" + std::string(48, 'e');
  EXPECT_EQ(wire::RouteKey("sha256:" + hex), "0123456789abcdef");
  EXPECT_EQ(wire::RouteKey("spheres/v1/" + hex), "0123456789abcdef");
  EXPECT_EQ(wire::RouteKey("spheres/v1/0123456789abcdef" + std::string(48, '7')),
            "0123456789abcdef");
  // Anything else routes as a whole.
  EXPECT_EQ(wire::RouteKey("sha256:0123456789ABCDEF" + std::string(48, 'e')),
            "sha256:0123456789ABCDEF" + std::string(48, 'e'));
  EXPECT_EQ(wire::RouteKey("sha256:0123456789abcde"), "sha256:0123456789abcde");  // too short
  EXPECT_EQ(wire::RouteKey("sha256:0123456789abcdeg" + std::string(48, 'e')),
            "sha256:0123456789abcdeg" + std::string(48, 'e'));
  EXPECT_EQ(wire::RouteKey("spheres/v2/" + hex), "spheres/v2/" + hex);
  EXPECT_EQ(wire::RouteKey("hierarchy/v1/sphere/spheres/v1/" + hex),
            "hierarchy/v1/sphere/spheres/v1/" + hex);
  EXPECT_EQ(wire::RouteKey("spheres/v1/two"), "spheres/v1/two");
  EXPECT_EQ(wire::RouteKey(""), "");
}

// Chi-square statistic of `counts` against equal shares.
double ChiSquare(const std::vector<int>& counts, int total) {
  const double expected = static_cast<double>(total) / counts.size();
  double chi2 = 0.0;
  for (int c : counts) chi2 += (c - expected) * (c - expected) / expected;
  return chi2;
}

TEST(RendezvousOrder, SpreadsKeysEvenly) {
  std::mt19937_64 bits(7);
  constexpr int kKeys = 10'000;
  for (int n : {3, 5}) {
    std::vector<std::string> names;
    for (int i = 0; i < n; ++i) names.push_back("10.0.0." + std::to_string(i + 1) + ":50051");
    std::vector<int> first(n, 0);
    std::vector<std::vector<int>> second(n, std::vector<int>(n, 0));
    for (int k = 0; k < kKeys; ++k) {
      const std::vector<int> order = RendezvousOrder(RandomHex(bits, 16), names);
      ASSERT_EQ(order.size(), static_cast<std::size_t>(n));
      ASSERT_EQ(std::set<int>(order.begin(), order.end()).size(), static_cast<std::size_t>(n));
      ++first[order[0]];
      ++second[order[0]][order[1]];
    }
    for (int i = 0; i < n; ++i) {
      EXPECT_NEAR(static_cast<double>(first[i]) / kKeys, 1.0 / n, 0.03) << n << " replicas";
    }
    // The 99.99th percentile of chi-square is 18.4 for 2 degrees of freedom and 23.5 for 4; a
    // constant owner scores kKeys * (n - 1).
    EXPECT_LT(ChiSquare(first, kKeys), 25.0) << n << " replicas";
    // A replica's keys fall back evenly on the others (so a failure spreads its load).
    std::vector<int> fallback;
    for (int j = 1; j < n; ++j) fallback.push_back(second[0][j]);
    EXPECT_LT(ChiSquare(fallback, first[0]), 25.0) << n << " replicas";
  }
}

TEST(RendezvousOrder, RemovingAReplicaMovesOnlyItsKeysToTheirSecondChoice) {
  std::mt19937_64 bits(11);
  const std::vector<std::string> names = {"a:1", "b:1", "c:1", "d:1", "e:1"};
  for (int removed = 0; removed < 5; ++removed) {
    std::vector<std::string> rest = names;
    rest.erase(rest.begin() + removed);
    int owned = 0, moved = 0;
    for (int k = 0; k < 2000; ++k) {
      const std::string key = RandomHex(bits, 16);
      const std::vector<int> before = RendezvousOrder(key, names);
      const std::string now = rest[RendezvousOrder(key, rest)[0]];
      if (before[0] == removed) {
        ++owned;
        EXPECT_EQ(now, names[before[1]]) << key;
      } else {
        EXPECT_EQ(now, names[before[0]]) << key;
      }
      moved += now != names[before[0]];
    }
    EXPECT_EQ(moved, owned);
    EXPECT_GT(owned, 250);  // about 2000 / 5
  }
  // Adding one moves keys only to the new replica.
  std::vector<std::string> more = names;
  more.push_back("f:1");
  int gained = 0;
  for (int k = 0; k < 2000; ++k) {
    const std::string key = RandomHex(bits, 16);
    const std::string before = names[RendezvousOrder(key, names)[0]];
    const std::string after = more[RendezvousOrder(key, more)[0]];
    if (after != before) {
      EXPECT_EQ(after, "f:1");
      ++gained;
    }
  }
  EXPECT_NEAR(gained, 2000 / 6, 100);
}

TEST(RendezvousOrder, DoesNotDependOnTheOrderEndpointsAreListed) {
  std::mt19937_64 bits(3);
  std::vector<std::string> names = {"127.0.0.1:4001", "127.0.0.1:4002", "127.0.0.1:4003",
                                    "replica.example:443"};
  std::vector<std::string> shuffled = names;
  std::reverse(shuffled.begin(), shuffled.end());
  std::swap(shuffled[0], shuffled[2]);
  for (int k = 0; k < 500; ++k) {
    const std::string key = RandomHex(bits, 16);
    std::vector<std::string> a, b;
    for (int i : RendezvousOrder(key, names)) a.push_back(names[i]);
    for (int i : RendezvousOrder(key, shuffled)) b.push_back(shuffled[i]);
    EXPECT_EQ(a, b);
  }
  // Known orders, computed independently (Python's hashlib: the first 8 bytes of
  // SHA-256(key NUL name), big-endian, highest first), so that a change of hash, which would
  // reroute every deployed client's keys, fails here.
  EXPECT_THAT(RendezvousOrder("0123456789abcdef", names), ElementsAre(1, 2, 3, 0));
  EXPECT_THAT(RendezvousOrder("fedcba9876543210", names), ElementsAre(0, 3, 2, 1));
}

}  // namespace
}  // namespace inscribe::client
