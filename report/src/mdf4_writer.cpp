#include "dynid/report/mdf4_writer.hpp"

#include <cstring>
#include <limits>
#include <set>
#include <stdexcept>

#include "dynid/report/residual_html.hpp"  // html_escape: the XML of an ##MD block

namespace dynid::report {
namespace {

// The file being written: blocks appended at 8-byte boundaries, links patched once their targets
// exist (a link is a 64-bit file offset; 0 is "none").
class Mdf4Bytes {
 public:
  Mdf4Bytes() { identification(); }

  // Appends block `id` ("##HD") with `links` links (all 0 for now) and `data`; its offset.
  std::uint64_t block(const char* id, std::size_t links, const std::string& data) {
    const std::uint64_t at = bytes_.size();
    const std::uint64_t length = 24 + 8 * links + data.size();
    bytes_.append(id, 4);
    bytes_.append(4, '\0');
    put(length);
    put(static_cast<std::uint64_t>(links));
    bytes_.append(8 * links, '\0');
    bytes_ += data;
    bytes_.append((8 - bytes_.size() % 8) % 8, '\0');
    return at;
  }

  void link(std::uint64_t block, std::size_t index, std::uint64_t target) {
    std::memcpy(bytes_.data() + block + 24 + 8 * index, &target, 8);
  }

  // A ##TX (or ##MD) block holding `text`, zero-terminated; 0 for an empty text.
  std::uint64_t text(const std::string& text, const char* id = "##TX") {
    if (text.empty()) return 0;
    return block(id, 0, text + '\0');
  }

  std::string take() { return std::move(bytes_); }

 private:
  template <typename T>
  void put(T value) {
    bytes_.append(reinterpret_cast<const char*>(&value), sizeof value);
  }

  void identification() {
    bytes_ = "MDF     4.10    dynid   ";
    bytes_.append(4, '\0');
    put(std::uint16_t{410});  // at byte 28
    bytes_.append(64 - bytes_.size(), '\0');
  }

  std::string bytes_;
};

template <typename T>
void append(std::string& data, T value) {
  data.append(reinterpret_cast<const char*>(&value), sizeof value);
}

std::string header_data(std::int64_t start_ns) {
  std::string d;
  append(d, static_cast<std::uint64_t>(start_ns));
  append(d, std::int16_t{0});  // time zone offset (min): the time is UTC
  append(d, std::int16_t{0});  // daylight saving offset (min)
  append(d, std::uint8_t{0});  // time flags: UTC, no offsets given
  append(d, std::uint8_t{0});  // time class: local PC reference
  append(d, std::uint8_t{0});  // flags: no start angle or distance
  append(d, std::uint8_t{0});
  append(d, 0.0);  // start angle (rad)
  append(d, 0.0);  // start distance (m)
  return d;
}

std::string history_data(std::int64_t start_ns) {
  std::string d;
  append(d, static_cast<std::uint64_t>(start_ns));
  append(d, std::int16_t{0});
  append(d, std::int16_t{0});
  append(d, std::uint8_t{0});
  d.append(3, '\0');
  return d;
}

// A float64 channel at `byte_offset` of the record: the master (type 2, sync 1: time) or a value.
std::string channel_data(bool master, std::uint32_t byte_offset) {
  std::string d;
  append(d, std::uint8_t{master ? std::uint8_t{2} : std::uint8_t{0}});  // channel type
  append(d, std::uint8_t{master ? std::uint8_t{1} : std::uint8_t{0}});  // sync type
  append(d, std::uint8_t{4});  // data type: IEEE 754 float, little-endian
  append(d, std::uint8_t{0});  // bit offset
  append(d, byte_offset);
  append(d, std::uint32_t{64});  // bit count
  append(d, std::uint32_t{0});   // flags
  append(d, std::uint32_t{0});   // invalidation bit position
  append(d, std::uint8_t{0});    // precision (not valid: flags bit 2 clear)
  append(d, std::uint8_t{0});
  append(d, std::uint16_t{0});                 // attachments
  for (int k = 0; k < 6; ++k) append(d, 0.0);  // value range and limits (not valid)
  return d;
}

std::string group_data(std::uint64_t records, std::uint32_t record_bytes) {
  std::string d;
  append(d, std::uint64_t{0});  // record id
  append(d, records);           // cycle count
  append(d, std::uint16_t{0});  // flags
  append(d, std::uint16_t{0});  // path separator
  d.append(4, '\0');
  append(d, record_bytes);
  append(d, std::uint32_t{0});  // invalidation bytes
  return d;
}

void check(const Mdf4Table& table) {
  if (table.name.empty()) throw std::invalid_argument("write_mdf4: a table without a name");
  std::set<std::string> names{"time"};
  for (const Mdf4Column& column : table.columns) {
    if (column.name.empty() || !names.insert(column.name).second)
      throw std::invalid_argument("write_mdf4: table '" + table.name + "': column '" + column.name +
                                  "' is empty, 'time' or repeated");
    if (column.values.size() != table.time_s.size())
      throw std::invalid_argument("write_mdf4: table '" + table.name + "': column '" + column.name +
                                  "' has " + std::to_string(column.values.size()) + " values for " +
                                  std::to_string(table.time_s.size()) + " times");
  }
  if ((table.columns.size() + 1) * 8 > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("write_mdf4: table '" + table.name + "': too many columns");
}

// Channel-group chain links (##CG): cg_next, cn_first, acq_name, acq_source, sr_first, comment.
// Channel links (##CN): cn_next, composition, name, source, conversion, data, unit, comment.
std::uint64_t write_table(Mdf4Bytes& file, const Mdf4Table& table) {
  const std::uint32_t record_bytes = static_cast<std::uint32_t>(8 * (table.columns.size() + 1));
  const std::uint64_t dg = file.block("##DG", 4, std::string(8, '\0'));  // no record ids
  const std::uint64_t cg = file.block("##CG", 6, group_data(table.time_s.size(), record_bytes));
  file.link(dg, 1, cg);
  file.link(cg, 2, file.text(table.name));
  file.link(cg, 5, file.text(table.comment));
  std::uint64_t previous = 0;
  for (std::size_t c = 0; c <= table.columns.size(); ++c) {
    const bool master = c == 0;
    const std::uint64_t cn =
        file.block("##CN", 8, channel_data(master, static_cast<std::uint32_t>(8 * c)));
    file.link(cn, 2, file.text(master ? "time" : table.columns[c - 1].name));
    file.link(cn, 6, file.text(master ? "s" : table.columns[c - 1].unit));
    if (!master) file.link(cn, 7, file.text(table.columns[c - 1].comment));
    file.link(previous == 0 ? cg : previous, previous == 0 ? 1 : 0, cn);
    previous = cn;
  }
  std::string records;
  records.reserve(table.time_s.size() * record_bytes);
  for (std::size_t k = 0; k < table.time_s.size(); ++k) {
    append(records, table.time_s[k]);
    for (const Mdf4Column& column : table.columns) append(records, column.values[k]);
  }
  file.link(dg, 2, file.block("##DT", 0, records));
  return dg;
}

}  // namespace

std::string write_mdf4(const Mdf4Document& document) {
  for (const Mdf4Table& table : document.tables) check(table);
  Mdf4Bytes file;
  const std::uint64_t hd = file.block("##HD", 6, header_data(document.start_ns));
  const std::uint64_t fh = file.block("##FH", 2, history_data(document.start_ns));
  file.link(hd, 1, fh);
  file.link(fh, 1,
            file.text("<FHcomment><TX>written by dynid</TX><tool_id>dynid</tool_id>"
                      "<tool_vendor>dynid</tool_vendor><tool_version>1</tool_version></FHcomment>",
                      "##MD"));
  if (!document.comment.empty())
    file.link(
        hd, 5,
        file.text("<HDcomment><TX>" + html_escape(document.comment) + "</TX></HDcomment>", "##MD"));
  std::uint64_t previous = 0;
  for (const Mdf4Table& table : document.tables) {
    const std::uint64_t dg = write_table(file, table);
    file.link(previous == 0 ? hd : previous, 0, dg);
    previous = dg;
  }
  return file.take();
}

}  // namespace dynid::report
