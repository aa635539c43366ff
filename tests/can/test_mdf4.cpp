// ASAM MDF4 (can/mdf4.hpp, can/mdf4_bus.hpp) on the real CANedge logs of
// ../shared/data/mdf4-canedge: every raw file replays, the decoded file asammdf wrote from one of
// them holds the values the product's decoder gives, the frames equal the same frames as
// candump, and hostile variants of the files (cut, bad links, cycles, huge counts, bad deflate)
// are clear errors in bounded time. Skips without the shared data.
#include <gtest/gtest.h>

#include <zlib.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "can_test_support.hpp"
#include "dynid/can/candump.hpp"
#include "dynid/can/dbc.hpp"
#include "dynid/can/decoder.hpp"
#include "dynid/can/log_reader.hpp"
#include "dynid/can/mdf4.hpp"
#include "dynid/can/mdf4_bus.hpp"

namespace dynid::can {
namespace {

using Bytes = std::vector<std::uint8_t>;

std::filesystem::path mdf4_dir() {
  return test::shared_data() / "mdf4-canedge";
}
std::filesystem::path raw_file(const std::string& name) {
  return mdf4_dir() / "raw" / name;
}
const std::string kSplit1 = "3BA199E2_00000164_00000001-60FE3F04.MF4";
const std::string kSplit2 = "3BA199E2_00000164_00000002-60FE415D.MF4";
const std::string kUnfinalized = "17BD1DB7_00000006_00000170.MF4";  // 80 KB, "UnFinMF "

Bytes read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::vector<Frame> frames_of(LogReader& reader) {
  std::vector<Frame> out;
  Frame f;
  while (reader.next(f)) out.push_back(f);
  return out;
}

std::uint64_t get64(const Bytes& b, std::uint64_t at) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | b[at + static_cast<std::uint64_t>(i)];
  return v;
}
void put64(Bytes& b, std::uint64_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i)
    b[at + static_cast<std::uint64_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
}

// Appends a block ("##<id>", its links, its data) at the next 8-byte boundary; returns its offset.
std::uint64_t append_block(Bytes& b, const std::string& id, const std::vector<std::uint64_t>& links,
                           const Bytes& data) {
  while (b.size() % 8 != 0) b.push_back(0);
  const std::uint64_t at = b.size();
  b.resize(at + 24 + 8 * links.size());
  b[at] = '#';
  b[at + 1] = '#';
  b[at + 2] = static_cast<std::uint8_t>(id[0]);
  b[at + 3] = static_cast<std::uint8_t>(id[1]);
  put64(b, at + 8, 24 + 8 * links.size() + data.size());
  put64(b, at + 16, links.size());
  for (std::size_t i = 0; i < links.size(); ++i) put64(b, at + 24 + 8 * i, links[i]);
  b.insert(b.end(), data.begin(), data.end());
  return at;
}

// The data section of the block at `at` (after its links).
Bytes block_data(const Bytes& b, std::uint64_t at) {
  const std::uint64_t length = get64(b, at + 8), links = get64(b, at + 16);
  return Bytes(b.begin() + static_cast<std::ptrdiff_t>(at + 24 + 8 * links),
               b.begin() + static_cast<std::ptrdiff_t>(at + length));
}

// A ##DZ of `data` (zip type 0, or 1 transposed into `columns` columns).
Bytes dz_data(const Bytes& data, std::uint8_t zip_type, std::uint32_t columns) {
  Bytes source = data;
  if (zip_type == 1) {
    const std::size_t rows = data.size() / columns;
    for (std::size_t r = 0; r < rows; ++r)
      for (std::size_t c = 0; c < columns; ++c) source[c * rows + r] = data[r * columns + c];
  }
  uLongf size = compressBound(static_cast<uLong>(source.size()));
  Bytes zipped(size);
  EXPECT_EQ(compress(zipped.data(), &size, source.data(), static_cast<uLong>(source.size())), Z_OK);
  zipped.resize(size);
  Bytes out(24, 0);
  out[0] = 'D';
  out[1] = 'T';
  out[2] = zip_type;
  out[4] = static_cast<std::uint8_t>(columns);
  put64(out, 8, data.size());
  put64(out, 16, zipped.size());
  out.insert(out.end(), zipped.begin(), zipped.end());
  return out;
}

struct Outcome {
  std::vector<Frame> frames;
  std::vector<std::string> errors;
  double seconds = 0;
};

Outcome read_memory(Bytes bytes, const std::string& name) {
  const auto start = std::chrono::steady_clock::now();
  Mdf4BusReader reader(std::move(bytes), name);
  Outcome out;
  out.frames = frames_of(reader);
  for (const auto& e : reader.errors()) out.errors.push_back(reader.describe(e));
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

bool same_frames(const std::vector<Frame>& a, const std::vector<Frame>& b, std::string& why) {
  if (a.size() != b.size()) {
    why = std::to_string(a.size()) + " vs " + std::to_string(b.size()) + " frames";
    return false;
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Frame &x = a[i], &y = b[i];
    if (x.timestamp != y.timestamp || x.id != y.id || x.extended != y.extended || x.fd != y.fd ||
        x.rtr != y.rtr || x.fd_flags != y.fd_flags || x.length != y.length || x.data != y.data ||
        x.interface_name() != y.interface_name()) {
      why = "frame " + std::to_string(i) + " differs";
      return false;
    }
  }
  return true;
}

// Every raw file is an MDF4 log by its content and replays to frames without an error; the
// unfinalized ones say what was recovered.
TEST(Mdf4, EveryRawCanedgeFileReplaysWithoutErrors) {
  DYNID_REQUIRE_DIR(mdf4_dir());
  std::size_t files = 0, unfinalized = 0;
  for (const auto& entry : std::filesystem::directory_iterator(mdf4_dir() / "raw")) {
    ++files;
    ASSERT_EQ(detect_log_format(entry.path()), LogFormat::Mdf4) << entry.path();
    auto reader = open_log(entry.path());
    const auto frames = frames_of(*reader);
    EXPECT_EQ(reader->error_count(), 0U)
        << entry.path() << ": "
        << (reader->errors().empty() ? "" : reader->describe(reader->errors().front()));
    EXPECT_GT(frames.size(), 1000U) << entry.path();
    EXPECT_EQ(reader->bytes_consumed(), std::filesystem::file_size(entry.path()));
    const Mdf4File file(entry.path());
    const auto notes = dynamic_cast<Mdf4BusReader&>(*reader).notes();
    if (file.unfinalized()) {
      ++unfinalized;
      ASSERT_FALSE(notes.empty()) << entry.path() << ": unfinalized, but no recovery note";
      EXPECT_NE(notes.back().find("recovered from the data: CAN_DataFrame " +
                                  std::to_string(frames.size())),
                std::string::npos)
          << notes.back();
    } else {
      EXPECT_TRUE(notes.empty()) << entry.path();
    }
    for (std::size_t i = 1; i < frames.size(); ++i)
      ASSERT_LE(frames[i - 1].timestamp, frames[i].timestamp) << entry.path() << " frame " << i;
    std::cout << entry.path().filename().string() << ": " << frames.size() << " frames"
              << (file.unfinalized() ? ", unfinalized: " + notes.back() : std::string()) << "\n";
  }
  EXPECT_EQ(files, 5U);
  EXPECT_GE(unfinalized, 1U);
}

// The raw split decoded with the GNSS module's DBC by the product's decoder: per message id, the
// frames' times (seconds from `start_s`) and per signal name its decoded values.
struct DecodedMessages {
  std::vector<double> time;
  std::map<std::string, std::vector<double>> values;
};

std::map<std::uint32_t, DecodedMessages> decode_split1(double start_s) {
  const Database db = parse_dbc_file(mdf4_dir() / "dbc" / "canmod-gps.dbc");
  Decoder decoder(db);
  Mdf4BusReader raw(raw_file(kSplit1));
  std::map<std::uint32_t, DecodedMessages> by_id;
  std::vector<DecodedSignal> out;
  Frame f;
  while (raw.next(f)) {
    if (f.interface_name() != "can1" || f.extended) continue;  // the module is on bus channel 2
    if (decoder.decode(f, out).status != DecodeStatus::Ok) continue;
    DecodedMessages& d = by_id[f.id];
    d.time.push_back(f.timestamp - start_s);
    for (const auto& signal : out) d.values[signal.signal->name].push_back(signal.value);
  }
  return by_id;
}

const char* const kDecodedSplit1 = "3BA199E2_00000164_00000001-60FE3F04";

// Must-show 1: the raw split decoded with the GNSS module's DBC by the product's decoder gives
// every value asammdf 7.0 wrote to decoded/ (one channel group per message, one channel per
// signal), read back through Mdf4File::read_signals, at the same times.
TEST(Mdf4, DecodingTheRawSplitReproducesAsammdfsDecodedFile) {
  DYNID_REQUIRE_DIR(mdf4_dir());
  const Mdf4File decoded(mdf4_dir() / "decoded" / (std::string(kDecodedSplit1) + ".mf4"));
  auto by_id = decode_split1(static_cast<double>(decoded.start_ns()) / 1e9);
  std::size_t compared = 0, groups = 0;
  double largest = 0, largest_time = 0;
  std::string where;
  for (std::size_t dg = 0; dg < decoded.data_groups().size(); ++dg) {
    const Mdf4ChannelGroup& g = decoded.data_groups()[dg].groups.at(0);
    unsigned id = 0;
    ASSERT_EQ(std::sscanf(g.name.c_str(), "CAN2 message ID=0x%x", &id), 1) << g.name;
    ASSERT_TRUE(by_id.count(id)) << "no decoded frames of id " << id;
    const DecodedMessages& mine = by_id[id];
    std::vector<std::string> names;
    for (const auto& c : g.channels)
      if (!c.is_master()) names.push_back(c.name);
    const Mdf4Signals theirs = decoded.read_signals(dg, 0, names);
    ASSERT_EQ(theirs.time.size(), mine.time.size()) << g.name;
    for (std::size_t k = 0; k < theirs.time.size(); ++k)
      largest_time = std::max(largest_time, std::fabs(theirs.time[k] - mine.time[k]));
    for (std::size_t i = 0; i < names.size(); ++i) {
      ASSERT_TRUE(mine.values.count(names[i]))
          << g.name << ": signal " << names[i] << " not decoded";
      const auto& a = mine.values.at(names[i]);
      const auto& b = theirs.values[i];
      ASSERT_EQ(a.size(), b.size()) << names[i];
      const Mdf4Channel& channel = *g.find(names[i]);
      const bool is_float = channel.data_type == Mdf4Channel::FloatLe;
      for (std::size_t k = 0; k < a.size(); ++k) {
        // an integer channel holds the value exactly; a float64 one to its rounding (a few ulp)
        const double diff = std::fabs(a[k] - b[k]);
        const double allowed =
            is_float ? 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::fabs(b[k]))
                     : 0.0;
        ASSERT_LE(diff, allowed) << g.name << " " << names[i] << " value " << k << ": " << a[k]
                                 << " vs " << b[k];
        if (diff > largest) {
          largest = diff;
          where = names[i];
        }
        ++compared;
      }
    }
    ++groups;
  }
  EXPECT_EQ(groups, 9U);
  EXPECT_GT(compared, 100000U);
  // asammdf's time is the raw one (float64 ns times 1e-9); ours is start + whole ns
  EXPECT_LT(largest_time, 1e-6);
  std::cout << "compared " << compared << " values of " << groups
            << " messages with asammdf's decoded file: largest "
            << "difference " << largest << (where.empty() ? "" : " (" + where + ")")
            << ", largest time difference " << largest_time << " s\n";
}

// Must-show 1, the .mat: the vendor's script exported asammdf's decoded values to MATLAB on a
// 1 s raster (its "timestamps"): integer signals as the previous sample, floats interpolated
// linearly (numpy's interp: the end values held outside the data). The product's decoded values,
// at asammdf's times, resampled by the same rules, give every value of the .mat: integers exactly,
// floats to their rounding. The .mat is read by scipy (mat_dump.py): the product has no .mat
// reader.
TEST(Mdf4, DecodingTheRawSplitReproducesTheVendorsMatFile) {
  DYNID_REQUIRE_DIR(mdf4_dir());
  const Mdf4File decoded(mdf4_dir() / "decoded" / (std::string(kDecodedSplit1) + ".mf4"));
  const auto by_id = decode_split1(static_cast<double>(decoded.start_ns()) / 1e9);
  // Per signal name: asammdf's times of its message and the product's values.
  std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> series;
  for (std::size_t dg = 0; dg < decoded.data_groups().size(); ++dg) {
    const Mdf4ChannelGroup& g = decoded.data_groups()[dg].groups.at(0);
    unsigned id = 0;
    ASSERT_EQ(std::sscanf(g.name.c_str(), "CAN2 message ID=0x%x", &id), 1) << g.name;
    const Mdf4Signals times = decoded.read_signals(dg, 0, {});
    for (const auto& [name, values] : by_id.at(id).values) {
      ASSERT_EQ(values.size(), times.time.size()) << name;
      ASSERT_TRUE(series.emplace(name, std::make_pair(times.time, values)).second)
          << name << " twice";
    }
  }
  int status = -1;
  const std::string dump = test::run_command(
      std::string(DYNID_SYSTEM_PYTHON) + " " + DYNID_CAN_TEST_DIR + "/mat_dump.py " +
          (mdf4_dir() / "decoded" / (std::string(kDecodedSplit1) + ".mat")).string(),
      status);
  ASSERT_EQ(status, 0) << dump;
  std::map<std::string, std::pair<std::string, std::vector<double>>> mat;
  std::istringstream lines(dump);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream fields(line);
    std::string name, kind;
    std::size_t count = 0;
    fields >> name >> kind >> count;
    std::vector<double> values(count);
    for (double& v : values) fields >> v;
    ASSERT_TRUE(fields) << "mat_dump: " << line.substr(0, 80);
    mat[name] = {kind, values};
  }
  ASSERT_TRUE(mat.count("timestamps"));
  const std::vector<double>& raster = mat["timestamps"].second;
  std::size_t compared = 0;
  double largest = 0;
  for (const auto& [name, entry] : mat) {
    if (name == "timestamps") continue;
    ASSERT_TRUE(series.count(name)) << "the .mat's " << name << " is no decoded signal";
    const auto& [t, v] = series.at(name);
    for (std::size_t k = 0; k < raster.size(); ++k) {
      const double x = raster[k];
      const auto after =
          static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin());
      double expected = 0;
      if (entry.first == "int") {
        expected = v[after == 0 ? 0 : after - 1];
      } else if (after == 0 || after == t.size()) {
        expected = after == 0 ? v.front() : v.back();
      } else {
        const std::size_t j = after - 1;
        expected = (v[j + 1] - v[j]) / (t[j + 1] - t[j]) * (x - t[j]) + v[j];
      }
      const double diff = std::fabs(expected - entry.second[k]);
      const double allowed =
          entry.first == "int" ? 0.0 : 1e-12 * std::max(1.0, std::fabs(entry.second[k]));
      ASSERT_LE(diff, allowed) << name << " at " << x << " s: " << expected << " vs the .mat's "
                               << entry.second[k];
      largest = std::max(largest, diff);
      ++compared;
    }
  }
  EXPECT_EQ(mat.size(), 40U);  // 39 signals and the raster
  std::cout << "compared " << compared << " values of " << mat.size() - 1
            << " signals with the vendor's .mat: largest difference " << largest << "\n";
}

// The frames of an MDF4 bus log written as candump text read back as the same frames.
TEST(Mdf4, FramesEqualTheSameFramesAsCandump) {
  DYNID_REQUIRE_DIR(mdf4_dir());
  for (const std::string& name : {kSplit1, kUnfinalized}) {
    Mdf4BusReader mdf(raw_file(name));
    const auto frames = frames_of(mdf);
    std::ostringstream text;
    for (const auto& f : frames) text << format_candump_line(f) << "\n";
    std::istringstream in(text.str());
    CandumpReader candump(in, name + ".log");
    const auto back = frames_of(candump);
    EXPECT_EQ(candump.error_count(), 0U);
    std::string why;
    EXPECT_TRUE(same_frames(frames, back, why)) << name << ": " << why;
  }
}

// Data lists and zipped data (plain and transposed deflate) give the frames of the plain ##DT.
TEST(Mdf4, DataListsAndZippedDataGiveTheFramesOfThePlainData) {
  DYNID_REQUIRE_DIR(mdf4_dir());
  const Bytes original = read_bytes(raw_file(kSplit1));
  const Mdf4File file(original, kSplit1);
  const auto& dg = file.data_groups().front();
  ASSERT_EQ(dg.groups.front().name, "CAN_DataFrame");
  const std::uint64_t data_link_at = dg.offset + 24 + 16;  // dg_data, the third link
  const Bytes data = block_data(original, dg.data_link);
  const auto plain = read_memory(original, "plain.mf4");
  ASSERT_TRUE(plain.errors.empty());
  const std::uint32_t record = dg.groups.front().record_bytes();
  auto variant = [&](const std::string& what, auto&& make) {
    Bytes b = original;
    put64(b, data_link_at, make(b));
    const auto got = read_memory(b, what);
    EXPECT_TRUE(got.errors.empty())
        << what << ": " << (got.errors.empty() ? "" : got.errors.front());
    std::string why;
    EXPECT_TRUE(same_frames(plain.frames, got.frames, why)) << what << ": " << why;
  };
  variant("deflate", [&](Bytes& b) { return append_block(b, "DZ", {}, dz_data(data, 0, 0)); });
  variant("transposed deflate",
          [&](Bytes& b) { return append_block(b, "DZ", {}, dz_data(data, 1, record)); });
  variant("a list of two blocks", [&](Bytes& b) {
    const std::size_t half = data.size() / 2 + 5;  // a record cut between the blocks
    const auto first = append_block(
        b, "DT", {}, Bytes(data.begin(), data.begin() + static_cast<std::ptrdiff_t>(half)));
    const auto second = append_block(
        b, "DZ", {},
        dz_data(Bytes(data.begin() + static_cast<std::ptrdiff_t>(half), data.end()), 0, 0));
    Bytes dl(16, 0);
    dl[4] = 2;  // count; then the two offsets
    put64(dl, 8, 0);
    dl.resize(24);
    put64(dl, 16, half);
    return append_block(b, "DL", {0, first, second}, dl);
  });
}

// The record's fields give the frame's: EDL makes it a CAN FD frame with its BRS flag, the bus
// channel its interface (channel n is can<n-1>). The CANedge logs hold classic frames on channels
// 1 and 2 only, so the first record of the split is patched.
TEST(Mdf4, RecordFieldsGiveFdFlagsAndTheInterface) {
  DYNID_REQUIRE_DIR(mdf4_dir());
  Bytes bytes = read_bytes(raw_file(kSplit1));
  const Mdf4File file(bytes, kSplit1);
  const std::uint64_t record = file.data_groups().front().data_link + 24;
  const auto plain = read_memory(bytes, "plain.mf4");
  bytes[record + 13] |= 0x3;  // EDL, BRS
  bytes[record + 8] =
      static_cast<std::uint8_t>((bytes[record + 8] & ~0x6) | (3 << 1));  // BusChannel 3
  const auto patched = read_memory(bytes, "patched.mf4");
  ASSERT_TRUE(patched.errors.empty());
  ASSERT_FALSE(plain.frames.front().fd);
  const Frame& f = patched.frames.front();
  EXPECT_TRUE(f.fd);
  EXPECT_EQ(f.fd_flags, Frame::kFdBrs);
  EXPECT_EQ(f.interface_name(), "can2");
  EXPECT_EQ(f.id, plain.frames.front().id);
  EXPECT_EQ(f.extended, plain.frames.front().extended);
  EXPECT_EQ(f.length, 8);
  EXPECT_EQ(f.data, plain.frames.front().data);
}

// Hostile files: each is one clear error naming the file and an offset, in bounded time.
TEST(Mdf4, HostileFilesAreClearErrorsInBoundedTime) {
  DYNID_REQUIRE_DIR(mdf4_dir());
  const Bytes original = read_bytes(raw_file(kSplit1));
  const Mdf4File file(original, kSplit1);
  const auto& dg = file.data_groups().front();
  const std::uint64_t data_link_at = dg.offset + 24 + 16;
  const auto& cg = dg.groups.front();
  const std::uint64_t cg_links = get64(original, cg.offset + 16);
  const std::uint64_t cycle_count_at = cg.offset + 24 + 8 * cg_links + 8;
  struct Case {
    std::string name;
    Bytes bytes;
    std::string expect;
  };
  std::vector<Case> cases;
  cases.push_back(
      {"truncated", Bytes(original.begin(), original.begin() + 10000), "outside the file"});
  cases.push_back({"cut inside the identification", Bytes(original.begin(), original.begin() + 40),
                   "shorter than"});
  {
    Bytes b = original;
    put64(b, 64 + 24, b.size() + 4096);  // ##HD's first data group
    cases.push_back({"a link past the end", b, "outside the file"});
  }
  {
    Bytes b = original;
    put64(b, dg.data_link + 8, b.size());  // the ##DT's length
    cases.push_back({"a length past the end", b, "runs past the end of the file"});
  }
  {
    Bytes b = original;
    Bytes dl(16, 0);
    dl[4] = 1;
    const std::uint64_t at = b.size() + (8 - b.size() % 8) % 8;
    append_block(b, "DL", {at, dg.data_link}, dl);  // next: itself
    put64(b, data_link_at, at);
    cases.push_back({"a cyclic ##DL chain", b, "comes back"});
  }
  {
    Bytes b = original;
    put64(b, cycle_count_at, std::uint64_t{1} << 62);
    cases.push_back({"a huge cycle count", b, "cycle count 4611686018427387904"});
  }
  {
    Bytes b = original;
    Bytes dz = dz_data(block_data(original, dg.data_link), 0, 0);
    for (std::size_t i = 40; i < dz.size(); i += 7) dz[i] ^= 0x5A;
    put64(b, data_link_at, append_block(b, "DZ", {}, dz));
    cases.push_back({"a ##DZ with bad deflate", b, "does not inflate"});
  }
  {
    Bytes b = original;
    Bytes dz = dz_data(Bytes(1000, 0), 0, 0);
    put64(dz, 8, std::uint64_t{1} << 40);  // claims a terabyte
    put64(b, data_link_at, append_block(b, "DZ", {}, dz));
    cases.push_back({"a ##DZ that claims a terabyte", b, "claims"});
  }
  {
    Bytes b = original;
    put64(b, cg.offset + 24, cg.offset);  // the channel group's next: itself
    cases.push_back({"a cyclic ##CG chain", b, "comes back"});
  }
  for (auto& c : cases) {
    const auto got = read_memory(std::move(c.bytes), "hostile.mf4");
    EXPECT_TRUE(got.frames.empty()) << c.name;
    ASSERT_EQ(got.errors.size(), 1U) << c.name;
    EXPECT_NE(got.errors.front().find("hostile.mf4: offset "), std::string::npos)
        << got.errors.front();
    EXPECT_NE(got.errors.front().find(c.expect), std::string::npos)
        << c.name << ": " << got.errors.front();
    EXPECT_LT(got.seconds, 2.0) << c.name;
    std::cout << c.name << ": " << got.errors.front() << " (" << got.seconds * 1e3 << " ms)\n";
  }
}

// The physical-channel API applies conversions: the raw log's Timestamp is float64 ns with a
// linear conversion of 1e-9, so its values are the seconds the bus reader adds to the start.
TEST(Mdf4, ReadSignalsAppliesTheConversions) {
  DYNID_REQUIRE_DIR(mdf4_dir());
  const Mdf4File file(raw_file(kSplit1));
  const auto where = file.find_group("CAN_DataFrame");
  ASSERT_TRUE(where.has_value());
  const auto s = file.read_signals(where->first, where->second,
                                   {"CAN_DataFrame.ID", "CAN_DataFrame.DataLength"});
  Mdf4BusReader reader(raw_file(kSplit1));
  const auto frames = frames_of(reader);
  ASSERT_EQ(s.time.size(), frames.size());
  for (std::size_t k = 0; k < frames.size(); k += 997) {
    EXPECT_NEAR(s.time[k] + static_cast<double>(file.start_ns()) / 1e9, frames[k].timestamp, 1e-6);
    EXPECT_EQ(s.values[0][k], frames[k].id);
    EXPECT_EQ(s.values[1][k], frames[k].length);
  }
  EXPECT_THROW(file.read_signals(where->first, where->second, {"NoSuchChannel"}), InputError);
}

TEST(Mdf4, ConversionsGiveTheirPhysicalValues) {
  Mdf4Conversion linear{Mdf4Conversion::Linear, {1.5, 2.0}, {}};
  EXPECT_EQ(linear.apply(3), 7.5);
  Mdf4Conversion rational{Mdf4Conversion::Rational, {0, 2, 1, 0, 0, 2}, {}};
  EXPECT_EQ(rational.apply(3), 3.5);
  Mdf4Conversion interpolated{Mdf4Conversion::TableInterpolated, {0, 0, 10, 100}, {}};
  EXPECT_EQ(interpolated.apply(2.5), 25);
  EXPECT_EQ(interpolated.apply(20), 100);
  Mdf4Conversion table{Mdf4Conversion::Table, {0, 0, 10, 100}, {}};
  EXPECT_EQ(table.apply(6), 100);
  Mdf4Conversion ranges{Mdf4Conversion::RangeToValue, {0, 9, 1, 10, 19, 2, -1}, {}};
  EXPECT_EQ(ranges.apply(12), 2);
  EXPECT_EQ(ranges.apply(30), -1);
  Mdf4Conversion text{Mdf4Conversion::ValueToText, {0, 1}, {"off", "on", "invalid"}};
  EXPECT_EQ(text.text(1), "on");
  EXPECT_EQ(text.text(5), "invalid");
  EXPECT_EQ(text.apply(1), 1);
}

}  // namespace
}  // namespace dynid::can
