#pragma once
// ASAM MDF 4.1x measurement files (.mf4, .MF4): the block structure, and the physical values of
// named channels. The CAN frames of a bus log are read by Mdf4BusReader (mdf4_bus.hpp).
//
// Layout read (all little-endian): the identification at byte 0 ("MDF     " or, for a file a
// logger did not finalize, "UnFinMF "; the version text at byte 8; the unfinalized flags at
// byte 60), then blocks, each "##XX", 4 reserved bytes, its length and its link count (64 bits
// each), its links (64-bit file offsets, 0 = none) and its data. Read: ##HD (start time in ns,
// time flags, comment), the ##DG chain (record id size), each DG's ##CG chain (name, comment,
// record id, cycle count, flags: bit 0 = VLSD group, data bytes, invalidation bytes), each CG's
// ##CN tree (name, unit, comment, channel type, sync type, data type, bit and byte offset, bit
// count; composition children are listed after their parent), ##CC conversions (identity, linear,
// rational, value-to-value with and without interpolation, value-range-to-value, value-to-text,
// value-range-to-text), ##TX and ##MD texts (an ##MD's <TX> element), and the data: ##DT, ##SD,
// ##DL chains and ##DZ (zlib deflate, plain or transposed), VLSD values from an ##SD stream or a
// VLSD channel group.
//
// Unfinalized files (the identification "UnFinMF "): a logger that loses power leaves the cycle
// counts and the length of the last data block unset. The last data block then runs to the next
// block after it or to the end of the file, the cycle counts are those of the records found, and
// a partial last record is dropped; notes() says so. Records are always counted from the data of
// a group with record ids, so a finalized file's counts only bound the data of sorted groups.
//
// Bounds (hostile files): every link and length is checked against the file size, a chain that
// comes back to a block it has visited is an error, a ##DZ inflates to at most
// kMaxInflatedBytes and at most 1032 times its size (zlib's limit), a cycle count needs the bytes
// it counts, and the metadata and all the data read (read_records, however often it is called)
// are at most kMaxBlocks blocks and kMaxDataBytes bytes in all (read_signals starts a budget of
// its own); the names and texts kept are at most kMaxTextBytes. Whatever is wrong throws InputError
// "<file>: offset <n>: <reason>" naming the block's offset. The file is read whole (at most
// kMaxFileBytes), since links point anywhere in it.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <dynid/error.hpp>

namespace dynid::can {

/// A structural error of an MDF4 file, at a byte offset (what BLF-like readers report).
class Mdf4Error : public InputError {
 public:
  Mdf4Error(const std::string& source, std::uint64_t offset, const std::string& reason);
  std::uint64_t offset() const { return offset_; }
  const std::string& reason() const { return reason_; }

 private:
  std::uint64_t offset_;
  std::string reason_;
};

/// A ##CC block: raw value -> physical value (or text, for the value-to-text kinds).
struct Mdf4Conversion {
  enum Kind : std::uint8_t {
    Identity = 0,
    Linear = 1,
    Rational = 2,
    Algebraic = 3,
    TableInterpolated = 4,
    Table = 5,
    RangeToValue = 6,
    ValueToText = 7,
    RangeToText = 8
  };
  std::uint8_t kind = Identity;
  std::vector<double> values;                     // cc_val
  std::vector<std::optional<std::string>> texts;  // per cc_ref: a text, or none (a nested ##CC)
  /// The physical value; a raw value that maps to a text gives itself (text() gives the text).
  double apply(double raw) const;
  /// The text the value-to-text kinds give for `raw` ("" when it maps to none).
  std::string text(double raw) const;
};

struct Mdf4Channel {
  enum Type : std::uint8_t { Fixed = 0, Vlsd = 1, Master = 2, VirtualMaster = 3, Sync = 4 };
  enum DataType : std::uint8_t {
    UintLe = 0,
    UintBe = 1,
    IntLe = 2,
    IntBe = 3,
    FloatLe = 4,
    FloatBe = 5,
    ByteArray = 10
  };
  std::string name;
  std::string unit;
  std::string comment;       // "" when none
  std::uint64_t offset = 0;  // of the ##CN block
  std::uint8_t type = Fixed;
  std::uint8_t sync_type = 0;
  std::uint8_t data_type = UintLe;
  std::uint8_t bit_offset = 0;
  std::uint32_t byte_offset = 0;  // after the record id
  std::uint32_t bit_count = 0;
  std::uint64_t data_link = 0;  // a VLSD channel's ##SD / ##DL / ##DZ, or its VLSD ##CG
  std::optional<Mdf4Conversion> conversion;
  bool is_master() const { return type == Master || type == VirtualMaster; }
};

struct Mdf4ChannelGroup {
  std::string name;     // the acquisition name (e.g. "CAN_DataFrame"), "" when none
  std::string comment;  // "" when none
  std::uint64_t offset = 0;
  std::uint64_t record_id = 0;
  std::uint64_t cycle_count = 0;  // as stored (see the unfinalized note above)
  std::uint16_t flags = 0;
  std::uint32_t data_bytes = 0;
  std::uint32_t inval_bytes = 0;
  std::vector<Mdf4Channel> channels;  // depth first: composition children after their parent
  bool is_vlsd() const { return (flags & 1U) != 0; }
  std::uint64_t record_bytes() const { return std::uint64_t{data_bytes} + inval_bytes; }
  /// The channel called `channel`, or nullptr.
  const Mdf4Channel* find(std::string_view channel) const;
  /// The master (time) channel, or nullptr.
  const Mdf4Channel* master() const;
};

struct Mdf4DataGroup {
  std::uint64_t offset = 0;
  std::uint8_t record_id_size = 0;  // 0, 1, 2, 4 or 8
  std::uint64_t data_link = 0;
  std::vector<Mdf4ChannelGroup> groups;
};

/// The records of one channel group, read from its data group's data.
struct Mdf4Records {
  /// A fixed group: `count` records of record_bytes() each. A VLSD group: its values one after
  /// the other, each a 32-bit length and its bytes (the layout of an ##SD block, which the
  /// offsets stored by the channels that point to the group index).
  std::vector<std::uint8_t> bytes;
  std::uint64_t count = 0;
};

/// Named channels of one channel group as physical values, with the master's.
struct Mdf4Signals {
  std::vector<double> time;                 // the master channel, physical (seconds from start)
  std::vector<std::string> names;           // as asked
  std::vector<std::vector<double>> values;  // values[i][k]: channel names[i] at time[k]
};

class Mdf4File {
 public:
  static constexpr std::uint64_t kMaxFileBytes = 2ULL << 30;
  static constexpr std::uint64_t kMaxInflatedBytes = 1ULL << 30;
  static constexpr std::size_t kMaxBlocks = 1U << 20;
  static constexpr std::uint64_t kMaxDataBytes = 4ULL << 30;
  static constexpr std::uint64_t kMaxTextBytes = 64ULL << 20;

  /// Reads and checks the file's metadata (not its data); throws InputError / Mdf4Error.
  explicit Mdf4File(const std::filesystem::path& path);
  /// The same from bytes in memory (tests, fuzzing); `source` names it in errors.
  Mdf4File(std::vector<std::uint8_t> bytes, std::string source);

  const std::string& source() const { return source_; }
  const std::string& version() const { return version_; }  // e.g. "4.11"
  bool unfinalized() const { return unfinalized_; }
  std::uint16_t unfinalized_flags() const { return unfinalized_flags_; }
  /// The measurement start (##HD), ns since 1970 (UTC unless the file says local time).
  std::int64_t start_ns() const { return start_ns_; }
  /// The file's comment (##HD): an ##TX's text or an ##MD's <TX> element; "" when none.
  const std::string& comment() const { return comment_; }
  std::uint64_t file_size() const { return bytes_.size(); }
  const std::vector<Mdf4DataGroup>& data_groups() const { return groups_; }
  /// What was recovered or dropped while reading (unfinalized files); grows as data is read.
  const std::vector<std::string>& notes() const { return notes_; }

  /// The records of every channel group of data group `dg` (index into data_groups()), in the
  /// order of its groups; throws Mdf4Error for data that cannot be read.
  std::vector<Mdf4Records> read_records(std::size_t dg) const;
  /// The first channel group called `name`: {data group, channel group}, or nullopt.
  std::optional<std::pair<std::size_t, std::size_t>> find_group(std::string_view name) const;
  /// Channels `names` of channel group `cg` of data group `dg`, each with its conversion
  /// applied, and the master channel; throws Mdf4Error naming a channel that is absent or not
  /// numeric.
  Mdf4Signals read_signals(std::size_t dg, std::size_t cg,
                           const std::vector<std::string>& names) const;

  /// The raw value of a fixed numeric channel in a record (the bytes after its record id), as
  /// a double; the caller checked the channel with check_numeric().
  static double raw_value(const Mdf4Channel& channel, const std::uint8_t* record);
  /// The raw bits of an integer channel of at most 64 bits.
  static std::uint64_t raw_bits(const Mdf4Channel& channel, const std::uint8_t* record);
  /// Throws Mdf4Error unless `channel` is a numeric value that fits in records of `group`.
  void check_numeric(const Mdf4ChannelGroup& group, const Mdf4Channel& channel) const;
  /// The values of VLSD channel `channel` of data group `dg` (an ##SD stream, or the records
  /// of the VLSD channel group it links to, taken from `records` of read_records(dg)).
  std::vector<std::uint8_t> vlsd_stream(std::size_t dg, const Mdf4Channel& channel,
                                        const std::vector<Mdf4Records>& records) const;
  /// The bytes of the VLSD value at `offset` of `stream`; throws Mdf4Error naming `channel`
  /// when the offset or the length runs past the stream.
  std::span<const std::uint8_t> vlsd_value(const std::vector<std::uint8_t>& stream,
                                           std::uint64_t offset, const Mdf4Channel& channel) const;

 private:
  struct Block;
  void parse();
  Block block(std::uint64_t offset, std::string_view expect = {}) const;
  std::string text(std::uint64_t link) const;
  Mdf4Conversion conversion(std::uint64_t link, int depth) const;
  Mdf4ChannelGroup channel_group(const Block& cg);
  void parse_channels(std::uint64_t first, Mdf4ChannelGroup& group, int depth,
                      std::set<std::uint64_t>& seen);
  // The data a link leads to (##DT, ##SD, ##DZ, ##DL/##HL lists); last_may_run_on: the last
  // ##DT of an unfinalized file runs to the next block.
  std::vector<std::uint8_t> data_of(std::uint64_t link, bool last_may_run_on) const;
  void append_block_data(std::uint64_t link, std::vector<std::uint8_t>& out, bool last_may_run_on,
                         std::set<std::uint64_t>& seen) const;
  void append_zipped(const Block& block, std::vector<std::uint8_t>& out) const;
  void read_sorted(const Mdf4DataGroup& group, const std::vector<std::uint8_t>& data,
                   Mdf4Records& out) const;
  void read_unsorted(const Mdf4DataGroup& group, const std::vector<std::uint8_t>& data,
                     std::vector<Mdf4Records>& out) const;
  std::uint64_t next_block_after(std::uint64_t offset) const;
  [[noreturn]] void fail(std::uint64_t offset, const std::string& reason) const;
  void count_block() const;
  void spend_data(std::uint64_t offset, std::uint64_t bytes) const;
  void reset_budget() const;

  std::string source_;
  std::vector<std::uint8_t> bytes_;
  std::string version_;
  bool unfinalized_ = false;
  std::uint16_t unfinalized_flags_ = 0;
  std::int64_t start_ns_ = 0;
  std::string comment_;
  std::vector<Mdf4DataGroup> groups_;
  std::vector<std::uint64_t> metadata_blocks_;  // sorted offsets of the blocks parsed
  mutable std::vector<std::string> notes_;
  mutable std::size_t blocks_read_ = 0;
  mutable std::uint64_t data_read_ = 0;
  mutable std::uint64_t text_kept_ = 0;
};

}  // namespace dynid::can
