#pragma once
// The delivery tests' link: a car (participant, spool, uplink, delivery) and a test-side
// acknowledger on real Cyclone DDS (loopback) that have discovered each other, with the car's log
// kept (test_delivery.cpp, test_refusals.cpp).
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "client_fixture.hpp"
#include "dynid/car/delivery.hpp"

namespace dynid::car::testing {

struct Log {
  std::vector<std::string> lines;
  DeliveryLog sink() {
    return [this](LogLevel, const std::string& m) { lines.push_back(m); };
  }
  bool contains(const std::string& text) const {
    for (const auto& l : lines)
      if (l.find(text) != std::string::npos) return true;
    return false;
  }
};

// Everything the car needs, on its own participant (as in its own process).
struct Car {
  Car(const std::filesystem::path& spool_dir, DeliveryOptions options, Log& log)
      : participant(loopback_options()),
        spool(spool_dir, 1 << 24),
        uplink(participant, "car-1"),
        delivery(spool, uplink, options, log.sink()) {}
  dds::Participant participant;
  Spool spool;
  Uplink uplink;
  Delivery delivery;
};

// Services the car and polls the acker until `done` or the patience ends.
template <typename P>
bool run_until(Car& car, TestAcker& acker, P done, std::chrono::milliseconds patience = kPatience) {
  const auto deadline = std::chrono::steady_clock::now() + patience;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    car.delivery.service(10ms);
    acker.poll(10ms);
  }
  return true;
}

// A car and a test-side acknowledger that have discovered each other.
struct Link {
  explicit Link(const std::string& name, DeliveryOptions options = {}, bool muted = false)
      : dir(name),
        server(loopback_options()),
        acker(server, "car-1"),
        car(dir.path(), options, log) {
    acker.muted = muted;
    // Matched first, so nothing is sent into the void (that case has its own test).
    connected = run_until(car, acker, [&] { return car.uplink.readers_matched_total() > 0; });
  }
  template <typename P>
  bool until(P done, std::chrono::milliseconds patience = kPatience) {
    return run_until(car, acker, done, patience);
  }
  ScratchDir dir;
  dds::Participant server;
  TestAcker acker;
  Log log;
  Car car;
  bool connected = false;
};

}  // namespace dynid::car::testing
