#include "dds_fixture.hpp"

#include <unistd.h>

#include <cmath>
#include <limits>

namespace dynid::dds::testing {

std::string loopback_config(const std::string& tag) {
  return config_file_uri(std::string(DYNID_SOURCE_DIR) + "/deploy/cyclonedds/loopback.xml") +
         ",<Discovery><Tag>" + tag + "</Tag></Discovery>";
}

std::string process_tag() {
  static const std::string tag =
      "dynid-test-" + std::to_string(getpid()) + "-" +
      std::to_string(std::chrono::steady_clock::now().time_since_epoch().count());
  return tag;
}

ParticipantOptions loopback_options(const std::string& tag) {
  return {kDomain, loopback_config(tag)};
}

ingest::RunAnnouncement make_announcement(const std::string& vehicle, const std::string& run) {
  ingest::RunAnnouncement announcement;
  announcement.vehicle = vehicle;
  announcement.run = run;
  announcement.sample_rate_hz = 100.0;
  announcement.channels = {{"vx", "m/s"}, {"ax", "m/s^2"}, {"wheel_torque", "N*m"}};
  announcement.models = {{"longitudinal", {{"wheel_radius", 0.3135}, {"g", 9.80665}}, {"road_grade"}},
                         {"kinematic", {}, {}}};
  return announcement;
}

ingest::Chunk make_chunk(const std::string& vehicle, const std::string& run,
                         std::uint64_t sequence, Eigen::Index rows, Eigen::Index gap) {
  ingest::Chunk chunk;
  chunk.vehicle = vehicle;
  chunk.run = run;
  chunk.sequence = sequence;
  chunk.first_sample_index = sequence * static_cast<std::uint64_t>(rows);
  chunk.samples.resize(rows, 3);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const double t = static_cast<double>(r) + 0.1;
    chunk.samples(r, 0) = std::nextafter(t / 3.0, 1e9);           // last bit matters
    chunk.samples(r, 1) = r % 2 ? -0.0 : std::numeric_limits<double>::denorm_min() * (r + 1);
    chunk.samples(r, 2) = std::ldexp(1.0 + t * 1e-15, 900) * (r % 3 ? 1 : -1);
  }
  chunk.valid.assign(static_cast<std::size_t>(rows), 1);
  if (gap >= 0) chunk.valid[static_cast<std::size_t>(gap)] = 0;
  chunk.checksum = 0xC0FFEE00u + static_cast<std::uint32_t>(sequence);
  return chunk;
}

}  // namespace dynid::dds::testing
