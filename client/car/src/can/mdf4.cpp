#include <dynid/can/mdf4.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <string_view>
#include <utility>

#include <zlib.h>

#include <dynid/input/input_file.hpp>

namespace dynid::can {
namespace {

constexpr std::size_t kIdBytes = 64;
constexpr std::uint64_t kBlockHeader = 24;
constexpr int kMaxComposition = 8;
constexpr int kMaxNestedConversions = 4;
constexpr std::uint16_t kUnfinLastDt = 4;  // id_unfin_flags: the last ##DT's length is not set

std::uint16_t u16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
std::uint32_t u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
std::uint64_t u64(const std::uint8_t* p) {
  return u32(p) | (static_cast<std::uint64_t>(u32(p + 4)) << 32);
}
double f64(const std::uint8_t* p) {
  return std::bit_cast<double>(u64(p));
}

std::string trimmed(const std::uint8_t* p, std::size_t n) {
  std::string s(reinterpret_cast<const char*>(p), n);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
  return s;
}

std::string hex(unsigned v) {
  static const char* digits = "0123456789abcdef";
  std::string s;
  do {
    s.insert(s.begin(), digits[v & 15U]);
    v >>= 4;
  } while (v != 0);
  return "0x" + s;
}

// Whether a value-to-text range [lo, hi] holds `raw` (the spec's ranges include both ends).
bool in_range(double raw, double lo, double hi) {
  return raw >= lo && raw <= hi;
}

// A table of (key, value) pairs sorted by key: the value at `raw`, interpolated or nearest.
double table_value(const std::vector<double>& kv, double raw, bool interpolate) {
  const std::size_t n = kv.size() / 2;
  if (n == 0) return raw;
  if (raw <= kv[0]) return kv[1];
  if (raw >= kv[2 * (n - 1)]) return kv[2 * (n - 1) + 1];
  std::size_t i = 1;
  while (i < n && kv[2 * i] < raw) ++i;
  const double x0 = kv[2 * (i - 1)], y0 = kv[2 * (i - 1) + 1], x1 = kv[2 * i], y1 = kv[2 * i + 1];
  if (interpolate) return x1 == x0 ? y0 : y0 + (y1 - y0) * (raw - x0) / (x1 - x0);
  return raw - x0 <= x1 - raw ? y0 : y1;
}

}  // namespace

Mdf4Error::Mdf4Error(const std::string& source, std::uint64_t offset, const std::string& reason)
    : InputError(source + ": offset " + std::to_string(offset) + ": " + reason),
      offset_(offset),
      reason_(reason) {}

double Mdf4Conversion::apply(double raw) const {
  const auto& v = values;
  switch (kind) {
    case Linear:
      return v[0] + v[1] * raw;
    case Rational:
      return (v[0] * raw * raw + v[1] * raw + v[2]) / (v[3] * raw * raw + v[4] * raw + v[5]);
    case TableInterpolated:
      return table_value(v, raw, true);
    case Table:
      return table_value(v, raw, false);
    case RangeToValue:
      for (std::size_t i = 0; i + 3 < v.size(); i += 3)
        if (in_range(raw, v[i], v[i + 1])) return v[i + 2];
      return v.back();  // the default
    default:
      return raw;  // identity; the text kinds keep the number
  }
}

std::string Mdf4Conversion::text(double raw) const {
  std::size_t hit = texts.empty() ? 0 : texts.size() - 1;  // the default is the last reference
  if (kind == ValueToText) {
    for (std::size_t i = 0; i < values.size() && i + 1 < texts.size(); ++i)
      if (values[i] == raw) hit = i;
  } else if (kind == RangeToText) {
    for (std::size_t i = 0; 2 * i + 1 < values.size() && i + 1 < texts.size(); ++i)
      if (in_range(raw, values[2 * i], values[2 * i + 1])) {
        hit = i;
        break;
      }
  } else {
    return {};
  }
  return hit < texts.size() && texts[hit] ? *texts[hit] : std::string();
}

const Mdf4Channel* Mdf4ChannelGroup::find(std::string_view channel) const {
  for (const auto& c : channels)
    if (c.name == channel) return &c;
  return nullptr;
}

const Mdf4Channel* Mdf4ChannelGroup::master() const {
  for (const auto& c : channels)
    if (c.is_master()) return &c;
  return nullptr;
}

// A block as found at an offset: checked to lie inside the file with its links.
struct Mdf4File::Block {
  std::uint64_t offset = 0;
  std::string id;  // "DT", "CG", ...
  std::uint64_t length = 0;
  std::uint64_t link_count = 0;
  const std::uint8_t* links = nullptr;
  const std::uint8_t* data = nullptr;
  std::uint64_t data_size = 0;
  std::uint64_t link(std::uint64_t i) const { return i < link_count ? u64(links + 8 * i) : 0; }
};

Mdf4File::Mdf4File(const std::filesystem::path& path) : source_(path.filename().string()) {
  input::check_input_file(path, "MDF4 file", kMaxFileBytes);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open the MDF4 file");
  bytes_.resize(static_cast<std::size_t>(std::filesystem::file_size(path)));
  in.read(reinterpret_cast<char*>(bytes_.data()), static_cast<std::streamsize>(bytes_.size()));
  if (static_cast<std::size_t>(in.gcount()) != bytes_.size())
    throw InputError(path.string() + ": cannot read the MDF4 file");
  parse();
}

Mdf4File::Mdf4File(std::vector<std::uint8_t> bytes, std::string source)
    : source_(std::move(source)), bytes_(std::move(bytes)) {
  if (bytes_.size() > kMaxFileBytes)
    fail(0, "larger than " + std::to_string(kMaxFileBytes) + " bytes");
  parse();
}

void Mdf4File::fail(std::uint64_t offset, const std::string& reason) const {
  throw Mdf4Error(source_, offset, reason);
}

// Every block read counts, over the reading of all data groups: a file of many small
// structures that link to the same blocks again and again ends here.
void Mdf4File::count_block() const {
  if (++blocks_read_ > kMaxBlocks)
    fail(0, "more than " + std::to_string(kMaxBlocks) + " blocks to read");
}

// Data read counts the same way: data groups that all list the same blocks, or zipped blocks
// that inflate to the limit, end at kMaxDataBytes in all.
void Mdf4File::spend_data(std::uint64_t offset, std::uint64_t bytes) const {
  data_read_ += bytes;
  if (data_read_ > kMaxDataBytes)
    fail(offset, "more than " + std::to_string(kMaxDataBytes) + " bytes of data to read");
}

void Mdf4File::reset_budget() const {
  blocks_read_ = 0;
  data_read_ = 0;
}

Mdf4File::Block Mdf4File::block(std::uint64_t offset, std::string_view expect) const {
  count_block();
  const std::uint64_t size = bytes_.size();
  if (offset < kIdBytes || offset > size || size - offset < kBlockHeader)
    fail(offset, "link to a block header outside the file of " + std::to_string(size) + " bytes");
  const std::uint8_t* p = bytes_.data() + offset;
  Block b;
  b.offset = offset;
  if (p[0] != '#' || p[1] != '#') fail(offset, "no block here (a block starts with '##')");
  b.id.assign(reinterpret_cast<const char*>(p + 2), 2);
  b.length = u64(p + 8);
  b.link_count = u64(p + 16);
  if (b.length < kBlockHeader || b.length > size - offset)
    fail(offset, "##" + b.id + " block of " + std::to_string(b.length) +
                     " bytes runs past the end of the file (" + std::to_string(size) + " bytes)");
  if (b.link_count > (b.length - kBlockHeader) / 8)
    fail(offset, "##" + b.id + " block of " + std::to_string(b.length) + " bytes cannot hold its " +
                     std::to_string(b.link_count) + " links");
  b.links = p + kBlockHeader;
  b.data = b.links + 8 * b.link_count;
  b.data_size = b.length - kBlockHeader - 8 * b.link_count;
  bool expected = expect.empty();
  for (std::size_t i = 0; i + 1 < expect.size(); i += 2)
    expected = expected || expect.substr(i, 2) == b.id;
  if (!expected)
    fail(offset,
         "##" + b.id + " block where a ##" + std::string(expect.substr(0, 2)) + " was expected");
  return b;
}

namespace {

// XML's five predefined entities in an ##MD's <TX> text; any other '&' is kept as it is.
std::string xml_unescaped(const std::string& s) {
  static constexpr std::pair<std::string_view, char> kEntities[] = {
      {"&lt;", '<'}, {"&gt;", '>'}, {"&amp;", '&'}, {"&quot;", '"'}, {"&apos;", '\''}};
  std::string out;
  for (std::size_t k = 0; k < s.size();) {
    bool replaced = false;
    for (const auto& [entity, c] : kEntities)
      if (s.compare(k, entity.size(), entity) == 0) {
        out += c;
        k += entity.size();
        replaced = true;
        break;
      }
    if (!replaced) out += s[k++];
  }
  return out;
}

}  // namespace

// ##TX: the text; ##MD: its <TX> element (the XML's comment text, entities replaced) or the whole
// XML.
std::string Mdf4File::text(std::uint64_t link) const {
  if (link == 0) return {};
  const Block b = block(link, "TXMD");
  const auto* p = reinterpret_cast<const char*>(b.data);
  std::string s(p, strnlen(p, b.data_size));
  if (b.id == "MD") {
    const auto open = s.find("<TX>"), close = s.find("</TX>");
    if (open != std::string::npos && close != std::string::npos && close > open)
      s = xml_unescaped(s.substr(open + 4, close - open - 4));
  }
  // Names are kept: many channels naming one huge text must not multiply it in memory.
  text_kept_ += s.size();
  if (text_kept_ > kMaxTextBytes)
    fail(link, "more than " + std::to_string(kMaxTextBytes) + " bytes of names and texts");
  return s;
}

void Mdf4File::parse() {
  if (bytes_.size() < kIdBytes)
    fail(0, "file of " + std::to_string(bytes_.size()) +
                " bytes, shorter than the 64-byte MDF identification");
  const std::string id(reinterpret_cast<const char*>(bytes_.data()), 8);
  if (id != "MDF     " && id != "UnFinMF ")
    fail(0, "not an MDF file (it starts with neither 'MDF' nor 'UnFinMF')");
  unfinalized_ = id == "UnFinMF ";
  version_ = trimmed(bytes_.data() + 8, 8);
  if (version_.rfind("4.", 0) != 0) fail(8, "MDF version '" + version_ + "': only MDF 4.x is read");
  unfinalized_flags_ = u16(bytes_.data() + 60);
  const Block hd = block(kIdBytes, "HD");
  if (hd.data_size < 16) fail(kIdBytes, "##HD block too short for its start time");
  const std::uint64_t start = u64(hd.data);
  if (start > static_cast<std::uint64_t>(INT64_MAX / 2)) fail(kIdBytes, "start time out of range");
  start_ns_ = static_cast<std::int64_t>(start);
  comment_ = text(hd.link(5));
  metadata_blocks_.push_back(kIdBytes);
  std::set<std::uint64_t> seen;
  for (std::uint64_t at = hd.link(0); at != 0;) {
    if (!seen.insert(at).second) fail(at, "the data group chain comes back to this ##DG (a cycle)");
    const Block dg = block(at, "DG");
    if (dg.data_size < 1) fail(at, "##DG block too short");
    Mdf4DataGroup group;
    group.offset = at;
    group.record_id_size = dg.data[0];
    group.data_link = dg.link(2);
    if (group.record_id_size != 0 && group.record_id_size != 1 && group.record_id_size != 2 &&
        group.record_id_size != 4 && group.record_id_size != 8)
      fail(at, "record id size " + std::to_string(group.record_id_size) + " (0, 1, 2, 4 or 8)");
    std::set<std::uint64_t> record_ids;
    for (std::uint64_t cg_at = dg.link(1); cg_at != 0;) {
      if (!seen.insert(cg_at).second)
        fail(cg_at, "the channel group chain comes back to this ##CG (a cycle)");
      const Block cg = block(cg_at, "CG");
      Mdf4ChannelGroup g = channel_group(cg);
      if (group.record_id_size != 0 && !record_ids.insert(g.record_id).second)
        fail(cg_at, "record id " + std::to_string(g.record_id) + " used by two channel groups");
      group.groups.push_back(std::move(g));
      metadata_blocks_.push_back(cg_at);
      cg_at = cg.link(0);
    }
    if (group.record_id_size == 0 && group.groups.size() > 1)
      fail(at, "a data group without record ids holds " + std::to_string(group.groups.size()) +
                   " channel groups");
    metadata_blocks_.push_back(at);
    if (group.data_link != 0) metadata_blocks_.push_back(group.data_link);
    groups_.push_back(std::move(group));
    at = dg.link(0);
  }
  std::sort(metadata_blocks_.begin(), metadata_blocks_.end());
}

// A ##CG and its channels.
Mdf4ChannelGroup Mdf4File::channel_group(const Block& cg) {
  if (cg.data_size < 32) fail(cg.offset, "##CG block too short");
  Mdf4ChannelGroup g;
  g.offset = cg.offset;
  g.name = text(cg.link(2));
  g.comment = text(cg.link(5));
  g.record_id = u64(cg.data);
  g.cycle_count = u64(cg.data + 8);
  g.flags = u16(cg.data + 16);
  g.data_bytes = u32(cg.data + 24);
  g.inval_bytes = u32(cg.data + 28);
  std::set<std::uint64_t> channels_seen;
  parse_channels(cg.link(1), g, 0, channels_seen);
  return g;
}

void Mdf4File::parse_channels(std::uint64_t first, Mdf4ChannelGroup& group, int depth,
                              std::set<std::uint64_t>& seen) {
  if (depth > kMaxComposition)
    fail(first, "channel composition deeper than " + std::to_string(kMaxComposition));
  for (std::uint64_t at = first; at != 0;) {
    if (!seen.insert(at).second) fail(at, "the channel chain comes back to this ##CN (a cycle)");
    const Block cn = block(at, depth == 0 ? "CN" : "CNCA");
    if (cn.id == "CA") return;  // an array composition: its elements are not read
    if (cn.data_size < 16) fail(at, "##CN block too short");
    Mdf4Channel c;
    c.offset = at;
    c.name = text(cn.link(2));
    c.unit = text(cn.link(6));
    c.comment = text(cn.link(7));
    c.type = cn.data[0];
    c.sync_type = cn.data[1];
    c.data_type = cn.data[2];
    c.bit_offset = cn.data[3];
    c.byte_offset = u32(cn.data + 4);
    c.bit_count = u32(cn.data + 8);
    c.data_link = cn.link(5);
    if (c.bit_offset > 7)
      fail(at, "channel bit offset " + std::to_string(c.bit_offset) + " (0..7)");
    if (cn.link(4) != 0) c.conversion = conversion(cn.link(4), 0);
    metadata_blocks_.push_back(at);
    group.channels.push_back(std::move(c));
    if (cn.link(1) != 0) parse_channels(cn.link(1), group, depth + 1, seen);
    at = cn.link(0);
  }
}

Mdf4Conversion Mdf4File::conversion(std::uint64_t link, int depth) const {
  if (depth > kMaxNestedConversions)
    fail(link, "conversions nested deeper than " + std::to_string(kMaxNestedConversions));
  const Block cc = block(link, "CC");
  if (cc.data_size < 24) fail(link, "##CC block too short");
  Mdf4Conversion c;
  c.kind = cc.data[0];
  const std::uint16_t refs = u16(cc.data + 4);
  const std::uint16_t vals = u16(cc.data + 6);
  if (cc.data_size < 24 + 8ULL * vals || cc.link_count < 4ULL + refs)
    fail(link, "##CC block cannot hold its " + std::to_string(vals) + " values and " +
                   std::to_string(refs) + " references");
  for (std::uint16_t i = 0; i < vals; ++i) c.values.push_back(f64(cc.data + 24 + 8 * i));
  const std::size_t n = vals;
  bool ok = true;
  switch (c.kind) {
    case Mdf4Conversion::Identity:
      break;
    case Mdf4Conversion::Linear:
      ok = n >= 2;
      break;
    case Mdf4Conversion::Rational:
      ok = n >= 6;
      break;
    case Mdf4Conversion::TableInterpolated:
    case Mdf4Conversion::Table:
      ok = n % 2 == 0;
      break;
    case Mdf4Conversion::RangeToValue:
      ok = n % 3 == 1;
      break;
    case Mdf4Conversion::ValueToText:
      ok = refs == n + 1;
      break;
    case Mdf4Conversion::RangeToText:
      ok = n % 2 == 0 && refs == n / 2 + 1;
      break;
    default:
      break;  // read, refused only when a value is asked of it (check_numeric)
  }
  if (!ok)
    fail(link, "conversion kind " + std::to_string(c.kind) + " with " + std::to_string(n) +
                   " values and " + std::to_string(refs) + " references is malformed");
  for (std::uint16_t i = 0; i < refs; ++i) {
    const std::uint64_t ref = cc.link(4 + i);
    if (ref == 0) {
      c.texts.emplace_back();
      continue;
    }
    const Block r = block(ref);
    if (r.id == "CC")
      (void)conversion(ref, depth + 1),
          c.texts.emplace_back();  // checked; a nested scale gives the number
    else
      c.texts.emplace_back(text(ref));
  }
  return c;
}

std::uint64_t Mdf4File::next_block_after(std::uint64_t offset) const {
  const auto it = std::upper_bound(metadata_blocks_.begin(), metadata_blocks_.end(), offset);
  return it == metadata_blocks_.end() ? bytes_.size() : *it;
}

std::vector<std::uint8_t> Mdf4File::data_of(std::uint64_t link, bool last_may_run_on) const {
  std::vector<std::uint8_t> out;
  std::set<std::uint64_t> seen;
  append_block_data(link, out, last_may_run_on, seen);
  return out;
}

// One data block (or a list of them) appended to `out`.
void Mdf4File::append_block_data(std::uint64_t link, std::vector<std::uint8_t>& out,
                                 bool last_may_run_on, std::set<std::uint64_t>& seen) const {
  if (link == 0) return;
  if (!seen.insert(link).second) fail(link, "a data list comes back to this block (a cycle)");
  const Block b = block(link, "DTSDRDDZDLHL");
  if (b.id == "DT" || b.id == "SD" || b.id == "RD") {
    std::uint64_t end = b.offset + b.length;
    // An unfinalized file's last ##DT keeps the length it had when created: its data runs on.
    if (last_may_run_on && b.id == "DT" && unfinalized_ &&
        (unfinalized_flags_ & kUnfinLastDt) != 0) {
      end = std::max(end, next_block_after(b.offset));
      notes_.push_back("unfinalized file: the ##DT block at offset " + std::to_string(b.offset) +
                       " stores " + std::to_string(b.length) + " bytes; its data runs to byte " +
                       std::to_string(end) + " (the next block or the end of the file)");
    }
    const std::uint8_t* from = b.data;
    const std::uint8_t* to = bytes_.data() + end;
    spend_data(link, static_cast<std::uint64_t>(to - from));
    out.insert(out.end(), from, to);
    return;
  }
  if (b.id == "DZ") return append_zipped(b, out);
  if (b.id == "HL") return append_block_data(b.link(0), out, last_may_run_on, seen);
  // ##DL: a chain of lists, each linking to data blocks.
  bool first = true;
  for (std::uint64_t at = link; at != 0; first = false) {
    if (!first && !seen.insert(at).second)
      fail(at, "the data list chain comes back to this ##DL (a cycle)");
    const Block dl = first ? b : block(at, "DL");
    if (dl.data_size < 8 || dl.link_count < 1) fail(at, "##DL block too short");
    const std::uint32_t count = u32(dl.data + 4);
    if (count > dl.link_count - 1)
      fail(at, "##DL lists " + std::to_string(count) + " blocks but holds " +
                   std::to_string(dl.link_count - 1) + " links");
    for (std::uint32_t i = 0; i < count; ++i) append_block_data(dl.link(1 + i), out, false, seen);
    at = dl.link(0);
  }
}

// ##DZ: deflate (zip type 0), or deflate of the data transposed as a matrix of zip_parameter
// columns (zip type 1: bytes of a column together compress better).
void Mdf4File::append_zipped(const Block& b, std::vector<std::uint8_t>& out) const {
  if (b.data_size < 24) fail(b.offset, "##DZ block too short");
  const std::uint8_t zip_type = b.data[2];
  const std::uint32_t columns = u32(b.data + 4);
  const std::uint64_t inflated = u64(b.data + 8);
  const std::uint64_t deflated = u64(b.data + 16);
  if (deflated > b.data_size - 24)
    fail(b.offset, "##DZ stores " + std::to_string(deflated) + " bytes in a block of " +
                       std::to_string(b.length));
  if (zip_type > 1)
    fail(b.offset,
         "##DZ zip type " + std::to_string(zip_type) + " (0 deflate, 1 transposed deflate)");
  if (inflated > kMaxInflatedBytes || inflated > 1032 * deflated + 64)
    fail(b.offset, "##DZ claims " + std::to_string(inflated) + " bytes from " +
                       std::to_string(deflated) + " (more than deflate can give or than " +
                       std::to_string(kMaxInflatedBytes) + ")");
  spend_data(b.offset, inflated);
  const std::size_t old = out.size();
  out.resize(old + inflated);
  uLongf got = static_cast<uLongf>(inflated);
  const int rc = uncompress(out.data() + old, &got, b.data + 24, static_cast<uLong>(deflated));
  if (rc != Z_OK || got != inflated)
    fail(b.offset, "##DZ does not inflate to its " + std::to_string(inflated) + " bytes (zlib " +
                       std::to_string(rc) + ")");
  if (zip_type == 1) {
    if (columns == 0) fail(b.offset, "transposed ##DZ with 0 columns");
    const std::uint64_t rows = inflated / columns;
    std::vector<std::uint8_t> t(out.begin() + static_cast<std::ptrdiff_t>(old),
                                out.begin() + static_cast<std::ptrdiff_t>(old + rows * columns));
    for (std::uint64_t c = 0; c < columns; ++c)
      for (std::uint64_t r = 0; r < rows; ++r) out[old + r * columns + c] = t[c * rows + r];
  }
}

std::vector<Mdf4Records> Mdf4File::read_records(std::size_t dg) const {
  const Mdf4DataGroup& g = groups_.at(dg);
  const std::vector<std::uint8_t> data = data_of(g.data_link, true);
  std::vector<Mdf4Records> out(g.groups.size());
  if (g.groups.empty()) return out;
  if (g.record_id_size == 0) {
    read_sorted(g, data, out.front());
  } else {
    read_unsorted(g, data, out);
  }
  return out;
}

// A data group of one channel group: records one after the other.
void Mdf4File::read_sorted(const Mdf4DataGroup& g, const std::vector<std::uint8_t>& data,
                           Mdf4Records& out) const {
  const Mdf4ChannelGroup& cg = g.groups.front();
  if (cg.is_vlsd()) fail(cg.offset, "a VLSD channel group alone in its data group");
  const std::uint64_t size = cg.record_bytes();
  if (size == 0) return;
  const std::uint64_t available = data.size() / size;
  std::uint64_t count = cg.cycle_count;
  if (unfinalized_) {
    count = available;
    notes_.push_back("unfinalized file: channel group '" + cg.name + "' at offset " +
                     std::to_string(cg.offset) + ": " + std::to_string(count) +
                     " records recovered from the data (stored cycle count " +
                     std::to_string(cg.cycle_count) + ")");
  } else if (count > available) {
    fail(cg.offset, "cycle count " + std::to_string(count) + " of " + std::to_string(size) +
                        "-byte records needs more than the " + std::to_string(data.size()) +
                        " bytes of its data");
  }
  out.count = count;
  out.bytes.assign(data.begin(), data.begin() + static_cast<std::ptrdiff_t>(count * size));
}

// A data group of several channel groups: each record starts with its group's record id; a
// VLSD group's record is a 32-bit length and that many bytes.
void Mdf4File::read_unsorted(const Mdf4DataGroup& g, const std::vector<std::uint8_t>& data,
                             std::vector<Mdf4Records>& out) const {
  const std::size_t id_size = g.record_id_size;
  std::size_t pos = 0;
  std::string stop;
  while (pos < data.size()) {
    if (data.size() - pos < id_size) {
      stop = "a partial record id";
      break;
    }
    std::uint64_t id = 0;
    for (std::size_t i = 0; i < id_size; ++i)
      id |= static_cast<std::uint64_t>(data[pos + i]) << (8 * i);
    std::size_t k = 0;
    while (k < g.groups.size() && g.groups[k].record_id != id) ++k;
    if (k == g.groups.size()) {
      stop = "record id " + std::to_string(id) + " of no channel group";
      break;
    }
    const std::size_t body = pos + id_size;
    std::uint64_t size = g.groups[k].record_bytes();
    std::uint64_t take = size;
    if (g.groups[k].is_vlsd()) {
      if (data.size() - body < 4) {
        stop = "a partial record";
        break;
      }
      take = 4ULL + u32(data.data() + body);
    }
    if (data.size() - body < take) {
      stop = "a partial record";
      break;
    }
    out[k].bytes.insert(out[k].bytes.end(), data.begin() + static_cast<std::ptrdiff_t>(body),
                        data.begin() + static_cast<std::ptrdiff_t>(body + take));
    ++out[k].count;
    pos = body + static_cast<std::size_t>(take);
  }
  if (!stop.empty() && !unfinalized_)
    fail(g.data_link, "data of the data group at offset " + std::to_string(g.offset) + " ends in " +
                          stop + " at data byte " + std::to_string(pos));
  if (unfinalized_) {
    std::string counts;
    for (std::size_t k = 0; k < g.groups.size(); ++k)
      if (out[k].count != 0)
        counts += (counts.empty() ? "" : ", ") +
                  (g.groups[k].name.empty() ? "VLSD" : g.groups[k].name) + " " +
                  std::to_string(out[k].count);
    notes_.push_back(
        "unfinalized file (flags " + hex(unfinalized_flags_) +
        "): record counts recovered from the data: " + (counts.empty() ? "none" : counts) +
        (stop.empty() ? ""
                      : "; dropped " + std::to_string(data.size() - pos) + " bytes from " + stop));
  }
}

std::optional<std::pair<std::size_t, std::size_t>> Mdf4File::find_group(
    std::string_view name) const {
  for (std::size_t d = 0; d < groups_.size(); ++d)
    for (std::size_t c = 0; c < groups_[d].groups.size(); ++c)
      if (groups_[d].groups[c].name == name) return std::pair{d, c};
  return std::nullopt;
}

void Mdf4File::check_numeric(const Mdf4ChannelGroup& group, const Mdf4Channel& c) const {
  const std::string what = "channel '" + c.name + "' ";
  if (c.type == Mdf4Channel::VirtualMaster) return;  // its value is the record's index
  if (c.type == Mdf4Channel::Vlsd || c.data_type > Mdf4Channel::FloatBe)
    fail(c.offset, what + "of data type " + std::to_string(c.data_type) + " is not a number");
  const bool is_float = c.data_type == Mdf4Channel::FloatLe || c.data_type == Mdf4Channel::FloatBe;
  const bool big = c.data_type == Mdf4Channel::UintBe || c.data_type == Mdf4Channel::IntBe;
  if (c.bit_count == 0 || c.bit_count > 64 ||
      (is_float && ((c.bit_count != 32 && c.bit_count != 64) || c.bit_offset != 0)) ||
      (big && (c.bit_offset != 0 || c.bit_count % 8 != 0)))
    fail(c.offset, what + "of " + std::to_string(c.bit_count) + " bits at bit " +
                       std::to_string(c.bit_offset) +
                       " is not a layout read (integers of 1..64 bits, big-endian ones whole "
                       "bytes, floats of 32 or 64)");
  const std::uint64_t end =
      static_cast<std::uint64_t>(c.byte_offset) + (c.bit_offset + c.bit_count + 7) / 8;
  if (end > group.data_bytes)
    fail(c.offset, what + "ends at byte " + std::to_string(end) + " of records of " +
                       std::to_string(group.data_bytes));
  if (c.conversion && (c.conversion->kind == Mdf4Conversion::Algebraic ||
                       c.conversion->kind > Mdf4Conversion::RangeToText))
    fail(c.offset, what + "has a conversion of kind " + std::to_string(c.conversion->kind) +
                       ", which is not read");
}

std::uint64_t Mdf4File::raw_bits(const Mdf4Channel& c, const std::uint8_t* record) {
  const std::uint8_t* p = record + c.byte_offset;
  const unsigned n = (c.bit_offset + c.bit_count + 7) / 8;
  std::uint64_t v = 0;
  if (c.data_type == Mdf4Channel::UintBe || c.data_type == Mdf4Channel::IntBe) {
    for (unsigned i = 0; i < n; ++i) v = (v << 8) | p[i];
    return v;
  }
  for (unsigned i = 0; i < n && i < 8; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  v >>= c.bit_offset;
  if (n == 9) v |= static_cast<std::uint64_t>(p[8]) << (64 - c.bit_offset);
  return c.bit_count >= 64 ? v : v & ((std::uint64_t{1} << c.bit_count) - 1);
}

double Mdf4File::raw_value(const Mdf4Channel& c, const std::uint8_t* record) {
  const std::uint64_t bits = raw_bits(c, record);
  switch (c.data_type) {
    case Mdf4Channel::IntLe:
    case Mdf4Channel::IntBe: {
      if (c.bit_count >= 64) return static_cast<double>(static_cast<std::int64_t>(bits));
      const std::uint64_t sign = std::uint64_t{1} << (c.bit_count - 1);
      return static_cast<double>(static_cast<std::int64_t>((bits ^ sign) - sign));
    }
    case Mdf4Channel::FloatLe:
    case Mdf4Channel::FloatBe:
      if (c.bit_count == 32) return std::bit_cast<float>(static_cast<std::uint32_t>(bits));
      return std::bit_cast<double>(bits);
    default:
      return static_cast<double>(bits);
  }
}

std::vector<std::uint8_t> Mdf4File::vlsd_stream(std::size_t dg, const Mdf4Channel& c,
                                                const std::vector<Mdf4Records>& records) const {
  if (c.data_link == 0) fail(c.offset, "VLSD channel '" + c.name + "' links to no data");
  const auto& groups = groups_.at(dg).groups;
  for (std::size_t k = 0; k < groups.size() && k < records.size(); ++k)
    if (groups[k].offset == c.data_link) {
      if (!groups[k].is_vlsd())
        fail(c.offset, "VLSD channel '" + c.name + "' links to a channel group that is not VLSD");
      return records[k].bytes;
    }
  return data_of(c.data_link, false);
}

std::span<const std::uint8_t> Mdf4File::vlsd_value(const std::vector<std::uint8_t>& stream,
                                                   std::uint64_t offset,
                                                   const Mdf4Channel& c) const {
  if (offset > stream.size() || stream.size() - offset < 4)
    fail(c.offset, "VLSD channel '" + c.name + "': offset " + std::to_string(offset) +
                       " past its " + std::to_string(stream.size()) + " bytes of values");
  const std::uint32_t n = u32(stream.data() + offset);
  if (stream.size() - offset - 4 < n)
    fail(c.offset, "VLSD channel '" + c.name + "': a value of " + std::to_string(n) +
                       " bytes at offset " + std::to_string(offset) + " runs past its " +
                       std::to_string(stream.size()) + " bytes of values");
  return {stream.data() + offset + 4, n};
}

Mdf4Signals Mdf4File::read_signals(std::size_t dg, std::size_t cg,
                                   const std::vector<std::string>& names) const {
  reset_budget();  // each call is a reading of its own
  const Mdf4ChannelGroup& group = groups_.at(dg).groups.at(cg);
  const Mdf4Channel* master = group.master();
  if (master == nullptr)
    fail(group.offset, "channel group '" + group.name + "' has no master channel");
  check_numeric(group, *master);
  std::vector<const Mdf4Channel*> channels;
  for (const auto& name : names) {
    const Mdf4Channel* c = group.find(name);
    if (c == nullptr)
      fail(group.offset, "channel group '" + group.name + "' has no channel '" + name + "'");
    check_numeric(group, *c);
    channels.push_back(c);
  }
  const auto records = read_records(dg);
  const Mdf4Records& r = records.at(cg);
  const std::size_t size = group.record_bytes();
  auto physical = [&](const Mdf4Channel& c, std::size_t k) {
    const double raw = c.type == Mdf4Channel::VirtualMaster
                           ? static_cast<double>(k)
                           : raw_value(c, r.bytes.data() + k * size);
    return c.conversion ? c.conversion->apply(raw) : raw;
  };
  Mdf4Signals out;
  out.names = names;
  out.values.resize(names.size());
  for (std::size_t k = 0; k < r.count; ++k) {
    out.time.push_back(physical(*master, k));
    for (std::size_t i = 0; i < channels.size(); ++i)
      out.values[i].push_back(physical(*channels[i], k));
  }
  return out;
}

}  // namespace dynid::can
