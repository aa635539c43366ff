#include "byte_codec.hpp"

#include <zlib.h>

#include <algorithm>

#include "dynid/error.hpp"

namespace dynid::ingest::detail {

std::uint32_t crc32_of(std::string_view bytes) {
  // zlib takes the length as uInt: feed large inputs piecewise.
  uLong crc = crc32(0L, Z_NULL, 0);
  while (!bytes.empty()) {
    const std::size_t n = std::min<std::size_t>(bytes.size(), 1u << 30);
    crc = crc32(crc, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(n));
    bytes.remove_prefix(n);
  }
  return static_cast<std::uint32_t>(crc);
}

void ByteWriter::put_string(std::string_view s) {
  put<std::uint32_t>(static_cast<std::uint32_t>(s.size()));
  out_.append(s);
}

void ByteWriter::put_matrix(const Eigen::MatrixXd& m) {
  put<std::uint64_t>(static_cast<std::uint64_t>(m.rows()));
  put<std::uint64_t>(static_cast<std::uint64_t>(m.cols()));
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index i = 0; i < m.rows(); ++i) put<double>(m(i, j));
}

void ByteWriter::put_bytes(std::string_view bytes) {
  put<std::uint64_t>(bytes.size());
  out_.append(bytes);
}

void ByteReader::fail(const std::string& why) const {
  throw InputError(what_ + ": " + why);
}

void ByteReader::require(std::size_t count, const char* field) const {
  if (count > remaining())
    fail(std::string("truncated: ") + field + " needs " + std::to_string(count) +
         " bytes at byte " + std::to_string(pos_) + ", " + std::to_string(remaining()) + " left");
}

bool ByteReader::get_bool(const char* field) {
  const auto v = get<std::uint8_t>(field);
  if (v > 1) fail(std::string(field) + " is " + std::to_string(v) + ", not 0 or 1");
  return v == 1;
}

std::string ByteReader::get_string(const char* field) {
  const auto n = get<std::uint32_t>(field);
  require(n, field);
  std::string s(in_.substr(pos_, n));
  pos_ += n;
  return s;
}

Eigen::MatrixXd ByteReader::get_matrix(const char* field) {
  const auto rows = get<std::uint64_t>(field);
  const auto cols = get<std::uint64_t>(field);
  // Checked against what is left before allocating: a corrupted size is an error, not a bad_alloc.
  if (cols != 0 && rows > remaining() / sizeof(double) / cols)
    fail(std::string("truncated or corrupted: ") + field + " claims " + std::to_string(rows) +
         " x " + std::to_string(cols) + " values, " + std::to_string(remaining()) + " bytes left");
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index i = 0; i < m.rows(); ++i) m(i, j) = get<double>(field);
  return m;
}

std::string_view ByteReader::get_bytes(const char* field) {
  const auto n = get<std::uint64_t>(field);
  require(n, field);
  const std::string_view s = in_.substr(pos_, n);
  pos_ += n;
  return s;
}

std::uint16_t ByteReader::expect_header(std::string_view magic, std::uint16_t oldest, std::uint16_t newest) {
  if (in_.substr(0, magic.size()) != magic) fail("bad magic (not a " + what_ + ")");
  pos_ = magic.size();
  const auto found = get<std::uint16_t>("version");
  if (found < oldest || found > newest)
    fail("unsupported format version " + std::to_string(found) + " (this build reads version " +
         (oldest == newest ? std::to_string(newest) : std::to_string(oldest) + " to " + std::to_string(newest)) +
         ")");
  return found;
}

void ByteReader::verify_checksum() {
  if (in_.size() < pos_ + sizeof(std::uint32_t)) fail("truncated: no checksum");
  const std::string_view body = in_.substr(0, in_.size() - sizeof(std::uint32_t));
  std::uint32_t stored;
  std::memcpy(&stored, in_.data() + body.size(), sizeof(stored));
  if (stored != crc32_of(body)) fail("checksum mismatch (corrupted)");
  in_ = body;
}

void ByteReader::open(std::string_view magic, std::uint16_t version) { open(magic, version, version); }

std::uint16_t ByteReader::open(std::string_view magic, std::uint16_t oldest, std::uint16_t newest) {
  const std::uint16_t found = expect_header(magic, oldest, newest);
  verify_checksum();
  return found;
}

void ByteReader::expect_end() const {
  if (remaining() != 0) fail(std::to_string(remaining()) + " trailing bytes");
}

}  // namespace dynid::ingest::detail
