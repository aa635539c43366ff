#include "faults_fixture.hpp"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/mount.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "dynid/car/vehicle_profile.hpp"
#include "dynid/dds/conversions.hpp"
#include "dynid/dds/topics.hpp"
#include "dynid/ingest/run_processor.hpp"
#include "dynid/report/estimate_report.hpp"
#include "dynid/server/estimate_tables.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace dynid::faults {

namespace {

std::vector<std::string> server_command(const std::filesystem::path& store, int checkpoint_every) {
  return {DYNID_SERVER, "--store", store.string(), "--cyclone-config", loopback_options().config,
          "--domain", std::to_string(kDomain), "--threads", "2", "--checkpoint-every",
          std::to_string(checkpoint_every), "--publish-interval-ms", "50"};
}

std::string sql_error(sqlite3* db, const std::string& what) {
  return what + ": " + (db ? sqlite3_errmsg(db) : "out of memory");
}

// One prepared statement, finalized on scope exit.
struct Query {
  Query(sqlite3* connection, const char* sql) : db(connection) {
    if (sqlite3_prepare_v2(db, sql, -1, &statement, nullptr) != SQLITE_OK)
      throw std::runtime_error(sql_error(db, sql));
  }
  ~Query() { sqlite3_finalize(statement); }
  Query& bind(int index, const std::string& text) {
    sqlite3_bind_text(statement, index, text.c_str(), static_cast<int>(text.size()), SQLITE_TRANSIENT);
    return *this;
  }
  bool step() {
    const int rc = sqlite3_step(statement);
    if (rc != SQLITE_ROW && rc != SQLITE_DONE) throw std::runtime_error(sql_error(db, "step"));
    return rc == SQLITE_ROW;
  }
  std::int64_t integer(int column) const { return sqlite3_column_int64(statement, column); }
  std::string bytes(int column) const {
    const void* data = sqlite3_column_blob(statement, column);
    return data ? std::string(static_cast<const char*>(data),
                              static_cast<std::size_t>(sqlite3_column_bytes(statement, column)))
                : std::string();
  }
  sqlite3* db;
  sqlite3_stmt* statement = nullptr;
};

constexpr const char* kRunOfVehicle =
    "(SELECT r.id FROM runs r JOIN vehicles v ON v.id = r.vehicle_id WHERE v.name = ?1 AND r.name = ?2)";

// |a - b| relative to the larger magnitude (0 when equal, NaN matching NaN).
double relative_difference(double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) ? 0.0 : INFINITY;
  if (a == b) return 0.0;
  return std::abs(a - b) / std::max(std::abs(a), std::abs(b));
}

// NaN and infinities are written as null (report/json.hpp).
double number(const nlohmann::json& value) {
  return value.is_null() ? std::nan("") : value.get<double>();
}

}  // namespace

// ---- processes ---------------------------------------------------------------------------

ServerProcess::ServerProcess(const std::filesystem::path& store, const std::filesystem::path& log,
                             int checkpoint_every)
    : child_(server_command(store, checkpoint_every), log) {}

bool ServerProcess::kill(std::string& why) {
  if (!child_.running()) {
    why = "the server had already ended: " + std::to_string(child_.wait(std::chrono::milliseconds(0)).value_or(-1));
    return false;
  }
  child_.signal(SIGKILL);
  const auto status = child_.wait(15s);
  if (status != 128 + SIGKILL) {
    why = "the server did not die of SIGKILL: " + std::to_string(status.value_or(-1));
    return false;
  }
  return true;
}

std::optional<int> ServerProcess::stop() {
  child_.signal(SIGTERM);
  return child_.wait(15s);
}

AckWatch::AckWatch() : participant_(loopback_options()), reader_(participant_, {dds::vehicle_partition(kVehicle)}) {}

bool AckWatch::wait(const std::string& run, std::int64_t sequence, std::chrono::milliseconds patience) {
  const auto deadline = std::chrono::steady_clock::now() + patience;
  while (highest_ < sequence && std::chrono::steady_clock::now() < deadline) take(run, 20ms);
  return highest_ >= sequence;
}

void AckWatch::take(const std::string& run, std::chrono::milliseconds wait) {
  for (const auto& sample : reader_.wait_take(wait)) {
    const auto receipt = dds::from_wire(sample.data);
    if (receipt.run == run) highest_ = std::max(highest_, receipt.highest_contiguous);
  }
}

std::vector<std::string> car_command(const std::filesystem::path& spool, const std::string& run,
                                     const std::filesystem::path& log, double speed) {
  std::vector<std::string> argv{DYNID_CAR, "--profile", testcar_profile().string(), "--cyclone-config",
                                loopback_options().config, "--domain", std::to_string(kDomain), "--spool",
                                spool.string(), "--ack-timeout", "1", "--drain-timeout", "90"};
  if (log.empty()) return argv;
  argv.insert(argv.end(), {"--run", run, "--replay", log.string()});
  if (speed > 0) {
    argv.insert(argv.end(), {"--speed", std::to_string(speed)});
  } else {
    argv.push_back("--fast");
  }
  return argv;
}

std::string dynid_cli(const std::filesystem::path& scratch, const std::vector<std::string>& args) {
  std::vector<std::string> argv{DYNID_CLI, "--cyclone-config", loopback_options().config, "--domain",
                                std::to_string(kDomain), "--timeout", "15"};
  argv.insert(argv.end(), args.begin(), args.end());
  const auto out = scratch / "dynid-cli.out";
  std::filesystem::remove(out);
  Child command(argv, out);
  const auto status = command.wait(30s);
  EXPECT_EQ(status, 0) << "dynid " << args.front() << ": " << read_text(out);
  return read_text(out);
}

std::string text_since(const std::filesystem::path& file, std::size_t offset) {
  const std::string text = read_text(file);
  return offset < text.size() ? text.substr(offset) : std::string();
}

// ---- the store, read-only ------------------------------------------------------------------

StoreReader::StoreReader(const std::filesystem::path& file) {
  if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    const std::string message = sql_error(db_, "open " + file.string() + " read-only");
    sqlite3_close(db_);
    throw std::runtime_error(message);
  }
}

StoreReader::~StoreReader() { sqlite3_close(db_); }

StoreReader::Ledger StoreReader::ledger(const std::string& run) {
  Query q(db_, (std::string("SELECT contiguous_through, folded_through FROM ledger WHERE run_id = ") +
                kRunOfVehicle).c_str());
  q.bind(1, kVehicle).bind(2, run);
  if (!q.step()) return {};
  return {q.integer(0), q.integer(1)};
}

std::vector<std::pair<std::int64_t, std::string>> StoreReader::chunks(const std::string& run) {
  Query q(db_, (std::string("SELECT sequence, bytes FROM chunks WHERE run_id = ") + kRunOfVehicle +
                " ORDER BY sequence").c_str());
  q.bind(1, kVehicle).bind(2, run);
  std::vector<std::pair<std::int64_t, std::string>> out;
  while (q.step()) out.emplace_back(q.integer(0), q.bytes(1));
  return out;
}

std::map<std::string, std::string> StoreReader::final_estimates(const std::string& run) {
  Query q(db_,
          "SELECT e.model, e.encoded FROM estimates e JOIN vehicles v ON v.id = e.vehicle_id "
          "WHERE v.name = ?1 AND e.scope = ?2 ORDER BY e.id");
  q.bind(1, kVehicle).bind(2, run);
  std::map<std::string, std::string> latest;
  while (q.step()) latest[q.bytes(0)] = q.bytes(1);  // later rows replace earlier ones
  return latest;
}

std::string StoreReader::quick_check() {
  Query q(db_, "PRAGMA quick_check");
  std::string answer;
  while (q.step()) answer += (answer.empty() ? "" : "\n") + q.bytes(0);
  return answer;
}

std::int64_t StoreReader::integer(const char* sql) {
  Query q(db_, sql);
  return q.step() ? q.integer(0) : -1;
}

void expect_stored_once(StoreReader& store, const std::string& run, const std::vector<ingest::Chunk>& expected) {
  const auto stored = store.chunks(run);
  ASSERT_EQ(stored.size(), expected.size()) << run << ": stored chunks";
  for (std::size_t n = 0; n < stored.size(); ++n) {
    ASSERT_EQ(stored[n].first, static_cast<std::int64_t>(n)) << run << ": a sequence is missing or repeated";
    EXPECT_EQ(stored[n].second, ingest::encode_chunk(expected[n])) << run << "#" << n << " differs";
  }
  const auto marks = store.ledger(run);
  const auto last = static_cast<std::int64_t>(expected.size()) - 1;
  EXPECT_EQ(marks.contiguous_through, last) << run;
  EXPECT_EQ(marks.folded_through, last) << run << ": folded mark";
}

double expect_same_estimates(const std::map<std::string, std::string>& actual,
                             const std::map<std::string, std::string>& reference, double relative) {
  EXPECT_FALSE(reference.empty()) << "the reference run has no final estimate";
  EXPECT_EQ(actual.size(), reference.size()) << "not the same models";
  double worst = 0.0;
  const auto compare = [&](double a, double b, const std::string& what) {
    const double d = relative_difference(a, b);
    worst = std::max(worst, d);
    EXPECT_LE(d, relative) << what << ": " << a << " vs " << b;
  };
  for (const auto& [model, text] : reference) {
    const auto it = actual.find(model);
    if (it == actual.end()) {
      ADD_FAILURE() << "model " << model << " has no final estimate";
      continue;
    }
    const auto a = nlohmann::json::parse(it->second);
    const auto r = nlohmann::json::parse(text);
    EXPECT_EQ(a.at("rows"), r.at("rows")) << model << ": row count (a chunk folded twice or not at all)";
    EXPECT_EQ(a.at("groups").dump(), r.at("groups").dump()) << model << ": groups";  // rows, residual RMS
    compare(number(a.at("sigma")), number(r.at("sigma")), model + " sigma");
    const auto& ap = a.at("parameters");
    const auto& rp = r.at("parameters");
    if (ap.size() != rp.size()) {
      ADD_FAILURE() << model << ": parameters differ";
      continue;
    }
    for (std::size_t j = 0; j < rp.size(); ++j) {
      const std::string name = model + "." + rp[j].at("name").get<std::string>();
      EXPECT_EQ(ap[j].at("name"), rp[j].at("name"));
      compare(number(ap[j].at("value")), number(rp[j].at("value")), name);
      compare(number(ap[j].at("std")), number(rp[j].at("std")), name + " std");
    }
  }
  return worst;
}

std::map<std::string, std::string> offline_estimates(const std::string& run,
                                                     const std::vector<ingest::Chunk>& chunks) {
  const auto announced = car::load_vehicle_profile(testcar_profile()).announcement(run);
  ingest::RunProcessor processor(dds::from_wire(dds::to_wire(announced).data));
  for (const auto& chunk : chunks) processor.push(chunk);
  processor.finish();
  std::map<std::string, std::string> out;
  for (const auto& table : server::tables_of(kVehicle, run, processor.estimates()).tables)
    out[table.model] = report::estimate_json(table);
  return out;
}

// ---- a small filesystem ------------------------------------------------------------------

SmallDisk::SmallDisk(const std::filesystem::path& parent, std::uint64_t bytes) : path_(parent / "small-disk") {
  std::filesystem::create_directories(path_);
  // A private mount namespace for this thread (and the processes it starts): the mount never
  // outlives the test, whatever happens to it.
  if (unshare(CLONE_NEWNS) != 0)
    throw std::runtime_error(std::string("unshare(CLONE_NEWNS): ") + std::strerror(errno) +
                             " (a real full disk needs CAP_SYS_ADMIN to mount a small tmpfs)");
  if (mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0)
    throw std::runtime_error(std::string("mount --make-rprivate /: ") + std::strerror(errno));
  const std::string options = "size=" + std::to_string(bytes) + ",mode=0755";
  if (mount("dynid-faults", path_.c_str(), "tmpfs", MS_NOSUID | MS_NODEV, options.c_str()) != 0)
    throw std::runtime_error("mount -t tmpfs " + path_.string() + ": " + std::strerror(errno));
}

SmallDisk::~SmallDisk() { umount2(path_.c_str(), MNT_DETACH); }

std::uint64_t SmallDisk::fill() {
  const auto file = path_ / "filler";
  const int fd = open(file.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0) throw std::runtime_error("open " + file.string() + ": " + std::strerror(errno));
  const std::string block(4096, 'f');
  std::uint64_t written = 0;
  for (;;) {
    const ssize_t n = write(fd, block.data(), block.size());
    if (n <= 0) break;  // ENOSPC: full
    written += static_cast<std::uint64_t>(n);
  }
  const int error = errno;
  close(fd);
  if (error != ENOSPC) throw std::runtime_error("filling " + file.string() + ": " + std::strerror(error));
  return written;
}

void SmallDisk::make_room() { std::filesystem::remove(path_ / "filler"); }

std::uint64_t SmallDisk::free_bytes() const {
  struct statvfs s {};
  if (statvfs(path_.c_str(), &s) != 0) return 0;
  return static_cast<std::uint64_t>(s.f_bavail) * s.f_frsize;
}

}  // namespace dynid::faults
