#include <dynid/can/mdf4_bus.hpp>

#include <cmath>
#include <cstring>

#include <dynid/input/input_file.hpp>

namespace dynid::can {
namespace {

constexpr std::string_view kDataFrame = "CAN_DataFrame";
constexpr std::uint32_t kMaxBusChannel = 99;

std::size_t dlc_length(std::uint64_t dlc, bool fd) {
  static constexpr std::size_t kFd[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
  if (dlc > 15) return 64;
  return fd ? kFd[dlc] : std::min<std::size_t>(dlc, 8);
}

// "can<n>" without allocating: the interface of every frame is set in the hot path.
void set_interface(Frame& frame, std::uint32_t index) {
  char name[8] = {'c', 'a', 'n'};
  std::size_t n = 3;
  if (index >= 10) name[n++] = static_cast<char>('0' + index / 10);
  name[n++] = static_cast<char>('0' + index % 10);
  frame.set_interface_name(std::string_view(name, n));
}

}  // namespace

// One CAN_DataFrame channel group: its records, its VLSD values, its channels and the frame
// it gives next (groups are merged by that frame's time).
struct Mdf4BusReader::Cursor {
  const Mdf4ChannelGroup* group = nullptr;
  Mdf4Records records;
  std::vector<std::uint8_t> vlsd;  // the DataBytes values when DataBytes is a VLSD channel
  const Mdf4Channel* time = nullptr;
  const Mdf4Channel* id = nullptr;
  const Mdf4Channel* ide = nullptr;
  const Mdf4Channel* dlc = nullptr;
  const Mdf4Channel* length = nullptr;
  const Mdf4Channel* bytes = nullptr;
  const Mdf4Channel* bus = nullptr;
  const Mdf4Channel* edl = nullptr;
  const Mdf4Channel* brs = nullptr;
  const Mdf4Channel* esi = nullptr;
  std::uint64_t next = 0;
  Frame pending;
  bool has = false;
};

Mdf4BusReader::Mdf4BusReader(const std::filesystem::path& path, OnError on_error)
    : LogReader(path.filename().string(), on_error), path_(path) {
  input::check_input_file(path, "MDF4 log",
                          Mdf4File::kMaxFileBytes);  // throws InputError naming it
}

Mdf4BusReader::Mdf4BusReader(std::vector<std::uint8_t> bytes, std::string source, OnError on_error)
    : LogReader(std::move(source), on_error), bytes_(std::move(bytes)) {}

Mdf4BusReader::~Mdf4BusReader() = default;

std::vector<std::string> Mdf4BusReader::notes() const {
  std::vector<std::string> out = file_ ? file_->notes() : std::vector<std::string>{};
  if (unwritten_ != 0)
    out.push_back("unfinalized file: " + std::to_string(unwritten_) +
                  " CAN_DataFrame records whose data bytes were never written dropped");
  return out;
}

std::uint64_t Mdf4BusReader::bytes_consumed() const {
  if (!file_) return 0;
  if (ended_ || total_records_ == 0) return file_->file_size();
  std::uint64_t read = 0;
  for (const auto& c : cursors_) read += c->next;
  return static_cast<std::uint64_t>(static_cast<double>(file_->file_size()) *
                                    static_cast<double>(read) /
                                    static_cast<double>(total_records_));
}

void Mdf4BusReader::load() {
  loaded_ = true;
  try {
    file_ = path_.empty() ? std::make_unique<Mdf4File>(std::move(bytes_), source())
                          : std::make_unique<Mdf4File>(path_);
    open_groups();
  } catch (const Mdf4Error& e) {
    record_error(static_cast<std::size_t>(e.offset()), e.reason());
    cursors_.clear();
    ended_ = true;
  } catch (const InputError& e) {
    record_error(0, e.what());
    cursors_.clear();
    ended_ = true;
  }
}

// Reads every data group's records: CAN_DataFrame groups become cursors, others are counted.
void Mdf4BusReader::open_groups() {
  const auto& groups = file_->data_groups();
  for (std::size_t d = 0; d < groups.size(); ++d) {
    auto records = file_->read_records(d);
    for (std::size_t k = 0; k < groups[d].groups.size(); ++k) {
      const Mdf4ChannelGroup& g = groups[d].groups[k];
      if (g.is_vlsd()) continue;  // values of another group's channel
      if (g.name == "CAN_ErrorFrame") error_frames_ += records[k].count;
      if (g.name == "CAN_RemoteFrame") remote_frames_ += records[k].count;
      if (g.name != kDataFrame) {
        if (g.name != "CAN_ErrorFrame" && g.name != "CAN_RemoteFrame")
          other_records_ += records[k].count;
        continue;
      }
      auto c = std::make_unique<Cursor>();
      c->group = &g;
      auto field = [&](std::string_view name) {
        const Mdf4Channel* ch = g.find(std::string(kDataFrame) + "." + std::string(name));
        if (ch != nullptr && ch != g.find(std::string(kDataFrame) + ".DataBytes"))
          file_->check_numeric(g, *ch);
        return ch;
      };
      c->time = g.master();
      c->id = field("ID");
      if (c->time == nullptr || c->id == nullptr)
        throw Mdf4Error(source(), g.offset,
                        "CAN_DataFrame group without a master channel or an ID channel");
      file_->check_numeric(g, *c->time);
      c->ide = field("IDE");
      c->dlc = field("DLC");
      c->length = field("DataLength");
      c->bus = field("BusChannel");
      c->edl = field("EDL");
      c->brs = field("BRS");
      c->esi = field("ESI");
      c->bytes = field("DataBytes");
      if (c->bytes != nullptr && c->bytes->type == Mdf4Channel::Vlsd) {
        // the record holds a 64-bit offset into the values
        if (c->bytes->bit_offset != 0 || c->bytes->bit_count != 64 ||
            c->bytes->byte_offset + 8ULL > g.data_bytes)
          throw Mdf4Error(source(), c->bytes->offset,
                          "CAN_DataFrame.DataBytes: a VLSD offset is 64 bits in its records");
        c->vlsd = file_->vlsd_stream(d, *c->bytes, records);
      } else if (c->bytes != nullptr &&
                 (c->bytes->bit_offset != 0 || c->bytes->bit_count % 8 != 0 ||
                  c->bytes->byte_offset + c->bytes->bit_count / 8ULL > g.data_bytes)) {
        throw Mdf4Error(source(), c->bytes->offset,
                        "CAN_DataFrame.DataBytes does not lie in whole bytes of its records");
      }
      c->records = std::move(records[k]);
      total_records_ += c->records.count;
      cursors_.push_back(std::move(c));
    }
  }
  for (auto& c : cursors_) advance(*c);
}

bool Mdf4BusReader::advance(Cursor& c) {
  c.has = false;
  while (!stopped_ && c.next < c.records.count) {
    const std::uint64_t k = c.next++;
    if (decode(c, static_cast<std::size_t>(k), c.pending)) return c.has = true;
  }
  return false;
}

// Record k of a CAN_DataFrame group as a frame; false (an error recorded) when it is no frame.
bool Mdf4BusReader::decode(Cursor& c, std::size_t k, Frame& f) {
  const std::uint8_t* rec = c.records.bytes.data() + k * c.group->record_bytes();
  auto bad = [&](const std::string& reason) {
    record_error(static_cast<std::size_t>(c.group->offset),
                 "record " + std::to_string(k) + " of channel group CAN_DataFrame: " + reason);
    return false;
  };
  auto bits = [&](const Mdf4Channel* ch, std::uint64_t absent) {
    return ch ? Mdf4File::raw_bits(*ch, rec) : absent;
  };
  f = Frame{};
  double t = c.time->type == Mdf4Channel::VirtualMaster ? static_cast<double>(k)
                                                        : Mdf4File::raw_value(*c.time, rec);
  if (c.time->conversion) t = c.time->conversion->apply(t);
  if (!std::isfinite(t) || std::fabs(t) > 1e9)
    return bad("time " + std::to_string(t) + " s is not readable");
  f.timestamp = seconds_from_ns(file_->start_ns() + std::llround(t * 1e9));
  std::uint64_t id = bits(c.id, 0);
  f.extended =
      c.ide ? bits(c.ide, 0) != 0 : (id & 0x80000000ULL) != 0 || id > Frame::kMaxStandardId;
  if (c.ide == nullptr) id &= 0x7FFFFFFFULL;
  if (id > (f.extended ? Frame::kMaxExtendedId : Frame::kMaxStandardId))
    return bad("id " + std::to_string(id) + " out of range");
  f.id = static_cast<std::uint32_t>(id);
  f.fd = bits(c.edl, 0) != 0;
  if (f.fd)
    f.fd_flags = static_cast<std::uint8_t>((bits(c.brs, 0) ? Frame::kFdBrs : 0) |
                                           (bits(c.esi, 0) ? Frame::kFdEsi : 0));
  std::span<const std::uint8_t> payload;
  if (c.bytes != nullptr && c.bytes->type == Mdf4Channel::Vlsd) {
    // A logger that lost power may have written a frame's record but not yet its data bytes.
    if (file_->unfinalized() && bits(c.bytes, 0) >= c.vlsd.size()) {
      ++unwritten_;
      return false;
    }
    try {
      payload = file_->vlsd_value(c.vlsd, bits(c.bytes, 0), *c.bytes);
    } catch (const Mdf4Error& e) {
      return bad(e.reason());
    }
  } else if (c.bytes != nullptr) {
    payload = {rec + c.bytes->byte_offset, c.bytes->bit_count / 8};
  }
  const std::uint64_t length = c.length ? bits(c.length, 0)
                               : c.dlc  ? dlc_length(bits(c.dlc, 0), f.fd)
                                        : payload.size();
  if (length > payload.size())
    return bad("DataLength " + std::to_string(length) + " but " + std::to_string(payload.size()) +
               " data bytes");
  if (f.fd ? !is_valid_fd_length(length) : length > Frame::kMaxClassicData)
    return bad(std::string(f.fd ? "CAN FD" : "classic CAN") + " frame of " +
               std::to_string(length) + " bytes");
  f.length = static_cast<std::uint8_t>(length);
  if (length != 0)
    std::memcpy(f.data.data(), payload.data(), length);  // no DataBytes channel: none
  const std::uint64_t bus = bits(c.bus, 1);
  if (bus < 1 || bus > kMaxBusChannel)
    return bad("bus channel " + std::to_string(bus) + " out of 1..99");
  set_interface(f, static_cast<std::uint32_t>(bus - 1));
  return true;
}

bool Mdf4BusReader::next(Frame& frame) {
  if (!loaded_) load();
  while (!stopped_ && !ended_ && byte_budget() > 0) {
    Cursor* first = nullptr;
    for (auto& c : cursors_)
      if (c->has && (first == nullptr || c->pending.timestamp < first->pending.timestamp))
        first = c.get();
    if (first == nullptr) break;
    frame = first->pending;
    advance(*first);
    ++frame_count_;
    return true;
  }
  ended_ = ended_ || !stopped_;
  return false;
}

std::string Mdf4BusReader::describe(const LogError& error) const {
  return source() + ": offset " + std::to_string(error.line) + ": " + error.reason;
}

}  // namespace dynid::can
