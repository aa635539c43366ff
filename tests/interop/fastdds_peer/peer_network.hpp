#pragma once
// PeerNetwork: the Fast DDS side of dynid's wire contract (docs/INTEROP.md), written from the
// document and idl/dynid.idl alone, as a third party would: no dynid library is linked.
//
// - The participant comes from an XML profile ("dynid_loopback" of deploy/fastdds/loopback.xml:
//   UDPv4 on 127.0.0.1, no multicast, unicast discovery to dynid's ports) on the given domain.
// - The topic names and, per topic, the QoS of dynid's profiles: Profile::state (announcements,
//   acks, estimates: reliable, transient-local, keep-last 1), Profile::stream (chunks, requests,
//   replies: reliable, volatile, keep-all). Fast DDS 2.9 writes XCDR1 and announces no data
//   representation, which dynid takes as XCDR1: nothing to set for it.
// - Per-vehicle topics live in the partition "vehicle/<id>"; requests and replies in the default
//   partition.
//
// Contract: the constructor throws std::runtime_error when the profile or the participant cannot
// be made; the destructor deletes every entity the network created. writer()/reader() throw when
// Fast DDS refuses the entity. wait_matched() waits until the entity has at least one peer.
#include <chrono>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <string>

namespace peer {

inline constexpr const char* kRunAnnouncementTopic = "dynid/RunAnnouncement";
inline constexpr const char* kChunkTopic = "dynid/Chunk";
inline constexpr const char* kChunkAckTopic = "dynid/ChunkAck";
inline constexpr const char* kEstimateTopic = "dynid/Estimate";
inline constexpr const char* kRequestTopic = "dynid/Request";
inline constexpr const char* kReplyTopic = "dynid/Reply";

enum class Profile { state, stream };

/// "vehicle/<id>"; "" is the default partition (requests and replies).
std::string vehicle_partition(const std::string& vehicle);

class PeerNetwork {
 public:
  PeerNetwork(const std::string& profile_file, int domain);
  ~PeerNetwork();
  PeerNetwork(const PeerNetwork&) = delete;
  PeerNetwork& operator=(const PeerNetwork&) = delete;

  /// The topic `name` of the fastddsgen type `type` (registered on first use).
  eprosima::fastdds::dds::Topic* topic(const char* name,
                                       eprosima::fastdds::dds::TopicDataType* type);
  eprosima::fastdds::dds::DataWriter* writer(eprosima::fastdds::dds::Topic* topic, Profile profile,
                                             const std::string& partition);
  eprosima::fastdds::dds::DataReader* reader(eprosima::fastdds::dds::Topic* topic, Profile profile,
                                             const std::string& partition);

 private:
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
};

bool wait_matched(eprosima::fastdds::dds::DataWriter* writer, std::chrono::milliseconds patience);
bool wait_matched(eprosima::fastdds::dds::DataReader* reader, std::chrono::milliseconds patience);

}  // namespace peer
