#pragma once
// Writer<T>: a typed data writer of one wire type on its topic (Topic<T>), with the topic's QoS
// profile and the given partitions.
//
// Contract:
// - write() returns true when Cyclone accepted the sample, false when a keep-all writer stayed
//   blocked for max_blocking_time (readers full: retry later); any other failure throws
//   DdsError. A sample over a wire bound is refused by Cyclone's serializer (DdsError); build
//   samples with to_wire() (conversions.hpp) to get an InputError naming the field instead.
// - wait_for_readers() waits, on a waitset, until at least `count` readers match or `timeout`
//   passes; it returns whether they matched.
// - The Participant must outlive the Writer.
#include <dds/dds.h>

#include <chrono>
#include <string>
#include <vector>

#include "dynid/dds/entity.hpp"
#include "dynid/dds/error.hpp"
#include "dynid/dds/participant.hpp"
#include "dynid/dds/topics.hpp"

namespace dynid::dds {

namespace detail {
/// Creates (or finds) the topic of a descriptor in a participant.
Entity create_topic(const Participant& participant, const dds_topic_descriptor_t* descriptor,
                    const char* name, const Qos& qos);
Entity create_writer(const Participant& participant, const Entity& topic, const Qos& qos);
Entity create_reader(const Participant& participant, const Entity& topic, const Qos& qos);
/// Waits until the matched-count status of `entity` (publication or subscription matched)
/// reaches `count`; false on timeout.
bool wait_for_match(dds_entity_t entity, bool is_writer, int count,
                    std::chrono::milliseconds timeout);
/// false for DDS_RETCODE_TIMEOUT; throws DdsError for any other failure.
bool check_write(dds_return_t result, const char* topic);
}  // namespace detail

template <typename T>
class Writer {
 public:
  Writer(const Participant& participant, const std::vector<std::string>& partitions)
      : topic_(detail::create_topic(participant, Topic<T>::descriptor(), Topic<T>::name,
                                    Topic<T>::qos())),
        writer_(detail::create_writer(participant, topic_,
                                      Topic<T>::qos().partitions(partitions))) {}

  bool write(const T& sample) {
    return detail::check_write(dds_write(writer_.get(), &sample), Topic<T>::name);
  }

  bool wait_for_readers(int count, std::chrono::milliseconds timeout) {
    return detail::wait_for_match(writer_.get(), true, count, timeout);
  }

  dds_entity_t handle() const { return writer_.get(); }

 private:
  Entity topic_;   // declared first: deleted after the writer that uses it
  Entity writer_;
};

}  // namespace dynid::dds
