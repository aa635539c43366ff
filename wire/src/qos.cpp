#include "dynid/dds/qos.hpp"

namespace dynid::dds {

namespace {

dds_duration_t to_duration(std::chrono::milliseconds value) { return DDS_MSECS(value.count()); }

// XCDR1 on every endpoint: Cyclone would otherwise offer XCDR2 too, which Fast DDS 2.9 (and
// other XCDR1-only implementations) cannot decode; one representation also keeps the wire
// bytes of a sample the same whichever dynid process wrote it.
Qos with_xcdr1(Qos qos) {
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos.get(), 1, &xcdr1);
  return qos;
}

}  // namespace

Qos::Qos(const Qos& other) : qos_(dds_create_qos()) { dds_copy_qos(qos_, other.qos_); }

Qos& Qos::operator=(const Qos& other) {
  if (this != &other) dds_copy_qos(qos_, other.qos_);
  return *this;
}

Qos& Qos::partitions(const std::vector<std::string>& names) {
  std::vector<const char*> pointers;
  for (const auto& name : names) pointers.push_back(name.c_str());
  dds_qset_partition(qos_, static_cast<uint32_t>(pointers.size()), pointers.data());
  return *this;
}

namespace {

// Reliable, volatile, keep-all bounded by `limits`: a full reader makes the writer block up to
// max_blocking_time, then report a timeout, instead of dropping or growing without bound.
Qos reliable_keep_all(const KeepAllLimits& limits) {
  Qos qos;
  dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, to_duration(limits.max_blocking_time));
  dds_qset_durability(qos.get(), DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_ALL, 0);
  dds_qset_resource_limits(qos.get(), limits.max_samples, limits.max_instances,
                           limits.max_samples_per_instance);
  return with_xcdr1(qos);
}

}  // namespace

Qos chunk_qos(const KeepAllLimits& limits) { return reliable_keep_all(limits); }

Qos state_qos() {
  Qos qos;
  dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos.get(), DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, 1);
  // What a writer keeps for late joiners: also the latest per instance (Cyclone serves them
  // from this, not from the history QoS).
  dds_qset_durability_service(qos.get(), 0, DDS_HISTORY_KEEP_LAST, 1, DDS_LENGTH_UNLIMITED,
                              DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  // A writer that goes away (server restart) leaves its last states alive in readers.
  dds_qset_writer_data_lifecycle(qos.get(), false);
  return with_xcdr1(qos);
}

Qos request_qos(const KeepAllLimits& limits) { return reliable_keep_all(limits); }

}  // namespace dynid::dds
