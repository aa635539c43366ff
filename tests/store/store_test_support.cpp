#include "store_test_support.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <fstream>
#include <iterator>
#include <stdexcept>

namespace dynid::store::test {

ingest::RunAnnouncement announcement(const std::string& vehicle, const std::string& run) {
  ingest::RunAnnouncement a;
  a.vehicle = vehicle;
  a.run = run;
  a.sample_rate_hz = 100.0;
  a.channels = {{"speed", "m/s"}, {"yaw_rate", "rad/s"}, {"steering_angle", "rad"}};
  a.models = {{"lateral_bicycle", {{"mass", 1500.0}, {"wheelbase", 2.7}}, {}}};
  return a;
}

ingest::Chunk chunk(const std::string& vehicle, const std::string& run, std::uint64_t sequence,
                    int rows, int variant) {
  ingest::Chunk c;
  c.vehicle = vehicle;
  c.run = run;
  c.sequence = sequence;
  c.first_sample_index = sequence * static_cast<std::uint64_t>(rows);
  c.samples.resize(rows, 3);
  for (int r = 0; r < rows; ++r) {
    const double t = static_cast<double>(c.first_sample_index) + r;
    c.samples(r, 0) = 20.0 + 0.01 * t + variant;
    c.samples(r, 1) = 0.001 * static_cast<double>(sequence) + 1e-6 * r;
    c.samples(r, 2) = -0.5 + 0.25 * variant + 1e-4 * t;
  }
  c.valid.assign(static_cast<std::size_t>(rows), 1);
  if (rows > 2) c.valid[1] = 0;  // one gap row, so flags round-trip too
  c.seal();
  return c;
}

bool same(const ingest::Chunk& a, const ingest::Chunk& b) {
  return a.vehicle == b.vehicle && a.run == b.run && a.sequence == b.sequence &&
         a.first_sample_index == b.first_sample_index && a.samples.rows() == b.samples.rows() &&
         a.samples.cols() == b.samples.cols() && a.samples == b.samples && a.valid == b.valid &&
         a.checksum == b.checksum;
}

void overwrite(const std::string& path, std::uint64_t offset, const std::string& bytes) {
  std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
  ASSERT_TRUE(file) << path;
  file.seekp(static_cast<std::streamoff>(offset));
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(file) << path;
}

std::uint64_t find_in_file(const std::string& path, const std::string& needle) {
  std::ifstream file(path, std::ios::binary);
  const std::string content((std::istreambuf_iterator<char>(file)),
                            std::istreambuf_iterator<char>());
  const auto at = content.find(needle);
  EXPECT_NE(at, std::string::npos) << "bytes not found in " << path;
  return at == std::string::npos ? 0 : at;
}

}  // namespace dynid::store::test
