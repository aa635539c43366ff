// Fuzz target: the chunk decoder and validator (ingest/chunk.hpp), and a chunk that passes them
// pushed through a RunProcessor (ingest/run_processor.hpp) with its checkpoint restored.
// InputError is the documented outcome of every step for bad input.
//
// The encoding ends with a CRC-32 of the rest, which random mutations almost never keep right,
// so an input the decoder refuses is tried a second time with its last 4 bytes replaced by the
// right CRC: the fuzzer then reaches the fields behind the checksum.
//
// Properties: a decoded chunk re-encodes to exactly the input bytes and its checksum is its
// content's; a restored checkpoint continues like the original (same next sequence).
#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "dynid/error.hpp"
#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"
#include "dynid/ingest/run_processor.hpp"
#include "fuzz_check.hpp"

namespace {

using dynid::ingest::Chunk;
using dynid::ingest::RunAnnouncement;
using dynid::ingest::RunProcessor;

// The ingest tests' run layout (tests/ingest/ingest_test_support.hpp): three models over six
// channels, so a 6-column chunk reaches the filters, derivatives and row builders.
RunAnnouncement announcement_for(const Chunk& chunk) {
  RunAnnouncement a;
  a.vehicle = chunk.vehicle;
  a.run = chunk.run;
  a.sample_rate_hz = 100.0;
  a.channels = {{"vx", "m/s"},          {"ax", "m/s^2"},         {"wheel_torque", "N m"},
                {"engine_speed", "rad/s"}, {"engine_torque", "N m"}, {"gear", "-"}};
  a.models = {{"longitudinal_wheel", {{"wheel_radius", 0.31}, {"air_density", 1.2}}, {}},
              {"kinematic_longitudinal", {}, {"dict:lag2:vx"}},
              {"locked_driveline", {{"gear", 3.0}}, {}}};
  a.preprocessing.odmf = 5;
  return a;
}

void process(const Chunk& chunk) {
  const RunAnnouncement announcement = announcement_for(chunk);
  dynid::ingest::validate_chunk(chunk, announcement);
  RunProcessor processor(announcement);
  processor.push(chunk);
  RunProcessor restored = RunProcessor::restore(announcement, processor.checkpoint());
  dynid::fuzz::expect(restored.next_sequence() == processor.next_sequence(),
                      "a restored checkpoint continues at the same sequence");
  processor.finish();
  (void)processor.estimates();
}

// True when `bytes` decoded (whatever happened after).
bool try_chunk(std::string_view bytes) {
  Chunk chunk;
  try {
    chunk = dynid::ingest::decode_chunk(bytes);
  } catch (const dynid::InputError&) {
    return false;
  }
  dynid::fuzz::expect(dynid::ingest::encode_chunk(chunk) == bytes,
                      "a decoded chunk re-encodes to its bytes");
  dynid::fuzz::expect(chunk.compute_checksum() == chunk.checksum,
                      "a decoded chunk's checksum is its content's");
  try {
    process(chunk);
  } catch (const dynid::InputError&) {
    // documented: the chunk does not fit the run, or a model refuses its rows
  }
  return true;
}

std::string resealed(std::string_view bytes) {
  std::string copy(bytes);
  const std::size_t body = copy.size() - sizeof(std::uint32_t);
  const auto crc = static_cast<std::uint32_t>(
      crc32(0L, reinterpret_cast<const Bytef*>(copy.data()), static_cast<uInt>(body)));
  std::memcpy(copy.data() + body, &crc, sizeof crc);
  return copy;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  if (!try_chunk(bytes) && size >= sizeof(std::uint32_t)) try_chunk(resealed(bytes));
  return 0;
}
