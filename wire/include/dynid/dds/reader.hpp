#pragma once
// Reader<T>: a typed data reader of one wire type on its topic (Topic<T>), with the topic's
// QoS profile and the given partitions (wildcards allowed, e.g. kAllVehiclesPartition), and a
// waitset-based receive.
//
// Contract:
// - take() removes up to `max` samples from the reader cache without blocking and returns
//   those that carry data (dispose/unregister notices are consumed and dropped).
// - wait_take() waits on a waitset until data is available or `timeout` passes, then takes;
//   an empty result means the timeout passed. Never blocks longer than `timeout`.
// - Samples are returned as received: validate them with from_wire() (conversions.hpp)
//   before use; a malformed one is an InputError there, not a crash.
// - On a wildcard partition (e.g. kAllVehiclesPartition), a sample with a vehicle key is
//   returned only if its writer wrote in that vehicle's own partition; the others are dropped,
//   counted (refused_by_partition()) and logged (sender_partition.hpp: what DDS Security's
//   per-partition grants need to confine a car to its own vehicle's data).
// - The Participant must outlive the Reader.
#include <dds/dds.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "dynid/dds/entity.hpp"
#include "dynid/dds/error.hpp"
#include "dynid/dds/participant.hpp"
#include "dynid/dds/sample.hpp"
#include "dynid/dds/sender_partition.hpp"
#include "dynid/dds/topics.hpp"
#include "dynid/dds/writer.hpp"

namespace dynid::dds {

namespace detail {
/// A waitset with a read condition on `reader` that triggers while it holds any sample.
struct DataWaitset {
  explicit DataWaitset(const Participant& participant, dds_entity_t reader);
  /// True when data is available within `timeout`.
  bool wait(std::chrono::milliseconds timeout) const;
  Entity condition;
  Entity waitset;
};
}  // namespace detail

template <typename T>
class Reader {
 public:
  Reader(const Participant& participant, const std::vector<std::string>& partitions)
      : topic_(detail::create_topic(participant, Topic<T>::descriptor(), Topic<T>::name,
                                    Topic<T>::qos())),
        reader_(detail::create_reader(participant, topic_,
                                      Topic<T>::qos().partitions(partitions))),
        guard_(reader_.get(), partitions),
        waitset_(participant, reader_.get()) {}

  std::vector<Sample<T>> take(std::size_t max = 64) {
    std::vector<Sample<T>> samples(max);
    std::vector<void*> buffers(max);
    std::vector<dds_sample_info_t> infos(max);
    for (std::size_t k = 0; k < max; ++k) buffers[k] = &samples[k].data;
    const dds_return_t n =
        check(dds_take(reader_.get(), buffers.data(), infos.data(), max,
                       static_cast<uint32_t>(max)),
              std::string("dds_take(") + Topic<T>::name + ")");
    std::vector<Sample<T>> taken;
    for (dds_return_t k = 0; k < n; ++k) {
      const auto index = static_cast<std::size_t>(k);
      if (!infos[index].valid_data || !from_own_partition(samples[index].data, infos[index]))
        continue;
      samples[index].publication_handle = infos[index].publication_handle;
      taken.push_back(std::move(samples[index]));
    }
    return taken;
  }

  std::vector<Sample<T>> wait_take(std::chrono::milliseconds timeout, std::size_t max = 64) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() < 0 || !waitset_.wait(left)) return {};
      auto taken = take(max);  // may hold only dispose notices: then wait on
      if (!taken.empty()) return taken;
    }
  }

  bool wait_for_writers(int count, std::chrono::milliseconds timeout) {
    return detail::wait_for_match(reader_.get(), false, count, timeout);
  }

  /// Whether the writer `publication` (Sample::publication_handle) is still matched: false once
  /// it was deleted or its participant's lease expired.
  bool matches(dds_instance_handle_t publication) const {
    dds_builtintopic_endpoint_t* endpoint =
        dds_get_matched_publication_data(reader_.get(), publication);
    if (endpoint == nullptr) return false;
    dds_builtintopic_free_endpoint(endpoint);
    return true;
  }

  dds_entity_t handle() const { return reader_.get(); }
  std::uint64_t refused_by_partition() const { return guard_.refused(); }

 private:
  bool from_own_partition(const T& data, const dds_sample_info_t& info) {
    if constexpr (requires { data.vehicle; })
      return guard_.admits(info.publication_handle, data.vehicle, sizeof data.vehicle);
    else
      return true;  // requests and replies: not per vehicle
  }

  Entity topic_;
  Entity reader_;
  SenderPartitionGuard guard_;
  detail::DataWaitset waitset_;  // last: deleted first
};

}  // namespace dynid::dds
