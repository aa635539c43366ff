#include "dynid/dds/participant.hpp"

#include <algorithm>
#include <map>
#include <string_view>
#include <mutex>

#include <dynid/input/input_file.hpp>

#include "dynid/dds/error.hpp"

namespace dynid::dds {

// One Cyclone domain instance, created with an explicit configuration. Shared by the
// Participants of its domain id in this process; deleted with the last of them.
class Participant::Domain {
 public:
  Domain(dds_domainid_t id, std::string config) : config_(std::move(config)) {
    handle_ = Entity(check(dds_create_domain(id, config_.c_str()),
                           "dds_create_domain(" + std::to_string(id) + ")"));
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

}  // namespace

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
    if (item.substr(0, kFile.size()) == kFile) config_file_uri(std::string(item.substr(kFile.size())));
    start = comma + 1;
  }
  return value;
}

Participant::Participant(const ParticipantOptions& options) : domain_id_(options.domain_id) {
  if (options.config.empty())
    throw DdsError("Participant: no Cyclone configuration given (the default one is never used)",
                   DDS_RETCODE_BAD_PARAMETER);
  domain_ = acquire_domain(options.domain_id, options.config);
  participant_ = Entity(check(dds_create_participant(options.domain_id, nullptr, nullptr),
                              "dds_create_participant"));
}

Participant::~Participant() = default;

}  // namespace dynid::dds
