// What the machine itself costs, for the service's floor rows (bench/service_bench.cpp): no
// inscribe code runs in these.
#pragma once

#include <chrono>
#include <vector>

namespace inscribe::bench {

// `count` TCP round trips on loopback, one byte each way between two threads, TCP_NODELAY as
// gRPC sets it, each after `pause`: seconds each; empty if a socket call failed.
std::vector<double> LoopbackRoundTrips(int count, std::chrono::steady_clock::duration pause);

// `count` chases of 20,000 dependent loads around a random cycle through 256 KB (an L2
// cache's worth), each after `pause`: seconds each. Against back-to-back chases, how much of
// its caches a thread keeps over a paced client's period on this machine.
std::vector<double> PointerChases(int count, std::chrono::steady_clock::duration pause);

}  // namespace inscribe::bench
