#pragma once
// Shared by the DDS tests and their helper process: the loopback configuration with a
// discovery tag of our own, and small sample builders.
#include <chrono>
#include <cstring>
#include <string>

#include "dynid/dds/participant.hpp"
#include "dynid/dds/reader.hpp"
#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"

namespace dynid::dds::testing {

using namespace std::chrono_literals;

inline constexpr dds_domainid_t kDomain = 17;
/// Every wait in the tests: long enough for discovery on a loaded machine, still bounded.
inline constexpr std::chrono::milliseconds kPatience = 5s;

/// deploy/cyclonedds/loopback.xml plus <Discovery><Tag>`tag`</Tag></Discovery>.
std::string loopback_config(const std::string& tag);
/// A tag unique to this process (pid and start time).
std::string process_tag();
ParticipantOptions loopback_options(const std::string& tag = process_tag());

ingest::RunAnnouncement make_announcement(const std::string& vehicle, const std::string& run);
/// rows x 3 channels of awkward doubles (subnormal, -0, 0.1, large), row `gap` invalid.
ingest::Chunk make_chunk(const std::string& vehicle, const std::string& run,
                         std::uint64_t sequence, Eigen::Index rows, Eigen::Index gap = -1);

/// Same values to the last bit (0.0 and -0.0 differ, as they must on the wire).
inline bool same_bits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

/// Takes samples until `count` arrived or `patience` passed (then fewer are returned).
template <typename T>
std::vector<Sample<T>> take_count(Reader<T>& reader, std::size_t count,
                                  std::chrono::milliseconds patience = kPatience) {
  std::vector<Sample<T>> all;
  const auto deadline = std::chrono::steady_clock::now() + patience;
  while (all.size() < count && std::chrono::steady_clock::now() < deadline)
    for (auto& sample : reader.wait_take(100ms)) all.push_back(std::move(sample));
  return all;
}

}  // namespace dynid::dds::testing
