#pragma once
// Shared by the client tests: the loopback Cyclone configuration with a discovery tag of this
// test process (deploy/cyclonedds/loopback.xml, never Cyclone's default), a scratch folder, real
// chunks from the ChunkBuilder, child processes with a time limit, and the test-side
// acknowledger.
//
// TestAcker stands in for the server's ledger in the protocol unit tests, nothing more: it
// reads announcements and chunks of one vehicle over DDS, keeps every copy it received (so a
// test can count duplicates and check order and content), and publishes ChunkReceipts like the
// server does (highest contiguous sequence received) unless muted.
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <dynid/dds/chunk_receipt.hpp>
#include <dynid/dds/participant.hpp>
#include <dynid/dds/reader.hpp>
#include <dynid/dds/writer.hpp>
#include <dynid/ingest/chunk.hpp>
#include <dynid/ingest/run_announcement.hpp>

#include "car_test_support.hpp"

namespace dynid::car::testing {

using namespace std::chrono_literals;

inline constexpr dds_domainid_t kDomain = 19;
/// Every wait in the tests: long enough for discovery on a loaded machine, still bounded.
inline constexpr std::chrono::milliseconds kPatience = 10s;

std::filesystem::path source_dir();
std::filesystem::path loopback_xml();
/// A discovery tag unique to this test process.
std::string process_tag();
/// loopback.xml plus <Discovery><Tag>tag</Tag></Discovery>.
dds::ParticipantOptions loopback_options(const std::string& tag = process_tag());

using test::ScratchDir;  // tests/car's, which removes itself

/// `count` sealed chunks of `rows` rows x 3 channels of vehicle/run from the ChunkBuilder.
std::vector<ingest::Chunk> make_chunks(const std::string& vehicle, const std::string& run, std::size_t count,
                                       std::size_t rows = 10);
/// An announcement matching make_chunks' three channels.
ingest::RunAnnouncement make_announcement(const std::string& vehicle, const std::string& run);

bool same_chunk(const ingest::Chunk& a, const ingest::Chunk& b);

std::filesystem::path testcar_profile();
/// The chunks the car's own data path cuts from a log (what the server must end up with).
std::vector<ingest::Chunk> expected_chunks(const std::filesystem::path& log, const std::string& run,
                                           const std::filesystem::path& profile_file = testcar_profile());

class TestAcker {
 public:
  TestAcker(const dds::Participant& participant, const std::string& vehicle);

  /// Takes what arrived for up to `wait`, then acknowledges (unless muted).
  void poll(std::chrono::milliseconds wait = 50ms);
  /// Polls until `predicate` holds or `patience` passes; returns whether it holds.
  template <typename P>
  bool poll_until(P predicate, std::chrono::milliseconds patience = kPatience) {
    const auto deadline = std::chrono::steady_clock::now() + patience;
    while (!predicate()) {
      if (std::chrono::steady_clock::now() > deadline) return false;
      poll();
    }
    return true;
  }
  void acknowledge(const std::string& run, std::int64_t through,
                   const std::vector<dds::ChunkRejection>& rejections = {});

  bool muted = false;
  /// Every chunk copy in arrival order.
  std::vector<ingest::Chunk> received;
  std::vector<ingest::RunAnnouncement> announcements;
  /// Distinct sequences of a run received so far.
  std::size_t distinct(const std::string& run) const;
  /// Copies of run#sequence received.
  std::size_t copies(const std::string& run, std::uint64_t sequence) const;
  /// Highest contiguous sequence of the run received (-1: none).
  std::int64_t contiguous(const std::string& run) const;

 private:
  std::string vehicle_;
  dds::Reader<dynid_wire_RunAnnouncement> announcement_reader_;
  dds::Reader<dynid_wire_Chunk> chunk_reader_;
  dds::Writer<dynid_wire_ChunkAck> ack_writer_;
  std::map<std::string, std::int64_t> acked_;
};

/// A child process running `args` (args[0] is the program), stdout+stderr to `log`.
class Child {
 public:
  Child(const std::vector<std::string>& args, const std::filesystem::path& log);
  ~Child();  // kills the child (by its id) if it still runs
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  /// Exit status, or nullopt if it did not end within `timeout` (then it is killed).
  std::optional<int> wait(std::chrono::milliseconds timeout);
  void signal(int sig);
  bool running();
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  bool reaped_ = false;
  int status_ = 0;
};

std::string read_text(const std::filesystem::path& file);

/// A simulated test run (dynid-sim with `scenario`), cached per test process: its folder.
std::filesystem::path simulated_run(const std::string& scenario, const ScratchDir& scratch);

}  // namespace dynid::car::testing
