#include "dynid/dds/participant.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <random>
#include <string_view>
#include <thread>
#include <vector>

#include <dynid/input/input_file.hpp>

#include "dynid/dds/error.hpp"

namespace dynid::dds {

namespace {

// Cyclone's log while a domain is created: dds_create_domain returns a bare "Error", and only
// its log says that no participant index was free. The lines are kept and written to stderr
// when the log ends (as Cyclone would have written them), unless dropped: a failure this class
// explains, or retries, in its own words.
class CreationLog {
 public:
  CreationLog() {
    dds_set_log_sink(&CreationLog::keep, this);
    dds_set_trace_sink(&CreationLog::keep, this);
  }
  ~CreationLog() {
    dds_set_log_sink(nullptr, nullptr);  // Cyclone's own sinks again
    dds_set_trace_sink(nullptr, nullptr);
    if (dropped_) return;
    for (const std::string& line : lines_) std::fprintf(stderr, "%s\n", line.c_str());
  }
  CreationLog(const CreationLog&) = delete;
  CreationLog& operator=(const CreationLog&) = delete;

  bool mentions(std::string_view text) {
    const std::lock_guard lock(mutex_);
    return std::any_of(lines_.begin(), lines_.end(),
                       [&](const std::string& l) { return l.find(text) != std::string::npos; });
  }
  void drop() { dropped_ = true; }

 private:
  static void keep(void* self, const dds_log_data_t* data) {
    auto* log = static_cast<CreationLog*>(self);
    std::string line(data->message, data->size);
    while (!line.empty() && line.back() == '\n') line.pop_back();
    const std::lock_guard lock(log->mutex_);
    log->lines_.push_back(std::move(line));
  }

  std::mutex mutex_;  // Cyclone's threads may log too
  std::vector<std::string> lines_;
  bool dropped_ = false;
};

}  // namespace

// One Cyclone domain instance, created with an explicit configuration. Shared by the
// Participants of its domain id in this process; deleted with the last of them.
class Participant::Domain {
 public:
  Domain(dds_domainid_t id, std::string config) : config_(std::move(config)) {
    CreationLog log;
    const dds_entity_t handle = dds_create_domain(id, config_.c_str());
    if (handle < 0 && log.mentions("free participant index")) {
      log.drop();
      throw NoParticipantIndex(id, config_, 1);
    }
    handle_ = Entity(check(handle, "dds_create_domain(" + std::to_string(id) + ")"));
  }
  const std::string& config() const { return config_; }

 private:
  std::string config_;
  Entity handle_;
};

namespace {

// Cyclone keeps one instance per domain id and process, so the registry is process-wide.
std::shared_ptr<Participant::Domain> acquire_domain(dds_domainid_t id, const std::string& config) {
  static std::mutex mutex;
  static std::map<dds_domainid_t, std::weak_ptr<Participant::Domain>> domains;
  const std::lock_guard lock(mutex);
  if (auto existing = domains[id].lock()) {
    if (existing->config() != config)
      throw DdsError("Participant: domain " + std::to_string(id) +
                         " already runs in this process with another configuration",
                     DDS_RETCODE_PRECONDITION_NOT_MET);
    return existing;
  }
  auto created = std::make_shared<Participant::Domain>(id, config);
  domains[id] = created;
  return created;
}

// Randomized, so that programs that failed together do not try again together: half to all
// of 0.1 s doubled at each attempt, at most 2 s.
std::chrono::milliseconds retry_wait(int attempt, std::mt19937& random) {
  const double base_ms = std::min(2000.0, 100.0 * std::pow(2.0, attempt - 1));
  return std::chrono::milliseconds(
      static_cast<long long>(std::uniform_real_distribution<double>(0.5, 1.0)(random) * base_ms));
}

std::shared_ptr<Participant::Domain> acquire_domain(const ParticipantOptions& options) {
  std::mt19937 random(std::random_device{}());
  const auto deadline = std::chrono::steady_clock::now() + options.index_wait;
  for (int attempt = 1;; ++attempt) {
    try {
      return acquire_domain(options.domain_id, options.config);
    } catch (const NoParticipantIndex&) {
      const auto left = deadline - std::chrono::steady_clock::now();
      if (left <= std::chrono::steady_clock::duration::zero())
        throw NoParticipantIndex(options.domain_id, options.config, attempt);
      std::this_thread::sleep_for(
          std::min<std::chrono::steady_clock::duration>(retry_wait(attempt, random), left));
    }
  }
}

std::string no_index_text(dds_domainid_t domain, const std::string& config, int attempts) {
  return "no free DDS participant index on this host for domain " + std::to_string(domain) +
         (attempts > 1 ? " (tried " + std::to_string(attempts) + " times)" : "") +
         ": each process on a domain takes one (Discovery/ParticipantIndex auto), up to "
         "Discovery/MaxAutoParticipantIndex of the Cyclone configuration " +
         config +
         ", and other DDS programs on this host (dynid cars, servers, CLIs) hold them all. Wait "
         "for some to end, or raise Discovery/MaxAutoParticipantIndex in that configuration "
         "(index i uses UDP ports 7400 + 250 x domain + 10 + 2i and the one after)";
}

}  // namespace

NoParticipantIndex::NoParticipantIndex(dds_domainid_t domain, const std::string& config,
                                       int attempts)
    : DdsError(DDS_RETCODE_OUT_OF_RESOURCES, no_index_text(domain, config, attempts)) {}

std::string config_file_uri(const std::filesystem::path& file) {
  std::error_code error;
  const auto absolute = std::filesystem::canonical(file, error);
  if (error)
    throw DdsError("config_file_uri: no configuration file " + file.string(),
                   DDS_RETCODE_BAD_PARAMETER);
  input::check_input_file(absolute, "Cyclone DDS configuration", input::kMaxTextFileBytes);
  return "file://" + absolute.string();
}

std::string config_uri(const std::string& value) {
  if (value.rfind("file://", 0) != 0 && value.rfind('<', 0) != 0) return config_file_uri(value);
  constexpr std::string_view kFile = "file://";
  for (std::size_t start = 0; start <= value.size();) {
    const auto comma = std::min(value.find(',', start), value.size());
    const std::string_view item = std::string_view(value).substr(start, comma - start);
    if (item.substr(0, kFile.size()) == kFile)
      config_file_uri(std::string(item.substr(kFile.size())));
    start = comma + 1;
  }
  return value;
}

Participant::Participant(const ParticipantOptions& options) : domain_id_(options.domain_id) {
  if (options.config.empty())
    throw DdsError("Participant: no Cyclone configuration given (the default one is never used)",
                   DDS_RETCODE_BAD_PARAMETER);
  domain_ = acquire_domain(options);
  participant_ = Entity(
      check(dds_create_participant(options.domain_id, nullptr, nullptr), "dds_create_participant"));
}

Participant::~Participant() = default;

}  // namespace dynid::dds
