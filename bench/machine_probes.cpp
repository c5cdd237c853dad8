#include "machine_probes.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <thread>

namespace inscribe::bench {

using Clock = std::chrono::steady_clock;

std::vector<double> LoopbackRoundTrips(int count, Clock::duration pause) {
  const int listener = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof(address);
  if (bind(listener, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
      listen(listener, 1) != 0 ||
      getsockname(listener, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    close(listener);
    return {};
  }
  const int client = socket(AF_INET, SOCK_STREAM, 0);
  if (connect(client, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    close(client);
    close(listener);
    return {};
  }
  const int server = accept(listener, nullptr, nullptr);
  const int one = 1;
  setsockopt(client, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
  setsockopt(server, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
  std::thread echo([server, count] {
    char byte = 0;
    for (int i = 0; i < count; ++i) {
      if (read(server, &byte, 1) != 1 || write(server, &byte, 1) != 1) return;
    }
  });
  std::vector<double> times;
  char byte = 1;
  for (int i = 0; i < count; ++i) {
    std::this_thread::sleep_for(pause);
    const Clock::time_point sent = Clock::now();
    if (write(client, &byte, 1) != 1 || read(client, &byte, 1) != 1) break;
    times.push_back(std::chrono::duration<double>(Clock::now() - sent).count());
  }
  echo.join();
  close(client);
  close(server);
  close(listener);
  return times;
}

std::vector<double> PointerChases(int count, Clock::duration pause) {
  constexpr std::size_t kEntries = 256 * 1024 / sizeof(std::uint32_t);
  std::vector<std::uint32_t> order(kEntries), next(kEntries);
  std::iota(order.begin(), order.end(), 0u);
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  for (std::size_t i = 0; i < kEntries; ++i) next[order[i]] = order[(i + 1) % kEntries];
  std::vector<double> times;
  std::uint32_t at = 0;
  for (int round = 0; round < count; ++round) {
    std::this_thread::sleep_for(pause);
    const Clock::time_point start = Clock::now();
    for (int step = 0; step < 20000; ++step) at = next[at];
    times.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }
  static volatile std::uint32_t sink;
  sink = at;
  return times;
}

}  // namespace inscribe::bench
