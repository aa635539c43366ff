// The non-template parts of Writer<T> and Reader<T>.
#include <string>

#include "dynid/dds/reader.hpp"
#include "dynid/dds/writer.hpp"

namespace dynid::dds::detail {

Entity create_topic(const Participant& participant, const dds_topic_descriptor_t* descriptor,
                    const char* name, const Qos& qos) {
  return Entity(check(dds_create_topic(participant.handle(), descriptor, name, qos.get(), nullptr),
                      std::string("dds_create_topic(") + name + ")"));
}

Entity create_writer(const Participant& participant, const Entity& topic, const Qos& qos) {
  return Entity(check(dds_create_writer(participant.handle(), topic.get(), qos.get(), nullptr),
                      "dds_create_writer"));
}

Entity create_reader(const Participant& participant, const Entity& topic, const Qos& qos) {
  return Entity(check(dds_create_reader(participant.handle(), topic.get(), qos.get(), nullptr),
                      "dds_create_reader"));
}

namespace {

int matched_count(dds_entity_t entity, bool is_writer) {
  if (is_writer) {
    dds_publication_matched_status_t status;
    check(dds_get_publication_matched_status(entity, &status), "publication matched status");
    return static_cast<int>(status.current_count);
  }
  dds_subscription_matched_status_t status;
  check(dds_get_subscription_matched_status(entity, &status), "subscription matched status");
  return static_cast<int>(status.current_count);
}

}  // namespace

bool wait_for_match(dds_entity_t entity, bool is_writer, int count,
                    std::chrono::milliseconds timeout) {
  const auto mask = is_writer ? DDS_PUBLICATION_MATCHED_STATUS : DDS_SUBSCRIPTION_MATCHED_STATUS;
  check(dds_set_status_mask(entity, mask), "dds_set_status_mask");
  const Entity waitset(check(dds_create_waitset(dds_get_participant(entity)), "dds_create_waitset"));
  check(dds_waitset_attach(waitset.get(), entity, entity), "dds_waitset_attach");
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    // Reading the status resets its trigger, so the next wait sleeps until a change.
    if (matched_count(entity, is_writer) >= count) return true;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    check(dds_waitset_wait(waitset.get(), nullptr, 0, DDS_MSECS(left.count())),
          "dds_waitset_wait");
  }
}

bool check_write(dds_return_t result, const char* topic) {
  if (result == DDS_RETCODE_TIMEOUT) return false;
  check(result, std::string("dds_write(") + topic + ")");
  return true;
}

DataWaitset::DataWaitset(const Participant& participant, dds_entity_t reader)
    : condition(check(dds_create_readcondition(reader, DDS_ANY_STATE), "dds_create_readcondition")),
      waitset(check(dds_create_waitset(participant.handle()), "dds_create_waitset")) {
  check(dds_waitset_attach(waitset.get(), condition.get(), reader), "dds_waitset_attach");
}

bool DataWaitset::wait(std::chrono::milliseconds timeout) const {
  return check(dds_waitset_wait(waitset.get(), nullptr, 0, DDS_MSECS(timeout.count())),
               "dds_waitset_wait") > 0;
}

}  // namespace dynid::dds::detail
