#pragma once
// Participant: a DDS domain participant on a domain created with an explicit Cyclone
// configuration. There is no default: a participant never falls back to Cyclone's built-in
// configuration (which picks the machine's default interface), so tests and the demo stay on
// the interface that deploy/cyclonedds/*.xml selects.
//
// Contract:
// - `config` is what Cyclone accepts in CYCLONEDDS_URI: file URIs ("file:///path.xml") and XML
//   fragments, comma-separated, later ones overriding earlier ones. Empty -> DdsError.
// - Cyclone allows one instance of a domain per process. The first Participant on a domain id
//   creates it with its config; later participants in the same process share it and must pass
//   the same config string (DdsError otherwise, rather than silently running on another
//   config). The domain is deleted with its last Participant.
// - Two participants of one process on one domain talk through Cyclone's local delivery, with
//   the same QoS and partition matching as across processes.
// - Every process on a host and domain takes one participant index (its unicast ports), with
//   Discovery/ParticipantIndex "auto" the first free one up to Discovery/MaxAutoParticipantIndex
//   (deploy/cyclonedds/loopback.xml allows 60). When none is free the domain cannot be created:
//   NoParticipantIndex says so and what to do, instead of Cyclone's bare "Error". With
//   ParticipantOptions::index_wait > 0 the creation is tried again after randomized waits
//   (about 0.1, 0.2, 0.4, ... s, at most 2 s each) until that much time has passed: the other
//   programs may end meanwhile (a storm of short CLI requests). A budget of time, not of
//   attempts, because how long the others hold their indices is what decides.
// - While a domain is created, Cyclone's log goes through this class (to tell that failure from
//   the others) and is written to stderr unchanged, except the lines of a retried failure.
#include <dds/dds.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include "dynid/dds/entity.hpp"
#include "dynid/dds/error.hpp"

namespace dynid::dds {

struct ParticipantOptions {
  dds_domainid_t domain_id = 0;
  std::string config;  ///< required, see above
  /// How long to keep trying when no participant index is free (see above); 0: one try.
  std::chrono::milliseconds index_wait{0};
};

/// The domain could not be created because every participant index its configuration allows is
/// held by another process on this host (see the contract above).
class NoParticipantIndex : public DdsError {
 public:
  NoParticipantIndex(dds_domainid_t domain, const std::string& config, int attempts);
};

/// "file://<absolute path>" for a configuration file. Throws DdsError if it does not exist,
/// InputError if it is not a regular file (a FIFO would block Cyclone) or is over
/// input::kMaxTextFileBytes.
std::string config_file_uri(const std::filesystem::path& file);

/// The value of a program's --cyclone-config option as Participant takes it: a value starting
/// with "file://" or "<" (URIs and XML fragments, comma-separated, as in CYCLONEDDS_URI) is used
/// as it is, after checking every "file://" item as config_file_uri checks a file; anything else
/// is a path to a file (config_file_uri).
std::string config_uri(const std::string& value);

class Participant {
 public:
  explicit Participant(const ParticipantOptions& options);
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;
  ~Participant();

  dds_entity_t handle() const { return participant_.get(); }
  dds_domainid_t domain_id() const { return domain_id_; }

  class Domain;  // process-wide, shared by the participants of one domain id

 private:
  dds_domainid_t domain_id_;
  std::shared_ptr<Domain> domain_;  // declared first: destroyed after the participant
  Entity participant_;
};

}  // namespace dynid::dds
