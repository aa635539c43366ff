#pragma once
// Private to the ingest area: the little-endian byte layout shared by the chunk encoding, the
// announcement encoding and the run checkpoint. Values are written as their exact bit patterns
// (doubles as IEEE-754 binary64), so a round trip is exact. The reader checks every length
// against the bytes that are left *before* allocating, so a corrupted size cannot make it
// allocate absurd amounts, and throws InputError naming the document and what was truncated.
#include <Eigen/Core>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>

namespace dynid::ingest::detail {

static_assert(std::endian::native == std::endian::little,
              "the ingest encodings are little-endian; add byte swapping for this host");

std::uint32_t crc32_of(std::string_view bytes);

class ByteWriter {
 public:
  template <typename T>
  void put(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    out_.append(raw, sizeof(T));
  }
  void put_bool(bool value) { put<std::uint8_t>(value ? 1 : 0); }
  void put_string(std::string_view s);
  /// rows, cols (u64 each), then the values column by column.
  void put_matrix(const Eigen::MatrixXd& m);
  void put_bytes(std::string_view bytes);  ///< u64 length, then the bytes
  /// Appends the CRC-32 of everything written so far.
  void seal() { put<std::uint32_t>(crc32_of(out_)); }

  std::string& bytes() { return out_; }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

class ByteReader {
 public:
  /// `what` names the document in error messages, e.g. "chunk encoding".
  ByteReader(std::string_view bytes, std::string what) : in_(bytes), what_(std::move(what)) {}

  template <typename T>
  T get(const char* field) {
    static_assert(std::is_trivially_copyable_v<T>);
    require(sizeof(T), field);
    T value;
    std::memcpy(&value, in_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  bool get_bool(const char* field);
  std::string get_string(const char* field);
  Eigen::MatrixXd get_matrix(const char* field);
  std::string_view get_bytes(const char* field);
  /// Checks the magic tag, the version, and that the last 4 bytes are the CRC-32 of the rest
  /// (excluded from reading); throws naming what was found.
  void open(std::string_view magic, std::uint16_t version);
  /// open() accepting any version in [oldest, newest]; returns the one found.
  std::uint16_t open(std::string_view magic, std::uint16_t oldest, std::uint16_t newest);
  /// Throws unless every byte was read.
  void expect_end() const;
  [[noreturn]] void fail(const std::string& why) const;
  std::size_t remaining() const { return in_.size() - pos_; }

 private:
  void require(std::size_t count, const char* field) const;
  std::uint16_t expect_header(std::string_view magic, std::uint16_t oldest, std::uint16_t newest);
  void verify_checksum();

  std::string_view in_;
  std::string what_;
  std::size_t pos_ = 0;
};

}  // namespace dynid::ingest::detail
