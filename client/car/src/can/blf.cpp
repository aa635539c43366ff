#include <dynid/can/blf.hpp>

#include <algorithm>
#include <cstring>
#include <istream>
#include <limits>

#include <zlib.h>

#include <dynid/error.hpp>

#include "log_text.hpp"

namespace dynid::can {
namespace {

constexpr std::size_t kFileHeaderMin = 72;  // up to the stop SYSTEMTIME
constexpr std::size_t kBaseHeader = 16;
constexpr std::uint32_t kLogContainer = 10;
constexpr std::uint32_t kCanMessage = 1;
constexpr std::uint32_t kCanErrorExt = 73;
constexpr std::uint32_t kCanMessage2 = 86;
constexpr std::uint32_t kCanFdMessage = 100;
constexpr std::uint32_t kExtendedIdFlag = 0x80000000U;
constexpr std::uint8_t kRemoteFlag = 0x80;
constexpr std::uint8_t kFdEdl = 0x1, kFdBrs = 0x2, kFdEsi = 0x4;

std::uint16_t u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
std::uint32_t u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
std::uint64_t u64(const std::uint8_t* p) { return u32(p) | (static_cast<std::uint64_t>(u32(p + 4)) << 32); }

}  // namespace

BlfReader::BlfReader(std::istream& in, std::string source, OnError on_error)
    : LogReader(std::move(source), on_error), in_(&in) {}

BlfReader::BlfReader(const std::filesystem::path& path, OnError on_error)
    : LogReader(path.filename().string(), on_error), file_(open_file(path, "BLF log")), in_(file_.get()) {}

void BlfReader::add_error(std::uint64_t offset, std::string reason, bool fatal) {
  record_error(static_cast<std::size_t>(offset), std::move(reason));
  if (fatal) ended_ = true;
}

bool BlfReader::read_bytes(void* out, std::size_t n) {
  in_->read(static_cast<char*>(out), static_cast<std::streamsize>(n));
  const auto got = static_cast<std::size_t>(in_->gcount());
  offset_ += got;
  return got == n;
}

void BlfReader::read_header() {
  header_read_ = true;
  std::uint8_t h[kFileHeaderMin];
  if (!read_bytes(h, sizeof h) || std::memcmp(h, "LOGG", 4) != 0) {
    add_error(0, "not a BLF file (no 'LOGG' header)", true);
    return;
  }
  const std::uint32_t size = u32(h + 4);
  if (size < kFileHeaderMin || size > 1u << 20) {
    add_error(4, "file header size " + std::to_string(size) + " out of " + std::to_string(kFileHeaderMin) + "..1 MiB", true);
    return;
  }
  std::vector<std::uint8_t> rest(size - kFileHeaderMin);
  if (!read_bytes(rest.data(), rest.size())) {
    add_error(offset_, "file ends inside its header", true);
    return;
  }
  const std::uint8_t* st = h + 40;  // SYSTEMTIME of the measurement start
  const unsigned year = u16(st), month = u16(st + 2), day = u16(st + 6);
  const unsigned hour = u16(st + 8), minute = u16(st + 10), second = u16(st + 12), ms = u16(st + 14);
  start_ns_ = std::max<std::int64_t>(0, detail::utc_ns(year, month, day, hour, minute, second, ms));
}

bool BlfReader::next_container() {
  // Padding between objects: zero bytes (writers pad to 4 bytes, or by size % 4).
  for (int k = 0; k < 8; ++k) {
    const int c = in_->peek();
    if (c == std::char_traits<char>::eof()) {
      if (inner_pos_ < inner_.size()) {
        bool zeros = true;
        for (std::size_t i = inner_pos_; i < inner_.size(); ++i) zeros = zeros && inner_[i] == 0;
        if (!zeros) add_error(container_offset_, "file ends inside an object of this container", true);
      }
      ended_ = true;
      return false;
    }
    if (c != 0) break;
    in_->get();
    ++offset_;
  }
  const std::uint64_t at = offset_;
  std::uint8_t h[kBaseHeader];
  if (!read_bytes(h, sizeof h)) {
    add_error(at, "file ends inside an object header", true);
    return false;
  }
  if (std::memcmp(h, "LOBJ", 4) != 0) {
    add_error(at, "expected an object ('LOBJ'), found other bytes", true);
    return false;
  }
  const std::uint32_t size = u32(h + 8);
  const std::uint32_t type = u32(h + 12);
  if (size < kBaseHeader || size > kMaxObjectBytes) {
    add_error(at, "object size " + std::to_string(size) + " out of 16.." + std::to_string(kMaxObjectBytes), true);
    return false;
  }
  std::vector<std::uint8_t> body(size - kBaseHeader);
  if (!read_bytes(body.data(), body.size())) {
    add_error(at, "file ends inside an object of " + std::to_string(size) + " bytes", true);
    return false;
  }
  inner_.erase(inner_.begin(), inner_.begin() + static_cast<std::ptrdiff_t>(inner_pos_));
  inner_pos_ = 0;
  container_offset_ = at;
  if (type != kLogContainer) {  // an object outside a container: parse it as one
    inner_.insert(inner_.end(), h, h + kBaseHeader);
    inner_.insert(inner_.end(), body.begin(), body.end());
    return true;
  }
  if (body.size() < 16) {
    add_error(at, "log container shorter than its header", true);
    return false;
  }
  const std::uint16_t method = u16(body.data());
  const std::uint32_t inflated = u32(body.data() + 8);
  if (inflated > kMaxObjectBytes) {
    add_error(at, "log container of " + std::to_string(inflated) + " bytes inflated, at most " +
                      std::to_string(kMaxObjectBytes), true);
    return false;
  }
  const std::uint8_t* data = body.data() + 16;
  const std::size_t n = body.size() - 16;
  if (method == 0) {
    inner_.insert(inner_.end(), data, data + n);
  } else if (method == 2) {
    const std::size_t old = inner_.size();
    inner_.resize(old + inflated);
    uLongf out = inflated;
    const int rc = uncompress(inner_.data() + old, &out, data, static_cast<uLong>(n));
    if (rc != Z_OK || out != inflated) {
      inner_.resize(old);
      add_error(at, "log container does not inflate to its " + std::to_string(inflated) + " bytes (zlib " +
                        std::to_string(rc) + ")", true);
      return false;
    }
  } else {
    add_error(at, "log container compression method " + std::to_string(method) + " unknown (0 stored, 2 zlib)", true);
    return false;
  }
  return true;
}

int BlfReader::parse_inner(Frame& f) {
  std::size_t z = 0;  // padding before the next object (at most 7 bytes)
  while (inner_pos_ + z < inner_.size() && inner_[inner_pos_ + z] == 0 && z < 8) ++z;
  if (inner_pos_ + z == inner_.size()) return -1;
  if (z == 8) {
    add_error(container_offset_, "more than 7 zero bytes between objects", true);
    return 0;
  }
  inner_pos_ += z;
  if (inner_.size() - inner_pos_ < kBaseHeader) return -1;
  const std::uint8_t* p = inner_.data() + inner_pos_;
  const std::size_t left = inner_.size() - inner_pos_;
  if (std::memcmp(p, "LOBJ", 4) != 0) {
    add_error(container_offset_, "expected an object ('LOBJ') inside the container", true);
    return 0;
  }
  const std::uint16_t header_size = u16(p + 4);
  const std::uint16_t version = u16(p + 6);
  const std::uint32_t size = u32(p + 8);
  const std::uint32_t type = u32(p + 12);
  if (size < kBaseHeader || size > kMaxObjectBytes) {
    add_error(container_offset_, "object size " + std::to_string(size) + " out of range", true);
    return 0;
  }
  if (size > left) return -1;  // continues in the next container
  inner_pos_ += size;
  if (type == kLogContainer) {
    add_error(container_offset_, "a log container inside a log container");
    return 0;
  }
  if (type != kCanMessage && type != kCanMessage2 && type != kCanFdMessage && type != kCanErrorExt) {
    ++skipped_;
    return 0;
  }
  const std::size_t fixed = version == 1 ? 32 : version == 2 ? 40 : 0;
  if (fixed == 0 || header_size < fixed || header_size > size) {
    add_error(container_offset_, "object header version " + std::to_string(version) + " / size " +
                                     std::to_string(header_size) + " not readable");
    return 0;
  }
  const std::uint32_t flags = u32(p + 16);
  const std::uint64_t ts = u64(p + 24);
  std::int64_t ns = 0;
  if (flags == 1 && ts <= static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max() / 20000))
    ns = static_cast<std::int64_t>(ts) * 10000;
  else if (flags == 2 && ts <= static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max() / 2))
    ns = static_cast<std::int64_t>(ts);
  else {
    add_error(container_offset_, "object timestamp flags " + std::to_string(flags) + " (1 = 10 us, 2 = 1 ns) or value " +
                                     std::to_string(ts) + " not readable");
    return 0;
  }
  if (type == kCanErrorExt) {
    add_error(container_offset_, "error frame");
    return 0;
  }
  const std::uint8_t* m = p + header_size;
  const std::size_t body = size - header_size;
  const std::size_t need = type == kCanFdMessage ? 84 : 16;
  if (body < need) {
    add_error(container_offset_, "CAN object of " + std::to_string(body) + " bytes, expected " + std::to_string(need));
    return 0;
  }
  f = Frame{};
  const std::uint16_t channel = u16(m);
  if (channel < 1 || channel > 99) {
    add_error(container_offset_, "channel " + std::to_string(channel) + " out of 1..99");
    return 0;
  }
  f.set_interface_name("can" + std::to_string(channel - 1));
  const std::uint8_t msg_flags = m[2];
  const std::uint8_t dlc = m[3];
  const std::uint32_t raw_id = u32(m + 4);
  f.extended = (raw_id & kExtendedIdFlag) != 0;
  f.id = raw_id & ~kExtendedIdFlag;
  if (f.id > (f.extended ? Frame::kMaxExtendedId : Frame::kMaxStandardId)) {
    add_error(container_offset_, "id " + std::to_string(f.id) + " out of range");
    return 0;
  }
  f.rtr = (msg_flags & kRemoteFlag) != 0;
  const std::uint8_t* data = m + 8;
  std::size_t length = 0;
  if (type == kCanFdMessage) {
    const std::uint8_t fd_flags = m[13];
    const std::uint8_t valid = m[14];
    data = m + 20;
    f.fd = (fd_flags & kFdEdl) != 0;
    if (f.fd) {
      f.fd_flags = static_cast<std::uint8_t>(((fd_flags & kFdBrs) ? Frame::kFdBrs : 0) | ((fd_flags & kFdEsi) ? Frame::kFdEsi : 0));
      f.rtr = false;
      length = valid;
      if (!is_valid_fd_length(length)) {
        add_error(container_offset_, "CAN FD frame of " + std::to_string(length) + " bytes is not a valid FD length");
        return 0;
      }
    } else {
      length = valid > 8 ? 8 : valid;
    }
  } else {
    if (dlc > 15) {
      add_error(container_offset_, "dlc " + std::to_string(dlc) + " out of 0..15");
      return 0;
    }
    length = dlc > 8 ? 8 : dlc;
  }
  if (f.rtr) {
    f.length = static_cast<std::uint8_t>(length);
  } else {
    f.length = static_cast<std::uint8_t>(length);
    std::memcpy(f.data.data(), data, length);
  }
  f.timestamp = seconds_from_ns(start_ns_ + ns);
  return 1;
}

bool BlfReader::next(Frame& frame) {
  if (!header_read_) read_header();
  while (!stopped_ && !ended_ && byte_budget() > 0) {
    const int r = parse_inner(frame);
    if (r == 1) {
      ++frame_count_;
      return true;
    }
    if (r == -1 && !next_container()) return false;
  }
  return false;
}

std::string BlfReader::describe(const LogError& error) const {
  return source() + ": offset " + std::to_string(error.line) + ": " + error.reason;
}

}  // namespace dynid::can
