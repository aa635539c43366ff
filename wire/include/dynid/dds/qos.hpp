#pragma once
// QoS profiles of the dynid topics (DESIGN.md, "DDS interface"), and an owning dds_qos_t.
//
//   chunk_qos     reliable, volatile, keep-all within kChunkLimits. A writer whose
//                 readers are full blocks up to max_blocking_time, then write() reports a
//                 timeout: the car keeps the chunk in its spool and retries. Volatile because
//                 the spool, not DDS, is the durable store on the car side.
//   state_qos     reliable, transient-local, keep-last 1 per instance: announcements, acks and
//                 estimates are states, and a late joiner gets the latest one of every key.
//                 Instances are not disposed when a writer goes away (a server restart does
//                 not withdraw the last estimate from readers that have it).
//   request_qos   reliable, volatile, keep-all within kRequestLimits (requests and
//                 replies: an engineer's second request must not overwrite the first).
// Every profile pins the data representation to XCDR1 (plain CDR), the encoding of the @final
// wire types that every DDS implementation reads and writes (idl/dynid.idl, docs/INTEROP.md):
// a writer announces it and a reader accepts only it.
// Partitions are set per reader/writer (see topics.hpp); the profiles carry none.
#include <dds/dds.h>

#include <chrono>
#include <string>
#include <vector>

namespace dynid::dds {

class Qos {
 public:
  Qos() : qos_(dds_create_qos()) {}
  Qos(const Qos& other);
  Qos& operator=(const Qos& other);
  ~Qos() { dds_delete_qos(qos_); }

  dds_qos_t* get() const { return qos_; }
  /// Sets the partition list (replaces any); an empty list means the default partition "".
  Qos& partitions(const std::vector<std::string>& names);

 private:
  dds_qos_t* qos_;
};

/// Resource limits of a keep-all reader or writer, so that keep-all stays bounded.
struct KeepAllLimits {
  int max_samples;               ///< over all instances
  int max_instances;             ///< chunks: runs in flight at once; requests: clients
  int max_samples_per_instance;  ///< chunks: of one run not yet taken
  std::chrono::milliseconds max_blocking_time;
};

inline constexpr KeepAllLimits kChunkLimits{1024, 1024, 64, std::chrono::milliseconds(1000)};
inline constexpr KeepAllLimits kRequestLimits{256, 256, 64, std::chrono::milliseconds(1000)};

Qos chunk_qos(const KeepAllLimits& limits = kChunkLimits);
Qos state_qos();
Qos request_qos(const KeepAllLimits& limits = kRequestLimits);

}  // namespace dynid::dds
