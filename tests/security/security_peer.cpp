// security_peer: one DDS participant with one identity (Cyclone's access control keeps one
// permissions document per process, so every identity of the security tests is a process of
// its own) doing one thing a car or an engineer does, with the product's own endpoints:
//
//   security_peer CONFIG DOMAIN SECONDS car VEHICLE RUN [KEY]
//       the Uplink of VEHICLE (partition vehicle/VEHICLE) announces and streams a synthetic run
//       of 12 chunks, keyed with vehicle KEY (default VEHICLE: KEY != VEHICLE is a forgery)
//   security_peer CONFIG DOMAIN SECONDS estimates VEHICLE  reads VEHICLE's estimates
//   security_peer CONFIG DOMAIN SECONDS request KIND [NAME=VALUE...]   an engineer's request
//
// SECONDS bounds the whole action: a negative test waits that long for the absence of data.
// It prints what happened on stdout ("refused: ...", "acked 11 of 11", "estimates 3", the
// reply's payload) and exits with
//   0  done (every chunk acknowledged / an estimate read / a reply received)
//   2  nothing came within the time (no server matched, or it never answered)
//   3  refused: Cyclone would not create the reader or writer (DDS_RETCODE_NOT_ALLOWED_BY_SECURITY
//      or another creation failure, named in the output)
//   1  bad arguments
#include <algorithm>
#include <chrono>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "dynid/car/uplink.hpp"
#include "dynid/cli/request_client.hpp"
#include "dynid/dds/conversions.hpp"
#include "dynid/dds/error.hpp"
#include "dynid/dds/participant.hpp"
#include "dynid/dds/reader.hpp"
#include "dynid/dds/topics.hpp"
#include "ingest_test_support.hpp"

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

enum Exit { kDone = 0, kBadArguments = 1, kNothing = 2, kRefused = 3 };

using Seconds = std::chrono::duration<double>;
constexpr Eigen::Index kChunkRows = 500;

// A synthetic run of `vehicle` (tests/ingest: known physics, gaps), cut into equal chunks.
std::pair<dynid::ingest::RunAnnouncement, std::vector<dynid::ingest::Chunk>> synthetic_run(
    const std::string& vehicle, const std::string& run) {
  auto r = dynid::ingest::test::make_run(6000, 7u);
  r.announcement.vehicle = vehicle;
  r.announcement.run = run;
  r.announcement.preprocessing = {};  // not on the wire: the server runs the defaults
  std::vector<dynid::ingest::Chunk> chunks;
  for (Eigen::Index first = 0; first < r.samples.rows(); first += kChunkRows)
    chunks.push_back(dynid::ingest::test::cut(r, chunks.size(), first,
                                              std::min(kChunkRows, r.samples.rows() - first)));
  return {r.announcement, chunks};
}

// As the car's spool does: send what is not acknowledged, wait for receipts, repeat.
int car(const dynid::dds::Participant& participant, Seconds patience, const std::string& vehicle,
        const std::string& run, const std::string& key) {
  std::optional<dynid::car::Uplink> uplink;
  try {
    uplink.emplace(participant, vehicle);
  } catch (const dynid::dds::DdsError& e) {
    std::cout << "refused: " << e.what() << std::endl;
    return kRefused;
  }
  const auto [announcement, chunks] = synthetic_run(key, run);
  const auto last = static_cast<std::int64_t>(chunks.size()) - 1;
  std::int64_t acked = -1;
  const auto deadline = Clock::now() + patience;
  while (acked < last && Clock::now() < deadline) {
    uplink->announce(announcement);
    for (auto k = static_cast<std::size_t>(acked + 1); k < chunks.size(); ++k)
      if (!uplink->send(chunks[k])) break;  // the server's queue is full: wait for receipts
    for (const auto until = Clock::now() + 2s; acked < last && Clock::now() < until;)
      for (const auto& receipt : uplink->receipts(100ms))
        if (receipt.run == run) acked = std::max(acked, receipt.highest_contiguous);
  }
  std::cout << "acked " << acked + 1 << " of " << chunks.size() << std::endl;
  return acked == last ? kDone : kNothing;
}

int estimates(const dynid::dds::Participant& participant, Seconds patience, const std::string& vehicle) {
  std::optional<dynid::dds::Reader<dynid_wire_Estimate>> reader;
  try {
    reader.emplace(participant, std::vector<std::string>{dynid::dds::vehicle_partition(vehicle)});
  } catch (const dynid::dds::DdsError& e) {
    std::cout << "refused: " << e.what() << std::endl;
    return kRefused;
  }
  std::size_t count = 0;
  const auto deadline = Clock::now() + patience;
  while (count == 0 && Clock::now() < deadline)
    for (const auto& sample : reader->wait_take(100ms))
      if (dynid::dds::from_wire(sample.data).vehicle == vehicle) ++count;
  std::cout << "estimates " << count << std::endl;
  return count > 0 ? kDone : kNothing;
}

int request(const dynid::dds::Participant& participant, Seconds patience, const std::string& kind,
            const std::vector<std::string>& pairs) {
  std::vector<dynid::dds::RequestArgument> arguments;
  for (const auto& pair : pairs) {
    const auto eq = pair.find('=');
    if (eq == std::string::npos) {
      std::cerr << "security_peer: request argument '" << pair << "' is not NAME=VALUE\n";
      return kBadArguments;
    }
    arguments.push_back({pair.substr(0, eq), pair.substr(eq + 1)});
  }
  std::optional<dynid::cli::RequestClient> client;
  try {
    client.emplace(participant, "security-peer");
  } catch (const dynid::dds::DdsError& e) {
    std::cout << "refused: " << e.what() << std::endl;
    return kRefused;
  }
  try {
    const auto reply =
        client->call(kind, arguments, std::chrono::duration_cast<std::chrono::milliseconds>(patience), 500ms);
    std::cout << "reply " << static_cast<int>(reply.status) << "\n" << reply.payload << std::endl;
    return kDone;
  } catch (const dynid::cli::NoServer& e) {
    std::cout << "no reply: " << e.what() << std::endl;
    return kNothing;
  }
}

int usage(const char* why) {
  std::cerr << "security_peer: " << why
            << "\nusage: security_peer CONFIG DOMAIN SECONDS (car VEHICLE RUN [KEY] | estimates VEHICLE"
               " | request KIND [NAME=VALUE...])\n";
  return kBadArguments;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() < 5) return usage("too few arguments");
  dds_domainid_t domain = 0;
  Seconds patience{};
  try {
    domain = static_cast<dds_domainid_t>(std::stoi(args[1]));
    patience = Seconds(std::stod(args[2]));
  } catch (const std::exception&) {
    return usage("DOMAIN and SECONDS must be numbers");
  }
  const std::string& action = args[3];
  try {
    dynid::dds::Participant participant({domain, args[0]});
    if (action == "car" && (args.size() == 6 || args.size() == 7))
      return car(participant, patience, args[4], args[5], args.size() == 7 ? args[6] : args[4]);
    if (action == "estimates" && args.size() == 5) return estimates(participant, patience, args[4]);
    if (action == "request") return request(participant, patience, args[4], {args.begin() + 5, args.end()});
    return usage(("unknown action or wrong argument count: " + action).c_str());
  } catch (const dynid::dds::DdsError& e) {  // e.g. the participant itself (bad identity)
    std::cout << "refused: " << e.what() << std::endl;
    return kRefused;
  }
}
