#include "peer_network.hpp"

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <stdexcept>
#include <thread>

namespace peer {

namespace dds = eprosima::fastdds::dds;

namespace {

constexpr const char* kProfileName = "dynid_loopback";

// Samples are allocated to their size: the preallocating default would reserve the type's bound
// (32 MiB for a chunk, 16 MiB for a reply) per history slot.
constexpr auto kMemoryPolicy = eprosima::fastrtps::rtps::DYNAMIC_RESERVE_MEMORY_MODE;

template <typename Qos>
void apply(Qos& qos, Profile profile) {
  qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  qos.reliability().max_blocking_time = eprosima::fastrtps::Duration_t(1, 0);
  if (profile == Profile::state) {
    // A state: the latest sample per key, also for a late joiner.
    qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
    qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    qos.history().depth = 1;
  } else {
    // A stream: every sample, none kept for late joiners.
    qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
    qos.history().kind = dds::KEEP_ALL_HISTORY_QOS;
  }
  qos.endpoint().history_memory_policy = kMemoryPolicy;
}

// Polls `count` (the entity's matched peers) until it is positive or `patience` is over.
template <typename Count>
bool wait_for_count(Count count, std::chrono::milliseconds patience) {
  const auto deadline = std::chrono::steady_clock::now() + patience;
  for (;;) {
    if (count() > 0) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace

std::string vehicle_partition(const std::string& vehicle) {
  return "vehicle/" + vehicle;
}

PeerNetwork::PeerNetwork(const std::string& profile_file, int domain) {
  auto* factory = dds::DomainParticipantFactory::get_instance();
  if (factory->load_XML_profiles_file(profile_file) != ReturnCode_t::RETCODE_OK)
    throw std::runtime_error("cannot load the Fast DDS profiles " + profile_file);
  participant_ =
      factory->create_participant_with_profile(static_cast<dds::DomainId_t>(domain), kProfileName);
  if (!participant_)
    throw std::runtime_error("cannot create a participant with the profile dynid_loopback");
}

PeerNetwork::~PeerNetwork() {
  participant_->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

dds::Topic* PeerNetwork::topic(const char* name, dds::TopicDataType* type) {
  dds::TypeSupport support(type);
  support.register_type(participant_);  // the same type again is accepted
  dds::Topic* topic =
      participant_->create_topic(name, support.get_type_name(), dds::TOPIC_QOS_DEFAULT);
  if (!topic) throw std::runtime_error(std::string("cannot create the topic ") + name);
  return topic;
}

dds::DataWriter* PeerNetwork::writer(dds::Topic* topic, Profile profile,
                                     const std::string& partition) {
  dds::PublisherQos pq = dds::PUBLISHER_QOS_DEFAULT;
  if (!partition.empty()) pq.partition().push_back(partition.c_str());
  dds::Publisher* publisher = participant_->create_publisher(pq);
  dds::DataWriterQos wq = publisher->get_default_datawriter_qos();
  apply(wq, profile);
  // Chunks are larger than a datagram: an asynchronous writer fragments them on its own thread.
  if (profile == Profile::stream) wq.publish_mode().kind = dds::ASYNCHRONOUS_PUBLISH_MODE;
  dds::DataWriter* writer = publisher->create_datawriter(topic, wq);
  if (!writer) throw std::runtime_error("Fast DDS refused a writer of " + topic->get_name());
  return writer;
}

dds::DataReader* PeerNetwork::reader(dds::Topic* topic, Profile profile,
                                     const std::string& partition) {
  dds::SubscriberQos sq = dds::SUBSCRIBER_QOS_DEFAULT;
  if (!partition.empty()) sq.partition().push_back(partition.c_str());
  dds::Subscriber* subscriber = participant_->create_subscriber(sq);
  dds::DataReaderQos rq = subscriber->get_default_datareader_qos();
  apply(rq, profile);
  dds::DataReader* reader = subscriber->create_datareader(topic, rq);
  if (!reader) throw std::runtime_error("Fast DDS refused a reader of " + topic->get_name());
  return reader;
}

bool wait_matched(dds::DataWriter* writer, std::chrono::milliseconds patience) {
  return wait_for_count(
      [writer] {
        dds::PublicationMatchedStatus status;
        writer->get_publication_matched_status(status);
        return status.current_count;
      },
      patience);
}

bool wait_matched(dds::DataReader* reader, std::chrono::milliseconds patience) {
  return wait_for_count(
      [reader] {
        dds::SubscriptionMatchedStatus status;
        reader->get_subscription_matched_status(status);
        return status.current_count;
      },
      patience);
}

}  // namespace peer
