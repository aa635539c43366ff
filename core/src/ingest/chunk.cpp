#include "dynid/ingest/chunk.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "byte_codec.hpp"
#include "dynid/error.hpp"
#include "dynid/input/ids.hpp"

namespace dynid::ingest {
namespace {

constexpr std::string_view kMagic = "DYNIDCHK";
constexpr std::uint16_t kVersion = 1;

// Everything but the checksum, in the documented layout.
detail::ByteWriter encode_body(const Chunk& c) {
  detail::ByteWriter w;
  const auto rows = static_cast<std::size_t>(c.samples.rows());
  const auto cols = static_cast<std::size_t>(c.samples.cols());
  w.bytes().reserve(64 + c.vehicle.size() + c.run.size() + rows * (8 * cols + 1));
  w.bytes().append(kMagic);
  w.put<std::uint16_t>(kVersion);
  w.put_string(c.vehicle);
  w.put_string(c.run);
  w.put<std::uint64_t>(c.sequence);
  w.put<std::uint64_t>(c.first_sample_index);
  w.put<std::uint64_t>(rows);
  w.put<std::uint64_t>(cols);
  // The samples row by row: written in place (a put() per value costs more than the CRC).
  std::string& out = w.bytes();
  const std::size_t at = out.size();
  out.resize(at + rows * cols * sizeof(double));
  char* p = out.data() + at;
  for (Eigen::Index i = 0; i < c.samples.rows(); ++i)
    for (Eigen::Index j = 0; j < c.samples.cols(); ++j, p += sizeof(double))
      std::memcpy(p, &c.samples.coeffRef(i, j), sizeof(double));
  w.put<std::uint64_t>(c.valid.size());
  w.bytes().append(reinterpret_cast<const char*>(c.valid.data()), c.valid.size());
  return w;
}

std::string name_of(const Chunk& c) {
  return "chunk " + input::printable(c.vehicle) + "/" + input::printable(c.run) + "#" + std::to_string(c.sequence);
}

[[noreturn]] void reject(const Chunk& c, const std::string& why) {
  throw InputError(name_of(c) + ": " + why);
}

void check_shape(const Chunk& c, const RunAnnouncement& run, const ChunkLimits& limits) {
  const Eigen::Index rows = c.samples.rows();
  const Eigen::Index cols = c.samples.cols();
  if (rows <= 0) reject(c, "no sample rows");
  if (rows > limits.max_rows)
    reject(c,
           std::to_string(rows) + " rows exceed the limit of " + std::to_string(limits.max_rows));
  if (cols > limits.max_channels)
    reject(c, std::to_string(cols) + " channels exceed the limit of " +
                  std::to_string(limits.max_channels));
  if (static_cast<std::size_t>(cols) != run.channels.size())
    reject(c, std::to_string(cols) + " channels, the run announced " +
                  std::to_string(run.channels.size()));
  if (c.valid.size() != static_cast<std::size_t>(rows))
    reject(c,
           std::to_string(c.valid.size()) + " valid flags for " + std::to_string(rows) + " rows");
}

void check_values(const Chunk& c, const RunAnnouncement& run, const ChunkLimits& limits) {
  for (std::size_t i = 0; i < c.valid.size(); ++i)
    if (c.valid[i] > 1)
      reject(c, "row " + std::to_string(i) + ": valid flag " + std::to_string(c.valid[i]) +
                    " is not 0 or 1");
  // Row by row so the first bad value in time order is the one named.
  for (Eigen::Index i = 0; i < c.samples.rows(); ++i)
    for (Eigen::Index j = 0; j < c.samples.cols(); ++j) {
      const double v = c.samples(i, j);
      if (std::isfinite(v) && std::abs(v) <= limits.max_abs_value) continue;
      const std::string what = std::isnan(v)   ? "is NaN"
                               : std::isinf(v) ? "is infinite"
                                               : "= " + std::to_string(v) + " exceeds the limit";
      reject(c, "row " + std::to_string(i) + " (sample " +
                    std::to_string(c.first_sample_index + static_cast<std::uint64_t>(i)) +
                    "), channel '" + run.channels[static_cast<std::size_t>(j)].name + "' " + what);
    }
}

}  // namespace

std::uint32_t Chunk::compute_checksum() const {
  return detail::crc32_of(encode_body(*this).bytes());
}

std::string validate_and_encode(const Chunk& chunk, const RunAnnouncement& run,
                                const ChunkLimits& limits) {
  if (chunk.vehicle != run.vehicle)
    reject(chunk, "vehicle '" + input::printable(chunk.vehicle) + "' but the run is of '" +
                      input::printable(run.vehicle) + "'");
  if (chunk.run != run.run)
    reject(chunk, "run '" + input::printable(chunk.run) + "' but the run is '" + input::printable(run.run) + "'");
  check_shape(chunk, run, limits);  // first: the encoding below is sized by the shape
  detail::ByteWriter encoded = encode_body(chunk);
  const std::uint32_t expected = detail::crc32_of(encoded.bytes());
  if (chunk.checksum != expected)
    reject(chunk, "checksum " + std::to_string(chunk.checksum) + " does not match the content (" +
                      std::to_string(expected) + "): corrupted");
  check_values(chunk, run, limits);
  encoded.put<std::uint32_t>(chunk.checksum);
  return encoded.take();
}

void validate_chunk(const Chunk& chunk, const RunAnnouncement& run, const ChunkLimits& limits) {
  validate_and_encode(chunk, run, limits);
}

std::string encode_chunk(const Chunk& chunk) {
  detail::ByteWriter w = encode_body(chunk);
  w.put<std::uint32_t>(chunk.checksum);  // as carried: decode verifies it against the content
  return w.take();
}

Chunk decode_chunk(std::string_view bytes) {
  detail::ByteReader r(bytes, "chunk encoding");
  r.open(kMagic, kVersion);
  Chunk c;
  c.vehicle = r.get_string("vehicle");
  c.run = r.get_string("run");
  c.sequence = r.get<std::uint64_t>("sequence");
  c.first_sample_index = r.get<std::uint64_t>("first sample index");
  const auto rows = r.get<std::uint64_t>("rows");
  const auto cols = r.get<std::uint64_t>("columns");
  // With zero rows or zero columns there are no sample bytes to bound the other dimension by;
  // no valid chunk has either, and a corrupted count must not make the loops below or
  // encode_chunk's reservation work on an absurd size (a hang found by tests/fuzz/fuzz_chunk),
  // so it is bounded by the bytes left all the same.
  const std::uint64_t left = r.remaining();
  const bool fits = rows == 0 || cols == 0 ? std::max(rows, cols) <= left
                                           : rows <= left / sizeof(double) / cols;
  if (!fits)
    r.fail("truncated or corrupted: " + std::to_string(rows) + " x " + std::to_string(cols) +
           " samples claimed, " + std::to_string(r.remaining()) + " bytes left");
  c.samples.resize(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
  for (Eigen::Index i = 0; i < c.samples.rows(); ++i)
    for (Eigen::Index j = 0; j < c.samples.cols(); ++j) c.samples(i, j) = r.get<double>("samples");
  const auto flags = r.get<std::uint64_t>("flag count");
  if (flags > r.remaining()) r.fail("truncated: " + std::to_string(flags) + " flags claimed");
  c.valid.resize(flags);
  for (std::uint8_t& f : c.valid) f = r.get<std::uint8_t>("flags");
  r.expect_end();
  // verify_checksum() proved the stored value equals the CRC of the content.
  std::memcpy(&c.checksum, bytes.data() + bytes.size() - sizeof(c.checksum), sizeof(c.checksum));
  return c;
}

}  // namespace dynid::ingest
