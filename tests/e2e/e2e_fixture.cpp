#include "e2e_fixture.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>

#include "child_process.hpp"
#include "dynid/dds/conversions.hpp"
#include "dynid/dds/topics.hpp"

namespace dynid::e2e {

namespace {

std::string process_tag() {
  static const std::string tag =
      "dynid-e2e-" + std::to_string(getpid()) + "-" +
      std::to_string(std::chrono::steady_clock::now().time_since_epoch().count());
  return tag;
}

bool same(double a, double b, double relative) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return std::abs(a - b) <= relative * std::max(std::abs(a), std::abs(b)) || a == b;
}

// True when every expected model is among `published` with the expected row count.
bool rows_match(const std::vector<Reference>& expected,
                const std::map<std::string, dds::EstimateTable>& published) {
  for (const auto& r : expected) {
    const auto it = published.find(r.model);
    if (it == published.end() || it->second.rows != r.rows) return false;
  }
  return !expected.empty();
}

}  // namespace

namespace {
// Set once by use_open_network(), before the first participant.
std::optional<dds_domainid_t> open_domain;
}  // namespace

std::string loopback_config() {
  const std::string file =
      dds::config_file_uri(std::string(DYNID_SOURCE_DIR) + "/deploy/cyclonedds/loopback.xml");
  if (open_domain) return file;
  return file + ",<Discovery><Tag>" + process_tag() + "</Tag></Discovery>";
}

std::string server_config() {
  return loopback_config() + "," +
         dds::config_file_uri(std::string(DYNID_SOURCE_DIR) + "/deploy/cyclonedds/server-lease.xml");
}

dds_domainid_t domain() { return open_domain.value_or(kDomain); }

void use_open_network(dds_domainid_t domain_id) { open_domain = domain_id; }

dds::Participant& participant() {
  static dds::Participant p({domain(), loopback_config()});
  return p;
}

server::ServerOptions server_options(const std::string& store_path) {
  server::ServerOptions o;
  o.store_path = store_path;
  o.cyclone_config = loopback_config();
  o.domain = domain();
  o.threads = 2;
  o.checkpoint_every = 4;
  o.publish_interval = 20ms;
  o.log_level = "warn";
  return o;
}

// ---- server ------------------------------------------------------------------------------

InProcessServer::InProcessServer(server::ServerOptions options)
    : server_(std::move(options)), thread_([this] { server_.run(); }) {}

InProcessServer::~InProcessServer() {
  server_.stop();
  thread_.join();
}

ServerProcess::ServerProcess(const std::vector<std::string>& arguments, const std::string& log) {
  std::vector<std::string> argv{DYNID_SERVER_EXE};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  pid_ = test::spawn_child(argv, {.file = log});
}

ServerProcess::~ServerProcess() {
  if (pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

void ServerProcess::signal(int sig) {
  if (pid_ > 0) kill(pid_, sig);
}

std::optional<int> ServerProcess::wait(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return status;
    }
    std::this_thread::sleep_for(20ms);
  }
  return std::nullopt;
}

CommandResult run_dynid(const std::vector<std::string>& arguments, int timeout_s,
                        std::optional<dds_domainid_t> domain_id) {
  std::vector<std::string> argv{DYNID_CLI_EXE, "--cyclone-config", loopback_config(), "--domain",
                                std::to_string(domain_id.value_or(domain())), "--timeout",
                                std::to_string(timeout_s)};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return run_command(argv, std::chrono::seconds(2 * timeout_s));
}

CommandResult run_command(const std::vector<std::string>& arguments,
                          std::chrono::milliseconds timeout) {
  // Close-on-exec: a child started meanwhile by another thread must not hold these pipes open.
  int out[2], err[2];
  if (pipe2(out, O_CLOEXEC) != 0 || pipe2(err, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  test::ChildOutput to_pipes;
  to_pipes.stdout_fd = out[1];
  to_pipes.stderr_fd = err[1];
  pid_t pid = -1;
  try {
    pid = test::spawn_child(arguments, to_pipes);
  } catch (...) {
    for (const int fd : {out[0], out[1], err[0], err[1]}) close(fd);
    throw;
  }
  close(out[1]);
  close(err[1]);
  CommandResult result;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  pollfd fds[2] = {{out[0], POLLIN, 0}, {err[0], POLLIN, 0}};
  std::string* sinks[2] = {&result.out, &result.err};
  for (int open_fds = 2; open_fds > 0 && std::chrono::steady_clock::now() < deadline;) {
    if (poll(fds, 2, 100) <= 0) continue;
    for (int k = 0; k < 2; ++k) {
      if (fds[k].fd < 0 || !(fds[k].revents & (POLLIN | POLLHUP))) continue;
      char buffer[4096];
      const ssize_t n = read(fds[k].fd, buffer, sizeof buffer);
      if (n > 0) {
        sinks[k]->append(buffer, static_cast<std::size_t>(n));
      } else {
        close(fds[k].fd);
        fds[k].fd = -1;
        --open_fds;
      }
    }
  }
  int status = 0;
  pid_t done = 0;
  while ((done = waitpid(pid, &status, WNOHANG)) == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(5ms);  // the pipes close a moment before the exit is reaped
  if (done != pid) {  // still running at the deadline
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    status = -1;
  }
  for (auto& fd : fds)
    if (fd.fd >= 0) close(fd.fd);
  result.exit_code = status >= 0 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// ---- car and watcher ------------------------------------------------------------------

TestCar::TestCar(const std::string& vehicle)
    : vehicle_(vehicle),
      announcements_(participant(), {dds::vehicle_partition(vehicle)}),
      chunks_(participant(), {dds::vehicle_partition(vehicle)}),
      acks_(participant(), {dds::vehicle_partition(vehicle)}) {}

void TestCar::announce(const ingest::RunAnnouncement& announcement) {
  announcements_.wait_for_readers(1, kPatience);
  ASSERT_TRUE(announcements_.write(dds::to_wire(announcement).data));
}

void TestCar::send(const ingest::Chunk& chunk) { send_raw(dds::to_wire(chunk).data); }

void TestCar::send_raw(const dynid_wire_Chunk& sample) {
  chunks_.wait_for_readers(1, kPatience);
  for (int attempt = 0; attempt < 50 && !chunks_.write(sample); ++attempt) {
  }  // a full reader blocks the writer for max_blocking_time; retry as the car's spool would
}

std::vector<dds::ChunkReceipt> TestCar::take_receipts() {
  std::vector<dds::ChunkReceipt> taken;
  for (auto& sample : acks_.take()) {
    taken.push_back(dds::from_wire(sample.data));
    EXPECT_EQ(taken.back().vehicle, vehicle_) << "an acknowledgement of another vehicle";
    latest_[taken.back().run] = taken.back();
  }
  return taken;
}

std::optional<dds::ChunkReceipt> TestCar::wait_receipt(
    const std::string& run, const std::function<bool(const dds::ChunkReceipt&)>& done,
    std::chrono::milliseconds patience) {
  const auto deadline = std::chrono::steady_clock::now() + patience;
  for (;;) {
    if (const auto it = latest_.find(run); it != latest_.end() && done(it->second)) return it->second;
    if (std::chrono::steady_clock::now() >= deadline) break;
    for (auto& sample : acks_.wait_take(50ms)) {
      auto receipt = dds::from_wire(sample.data);
      EXPECT_EQ(receipt.vehicle, vehicle_) << "an acknowledgement of another vehicle";
      latest_[receipt.run] = receipt;
    }
  }
  const auto it = latest_.find(run);
  return it == latest_.end() ? std::nullopt : std::optional(it->second);
}

bool TestCar::wait_acked(const std::string& run, std::int64_t last,
                         std::chrono::milliseconds patience) {
  const auto r = wait_receipt(
      run, [&](const dds::ChunkReceipt& c) { return c.highest_contiguous >= last; }, patience);
  return r && r->highest_contiguous >= last;
}

bool TestCar::stream(const ingest::RunAnnouncement& announcement,
                     const std::vector<ingest::Chunk>& chunks) {
  announce(announcement);
  return deliver(chunks);
}

bool TestCar::deliver(const std::vector<ingest::Chunk>& chunks, std::size_t from, std::size_t end) {
  end = std::min(end, chunks.size());
  if (end == 0) return true;
  const std::string& run = chunks.front().run;
  const auto last = static_cast<std::int64_t>(end) - 1;
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (std::chrono::steady_clock::now() < deadline) {
    for (std::size_t k = from; k < end; ++k) send(chunks[k]);
    if (wait_acked(run, last, 2s)) return true;
    const auto it = latest_.find(run);
    from = it == latest_.end() ? 0 : static_cast<std::size_t>(it->second.highest_contiguous + 1);
  }
  return false;
}

EstimateWatcher::EstimateWatcher(const std::string& vehicle)
    : vehicle_(vehicle), reader_(participant(), {dds::vehicle_partition(vehicle)}) {}

bool EstimateWatcher::wait_for(const std::vector<Reference>& expected, const std::string& source,
                               std::chrono::milliseconds patience) {
  const auto deadline = std::chrono::steady_clock::now() + patience;
  for (;;) {
    if (rows_match(expected, latest(source))) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    take(50ms);
  }
}

const std::map<std::string, dds::EstimateTable>& EstimateWatcher::latest(const std::string& source) const {
  static const std::map<std::string, dds::EstimateTable> none;
  const auto it = by_source_.find(source);
  return it == by_source_.end() ? none : it->second;
}

std::string EstimateWatcher::seen() const {
  std::string out;
  for (const auto& [source, tables] : by_source_) {
    out += source + ":";
    for (const auto& [model, table] : tables) out += " " + model + " rows " + std::to_string(table.rows);
    out += "; ";
  }
  return out.empty() ? "nothing" : out;
}

void EstimateWatcher::take(std::chrono::milliseconds timeout) {
  for (auto& sample : reader_.wait_take(timeout)) {
    auto table = dds::from_wire(sample.data);
    if (table.vehicle != vehicle_) ++foreign_;
    const std::string source = table.source, model = table.model;
    by_source_[source][model] = std::move(table);
  }
}

// ---- data and references --------------------------------------------------------------

ingest::test::TestRun test_run(const std::string& vehicle, const std::string& run, unsigned seed,
                               const ingest::test::Truth& truth) {
  auto r = ingest::test::make_run(6000, seed, truth);
  r.announcement.vehicle = vehicle;
  r.announcement.run = run;
  // The wire announcement (idl/dynid.idl) carries no preprocessing settings: the server runs
  // the defaults, so the reference must too.
  r.announcement.preprocessing = {};
  return r;
}

std::vector<ingest::Chunk> cut_run(const ingest::test::TestRun& run, unsigned seed,
                                   Eigen::Index largest) {
  std::vector<ingest::Chunk> chunks;
  Eigen::Index first = 0;
  for (const Eigen::Index size : ingest::test::random_cuts(run.samples.rows(), largest, seed)) {
    chunks.push_back(ingest::test::cut(run, chunks.size(), first, size));
    first += size;
  }
  return chunks;
}

ingest::RunProcessor offline(const ingest::test::TestRun& run,
                             const std::vector<ingest::Chunk>& chunks) {
  ingest::RunProcessor processor(run.announcement);
  for (const auto& chunk : chunks) processor.push(chunk);
  return processor;
}

Reference reference_of(const std::string& model, const std::vector<model::ParameterInfo>& parameters,
                       const ls::WeightedEstimate& estimate) {
  Reference r{model, {}, estimate.estimate.rows, estimate.estimate.value,
              estimate.estimate.standard_deviation, estimate.estimate.sigma};
  for (const auto& p : parameters) r.names.push_back(p.name);
  return r;
}

std::vector<Reference> references(const std::vector<ingest::ModelEstimate>& estimates) {
  std::vector<Reference> out;
  for (const auto& e : estimates)
    if (e.estimate) out.push_back(reference_of(e.model, e.parameters, *e.estimate));
  return out;
}

void expect_equal(const Reference& expected, const dds::EstimateTable& published, double relative) {
  ASSERT_EQ(published.parameters.size(), expected.names.size()) << expected.model;
  EXPECT_EQ(published.rows, expected.rows) << expected.model;
  EXPECT_TRUE(same(published.sigma, expected.sigma, relative)) << expected.model;
  for (std::size_t j = 0; j < expected.names.size(); ++j) {
    const auto& p = published.parameters[j];
    const auto index = static_cast<Eigen::Index>(j);
    EXPECT_EQ(p.name, expected.names[j]);
    EXPECT_TRUE(same(p.value, expected.value(index), relative))
        << expected.model << "." << p.name << ": " << p.value << " vs " << expected.value(index);
    EXPECT_TRUE(same(p.standard_deviation, expected.std(index), relative))
        << expected.model << "." << p.name << " std: " << p.standard_deviation << " vs "
        << expected.std(index);
  }
}

dds::Reply request(const std::string& kind, const std::vector<dds::RequestArgument>& arguments,
                   std::chrono::milliseconds patience) {
  static cli::RequestClient client(participant(), "e2e-" + std::to_string(getpid()));
  return client.call(kind, arguments, patience, 500ms);
}

}  // namespace dynid::e2e
