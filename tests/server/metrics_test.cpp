// The Prometheus endpoint of a real in-process server: scraped over HTTP after known calls, and
// its counts checked against those calls and against the CacheStats RPC.
#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "inscribe/client/client.h"
#include "inscribe/server/inscribe_server.h"
#include "support/inscribed_process.h"
#include "support/synthetic_meshes.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;

// One sample of the text exposition format: name, labels, value.
struct Sample {
  std::string name;
  std::map<std::string, std::string> labels;
  double value = 0.0;
};

std::vector<Sample> Parse(const std::string& text) {
  std::vector<Sample> samples;
  for (absl::string_view line : absl::StrSplit(text, '\n', absl::SkipEmpty())) {
    if (absl::StartsWith(line, "#")) continue;
    Sample sample;
    const std::size_t space = line.rfind(' ');
    absl::string_view head = line.substr(0, space);
    EXPECT_TRUE(absl::SimpleAtod(line.substr(space + 1), &sample.value)) << line;
    const std::size_t brace = head.find('{');
    sample.name = std::string(head.substr(0, brace));
    if (brace != absl::string_view::npos) {
      absl::string_view labels = head.substr(brace + 1, head.size() - brace - 2);
      for (absl::string_view pair : absl::StrSplit(labels, ',', absl::SkipEmpty())) {
        const std::size_t eq = pair.find('=');
        sample.labels[std::string(pair.substr(0, eq))] =
            std::string(absl::StripSuffix(absl::StripPrefix(pair.substr(eq + 1), "\""), "\""));
      }
    }
    samples.push_back(std::move(sample));
  }
  return samples;
}

// The value of the one sample named `name` carrying `labels` (others may be present too);
// -1 when there is none.
double Value(const std::vector<Sample>& samples, const std::string& name,
             const std::map<std::string, std::string>& labels = {}) {
  for (const Sample& sample : samples) {
    if (sample.name != name) continue;
    bool match = true;
    for (const auto& [key, value] : labels) {
      const auto it = sample.labels.find(key);
      match = match && it != sample.labels.end() && it->second == value;
    }
    if (match) return sample.value;
  }
  return -1.0;
}

class MetricsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ServerOptions options;
    options.listen = "127.0.0.1:0";
    options.metrics_listen = "127.0.0.1:0";
    options.jobs = 2;
    options.max_queue = 17;
    absl::StatusOr<std::unique_ptr<InscribeServer>> started = InscribeServer::Start(options);
    ASSERT_TRUE(started.ok()) << started.status();
    server_ = *std::move(started);
    ASSERT_GT(server_->metrics_port(), 0);
    client_ = std::make_unique<client::Client>(client::MakeGrpcConnection(server_->address()));
  }

  std::unique_ptr<InscribeServer> server_;
  std::unique_ptr<client::Client> client_;
};

TEST_F(MetricsTest, CountsEachCallByMethodAndCode) {
  const Mesh cube = testing::UnitCube();
  client::GenerateSettings settings;
  settings.parameters.voxel_size = 0.25;
  settings.parameters.evaluate = false;
  ASSERT_TRUE(client_->PutMesh(cube).ok());
  absl::StatusOr<client::GenerateResult> first = client_->Generate(cube, settings);
  ASSERT_TRUE(first.ok()) << first.status();
  ASSERT_TRUE(client_->Generate(first->mesh_sha256, settings).ok());  // a memory hit
  EXPECT_EQ(client_->GetSphereSet("spheres/v1/" + std::string(64, '0')).status().code(),
            absl::StatusCode::kNotFound);

  const std::vector<Sample> samples = Parse(testing::ScrapeMetrics(server_->metrics_port()));
  ASSERT_FALSE(samples.empty());
  // Generate(mesh) uploads first: two PutMesh calls in all, two Generate.
  EXPECT_EQ(Value(samples, "inscribe_rpc_calls_total", {{"method", "PutMesh"}, {"code", "OK"}}), 2);
  EXPECT_EQ(Value(samples, "inscribe_rpc_calls_total", {{"method", "Generate"}, {"code", "OK"}}),
            2);
  EXPECT_EQ(Value(samples, "inscribe_rpc_calls_total",
                  {{"method", "GetSphereSet"}, {"code", "NOT_FOUND"}}),
            1);
  EXPECT_EQ(
      Value(samples, "inscribe_rpc_calls_total", {{"method", "GetSphereSet"}, {"code", "OK"}}),
      -1);  // no such series until one succeeds

  // The histogram holds both Generate calls, its buckets cumulative up to +Inf.
  EXPECT_EQ(Value(samples, "inscribe_rpc_duration_seconds_count", {{"method", "Generate"}}), 2);
  EXPECT_GT(Value(samples, "inscribe_rpc_duration_seconds_sum", {{"method", "Generate"}}), 0.0);
  double previous = 0.0;
  int buckets = 0;
  for (const Sample& sample : samples) {
    if (sample.name != "inscribe_rpc_duration_seconds_bucket" ||
        sample.labels.at("method") != "Generate") {
      continue;
    }
    EXPECT_GE(sample.value, previous) << "le=" << sample.labels.at("le");
    previous = sample.value;
    ++buckets;
  }
  EXPECT_EQ(buckets, 21);  // 20 bounds and +Inf
  EXPECT_EQ(previous, 2);

  EXPECT_EQ(Value(samples, "inscribe_jobs_concurrency"), 2);
  EXPECT_EQ(Value(samples, "inscribe_jobs_capacity"), 17);
  // The last job may still be returning after its reply went out: the gauge drops to 0 soon.
  double in_flight = Value(samples, "inscribe_jobs_in_flight");
  for (int i = 0; i < 100 && in_flight != 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    in_flight =
        Value(Parse(testing::ScrapeMetrics(server_->metrics_port())), "inscribe_jobs_in_flight");
  }
  EXPECT_EQ(in_flight, 0);
  EXPECT_EQ(Value(samples, "inscribe_redis_available"), 0);  // none configured
}

TEST_F(MetricsTest, CacheFiguresAgreeWithCacheStats) {
  const Mesh cube = testing::UnitCube();
  client::GenerateSettings settings;
  settings.parameters.voxel_size = 0.2;
  settings.parameters.evaluate = false;
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(client_->Generate(cube, settings).ok());
  absl::StatusOr<client::ServerCacheStats> stats = client_->CacheStats();
  ASSERT_TRUE(stats.ok()) << stats.status();
  const std::vector<Sample> samples = Parse(testing::ScrapeMetrics(server_->metrics_port()));

  EXPECT_GE(stats->memory_hits, 2);  // the second and third Generate at least
  EXPECT_EQ(Value(samples, "inscribe_cache_lookups_total", {{"result", "memory"}}),
            stats->memory_hits);
  EXPECT_EQ(Value(samples, "inscribe_cache_lookups_total", {{"result", "miss"}}), stats->misses);
  EXPECT_EQ(Value(samples, "inscribe_cache_lookups_total", {{"result", "disk"}}), 0);
  EXPECT_EQ(Value(samples, "inscribe_cache_computations_total"), stats->computations);
  EXPECT_EQ(Value(samples, "inscribe_cache_entries", {{"tier", "memory"}}), stats->entries);
  EXPECT_EQ(Value(samples, "inscribe_cache_bytes", {{"tier", "memory"}}), stats->bytes);
  EXPECT_GT(stats->bytes, 0);
}

// inscribe_scenes_open counts SceneStream calls holding a scene, and drops when one closes.
TEST_F(MetricsTest, OpenScenesGaugeFollowsSceneSessions) {
  const auto scenes = [this] {
    return Value(Parse(testing::ScrapeMetrics(server_->metrics_port())), "inscribe_scenes_open");
  };
  EXPECT_EQ(scenes(), 0);
  SphereSet set;
  set.spheres = {{Vector3::Zero(), 0.5}};
  absl::StatusOr<client::PutSphereSetResult> stored = client_->PutSphereSet(set);
  ASSERT_TRUE(stored.ok()) << stored.status();
  std::vector<client::SceneSessionObject> objects(2);
  objects[1].object.id = 1;
  for (auto& object : objects) object.sphere_set_key = stored->sphere_set_key;
  absl::StatusOr<client::SceneSession> session = client_->OpenSceneSession(objects);
  ASSERT_TRUE(session.ok()) << session.status();
  EXPECT_EQ(session->created().pairs.size(), 1u);  // two coincident balls overlap
  EXPECT_EQ(scenes(), 1);
  EXPECT_TRUE(session->Close().ok());
  double open = scenes();
  for (int i = 0; i < 100 && open != 0; ++i) {  // OnDone runs just after the status is sent
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    open = scenes();
  }
  EXPECT_EQ(open, 0);
}

TEST_F(MetricsTest, ConcurrentCallsAreEachCountedOnce) {
  const Mesh cube = testing::UnitCube();
  constexpr int kThreads = 4;
  constexpr int kCalls = 25;
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&] {
      for (int i = 0; i < kCalls; ++i) EXPECT_TRUE(client_->InspectMesh(cube).ok());
    });
  }
  for (std::thread& thread : threads) thread.join();
  const std::vector<Sample> samples = Parse(testing::ScrapeMetrics(server_->metrics_port()));
  EXPECT_EQ(Value(samples, "inscribe_rpc_calls_total", {{"method", "InspectMesh"}, {"code", "OK"}}),
            kThreads * kCalls);
  EXPECT_EQ(Value(samples, "inscribe_rpc_queue_seconds_count", {{"method", "InspectMesh"}}),
            kThreads * kCalls);
}

TEST_F(MetricsTest, AnswersOnlyGetMetricsAndSurvivesBadClients) {
  const int port = server_->metrics_port();
  EXPECT_THAT(testing::ExchangeOnLoopback(port, "GET /other HTTP/1.1\r\n\r\n"),
              ::testing::StartsWith("HTTP/1.1 404"));
  EXPECT_THAT(testing::ExchangeOnLoopback(port, "POST /metrics HTTP/1.1\r\n\r\n"),
              ::testing::StartsWith("HTTP/1.1 405"));
  EXPECT_THAT(testing::ExchangeOnLoopback(port, std::string("\x01\xff garbage\r\n\r\n")),
              ::testing::StartsWith("HTTP/1.1 400"));
  EXPECT_THAT(testing::ExchangeOnLoopback(port, std::string(20000, 'A')),
              ::testing::StartsWith("HTTP/1.1 400"));
  const std::string head = testing::ExchangeOnLoopback(port, "HEAD /metrics HTTP/1.1\r\n\r\n");
  EXPECT_THAT(head, ::testing::StartsWith("HTTP/1.1 200"));
  EXPECT_THAT(head, ::testing::EndsWith("\r\n\r\n"));  // headers only

  // A client that connects and sends nothing is dropped after the 2 s read timeout; the next
  // scrape is answered.
  const int idle = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(idle, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  EXPECT_THAT(testing::ScrapeMetrics(port), HasSubstr("inscribe_jobs_capacity 17"));
  ::close(idle);
}

TEST(MetricsStartTest, BadAddressesAreClearErrors) {
  ServerOptions options;
  options.listen = "127.0.0.1:0";
  options.metrics_listen = "no-port-here";
  absl::StatusOr<std::unique_ptr<InscribeServer>> bad = InscribeServer::Start(options);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), HasSubstr("--metrics-listen"));

  for (const char* port : {"99999", "-1", "http", "+80"}) {
    options.metrics_listen = absl::StrCat("127.0.0.1:", port);
    bad = InscribeServer::Start(options);
    ASSERT_FALSE(bad.ok()) << port;
    EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument) << port;
    EXPECT_THAT(bad.status().message(), HasSubstr("0-65535")) << port;
  }

  options.metrics_listen = "127.0.0.1:0";
  absl::StatusOr<std::unique_ptr<InscribeServer>> first = InscribeServer::Start(options);
  ASSERT_TRUE(first.ok()) << first.status();
  options.metrics_listen = absl::StrCat("127.0.0.1:", (*first)->metrics_port());
  absl::StatusOr<std::unique_ptr<InscribeServer>> clash = InscribeServer::Start(options);
  ASSERT_FALSE(clash.ok());
  EXPECT_EQ(clash.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_THAT(clash.status().message(), HasSubstr("cannot serve metrics"));
}

TEST(MetricsStartTest, NoEndpointByDefault) {
  ServerOptions options;
  options.listen = "127.0.0.1:0";
  absl::StatusOr<std::unique_ptr<InscribeServer>> started = InscribeServer::Start(options);
  ASSERT_TRUE(started.ok()) << started.status();
  EXPECT_EQ((*started)->metrics_port(), 0);
}

}  // namespace
}  // namespace inscribe::server
