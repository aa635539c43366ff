// fastdds_peer: a third-party dynid client on eProsima Fast DDS 2.9, built from idl/dynid.idl by
// fastddsgen and from docs/INTEROP.md; tests/interop runs it against a real dynid-server.
//
//   fastdds_peer --profile <xml> --domain <id> estimates --vehicle V [--models N] [--seconds S]
//       Prints every dynid/Estimate table of V as a JSON line (dynid estimates --json's keys),
//       flushed as it arrives. With --models: exits 0 once N models were seen (a late joiner
//       gets the latest of each from the server's durability). Exits 1 when S seconds pass
//       first (0 without --models).
//   fastdds_peer ... request --kind K [--arg name=value]... [--seconds S]
//       One request, resent every second until its reply (as dynid's own client does): prints
//       the payload on stdout and "status <NAME>" (and the error) on stderr; exits 0 for OK,
//       3 for another status, 1 without a reply.
//   fastdds_peer ... car --vehicle V --run-file F [--corrupt K] [--seconds S]
//       Acts as a car: announces the run of F (JSON: the announcement and the chunks, without
//       vehicle and checksum) and streams its chunks, each with its computed checksum, resending
//       those after the highest acknowledged until every one is acknowledged. Prints the last
//       ChunkAck as a JSON line (with any rejections); exits 0 when all are acknowledged.
//       --corrupt K: chunk K goes with a wrong checksum (bad input from a foreign peer).
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "chunk_checksum.hpp"
#include "dynidPubSubTypes.h"
#include "estimate_json.hpp"
#include "peer_network.hpp"

namespace {

namespace dds = eprosima::fastdds::dds;
namespace wire = dynid::wire;
using clock_type = std::chrono::steady_clock;
using namespace std::chrono_literals;

volatile std::sig_atomic_t stop_requested = 0;

struct Options {
  std::string profile, command, vehicle, kind, run_file;
  int domain = 0, models = 0, corrupt = -1;
  double seconds = 30;
  std::vector<std::pair<std::string, std::string>> arguments;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    if (a == "--profile")
      o.profile = value();
    else if (a == "--domain")
      o.domain = std::stoi(value());
    else if (a == "--vehicle")
      o.vehicle = value();
    else if (a == "--models")
      o.models = std::stoi(value());
    else if (a == "--seconds")
      o.seconds = std::stod(value());
    else if (a == "--kind")
      o.kind = value();
    else if (a == "--corrupt")
      o.corrupt = std::stoi(value());
    else if (a == "--run-file")
      o.run_file = value();
    else if (a == "--arg") {
      const std::string kv = value();
      const auto eq = kv.find('=');
      if (eq == std::string::npos) throw std::invalid_argument("--arg takes name=value");
      o.arguments.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
    } else if (o.command.empty() && a.rfind("--", 0) != 0)
      o.command = a;
    else
      throw std::invalid_argument("unknown argument " + a);
  }
  if (o.profile.empty() || o.command.empty())
    throw std::invalid_argument("--profile and a command are required");
  return o;
}

clock_type::time_point deadline_of(const Options& o) {
  return clock_type::now() + std::chrono::milliseconds(static_cast<long long>(o.seconds * 1000));
}

// ---- estimates ---------------------------------------------------------------------------

int estimates(peer::PeerNetwork& net, const Options& o) {
  auto* topic = net.topic(peer::kEstimateTopic, new wire::EstimatePubSubType());
  auto* reader = net.reader(topic, peer::Profile::state, peer::vehicle_partition(o.vehicle));
  std::map<std::string, std::uint64_t> seen;  // model -> latest revision
  const auto deadline = deadline_of(o);
  while (clock_type::now() < deadline && !stop_requested) {
    if (o.models > 0 && static_cast<int>(seen.size()) >= o.models) return 0;
    if (!reader->wait_for_unread_message(eprosima::fastrtps::Duration_t(0, 100'000'000))) continue;
    wire::Estimate sample;
    dds::SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      std::cout << peer::estimate_json(sample).dump() << std::endl;
      seen[sample.model().to_string()] = sample.revision();
    }
  }
  return o.models > 0 && static_cast<int>(seen.size()) < o.models ? 1 : 0;
}

// ---- request -----------------------------------------------------------------------------

const char* status_name(wire::ReplyStatus status) {
  switch (status) {
    case wire::OK:
      return "OK";
    case wire::BAD_REQUEST:
      return "BAD_REQUEST";
    case wire::NOT_FOUND:
      return "NOT_FOUND";
    case wire::FAILED:
      return "FAILED";
  }
  return "UNKNOWN";
}

wire::Request make_request(const Options& o, const std::string& client) {
  wire::Request request;
  request.client(client);
  request.correlation_id(1);
  request.kind(o.kind);
  for (const auto& [name, value] : o.arguments) {
    wire::Argument argument;
    argument.name(name);
    argument.value(value);
    request.arguments().push_back(argument);
  }
  return request;
}

// The reply to (client, 1), or false at the deadline.
bool await_reply(dds::DataReader* replies, const std::string& client, clock_type::time_point until,
                 wire::Reply& reply) {
  while (clock_type::now() < until) {
    if (!replies->wait_for_unread_message(eprosima::fastrtps::Duration_t(0, 100'000'000))) continue;
    dds::SampleInfo info;
    while (replies->take_next_sample(&reply, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data && reply.client() == client && reply.correlation_id() == 1) return true;
  }
  return false;
}

int request(peer::PeerNetwork& net, const Options& o) {
  auto* requests = net.writer(net.topic(peer::kRequestTopic, new wire::RequestPubSubType()),
                              peer::Profile::stream, "");
  auto* replies = net.reader(net.topic(peer::kReplyTopic, new wire::ReplyPubSubType()),
                             peer::Profile::stream, "");
  const auto deadline = deadline_of(o);
  // Volatile topics: a request written before the server's reader matched, or a reply before
  // ours did, is lost; so wait for both, then resend until the reply comes.
  const auto patience =
      std::chrono::duration_cast<std::chrono::milliseconds>(deadline - clock_type::now());
  if (!peer::wait_matched(requests, patience) || !peer::wait_matched(replies, patience)) {
    std::cerr << "no dynid-server matched\n";
    return 1;
  }
  const std::string client = "fastdds-peer/" + std::to_string(::getpid());
  wire::Request sample = make_request(o, client);
  wire::Reply reply;
  while (clock_type::now() < deadline) {
    requests->write(&sample);
    if (!await_reply(replies, client, std::min(deadline, clock_type::now() + 1s), reply)) continue;
    std::cout.write(reinterpret_cast<const char*>(reply.payload().data()),
                    static_cast<std::streamsize>(reply.payload().size()));
    std::cerr << "status " << status_name(reply.status()) << (reply.error().size() == 0 ? "" : ": ")
              << reply.error().to_string() << "\n";
    return reply.status() == wire::OK ? 0 : 3;
  }
  std::cerr << "no reply\n";
  return 1;
}

// ---- car ---------------------------------------------------------------------------------

wire::RunAnnouncement announcement_of(const nlohmann::json& j, const std::string& vehicle) {
  wire::RunAnnouncement a;
  a.vehicle(vehicle);
  a.run(j.at("run").get<std::string>());
  a.sample_rate_hz(j.at("sample_rate_hz").get<double>());
  for (const auto& c : j.at("channels")) {
    wire::ChannelSpec spec;
    spec.name(c.at("name").get<std::string>());
    spec.unit(c.at("unit").get<std::string>());
    a.channels().push_back(spec);
  }
  for (const auto& m : j.at("models")) {
    wire::ModelSpec spec;
    spec.model(m.at("model").get<std::string>());
    for (const auto& [name, value] : m.at("constants").items()) {
      wire::NamedValue constant;
      constant.name(name);
      constant.value(value.get<double>());
      spec.constants().push_back(constant);
    }
    for (const auto& e : m.at("effects")) spec.effects().push_back(e.get<std::string>());
    a.models().push_back(spec);
  }
  a.butterworth_order(j.value("butterworth_order", 0));
  a.cutoff_hz(j.value("cutoff_hz", 0.0));
  a.odmf(j.value("odmf", 0));
  const nlohmann::json noise_of = j.value("channel_noise", nlohmann::json::object());
  for (const auto& [name, value] : noise_of.items()) {
    wire::NamedValue noise;
    noise.name(name);
    noise.value(value.get<double>());
    a.channel_noise().push_back(noise);
  }
  return a;
}

wire::Chunk chunk_of(const nlohmann::json& j, const wire::RunAnnouncement& run) {
  wire::Chunk c;
  c.vehicle(run.vehicle());
  c.run(run.run());
  c.sequence_number(j.at("sequence_number").get<std::uint64_t>());
  c.first_sample_index(j.at("first_sample_index").get<std::uint64_t>());
  c.rows(j.at("rows").get<std::uint32_t>());
  c.channels(j.at("channels").get<std::uint32_t>());
  c.data(j.at("data").get<std::vector<double>>());
  c.valid(j.at("valid").get<std::vector<std::uint8_t>>());
  c.checksum(peer::chunk_checksum(c));
  return c;
}

nlohmann::json ack_json(const wire::ChunkAck& ack) {
  nlohmann::json rejections = nlohmann::json::array();
  for (const auto& r : ack.rejections())
    rejections.push_back(
        {{"sequence_number", r.sequence_number()}, {"reason", r.reason().to_string()}});
  return {{"vehicle", ack.vehicle().to_string()},
          {"run", ack.run().to_string()},
          {"highest_contiguous", ack.highest_contiguous()},
          {"rejections", rejections}};
}

// Takes the acknowledgements that came; keeps the latest of `run` in `latest`.
void take_acks(dds::DataReader* acks, const std::string& run, wire::ChunkAck& latest) {
  wire::ChunkAck ack;
  dds::SampleInfo info;
  while (acks->take_next_sample(&ack, &info) == ReturnCode_t::RETCODE_OK)
    if (info.valid_data && ack.run() == run) latest = ack;
}

int car(peer::PeerNetwork& net, const Options& o) {
  std::ifstream in(o.run_file);
  const nlohmann::json file = nlohmann::json::parse(in);
  const wire::RunAnnouncement run = announcement_of(file.at("announcement"), o.vehicle);
  std::vector<wire::Chunk> chunks;
  for (const auto& c : file.at("chunks")) chunks.push_back(chunk_of(c, run));
  if (o.corrupt >= 0) {
    auto& bad = chunks.at(static_cast<std::size_t>(o.corrupt));
    bad.checksum(bad.checksum() ^ 1U);
  }

  const std::string partition = peer::vehicle_partition(o.vehicle);
  auto* announcements =
      net.writer(net.topic(peer::kRunAnnouncementTopic, new wire::RunAnnouncementPubSubType()),
                 peer::Profile::state, partition);
  auto* chunk_writer = net.writer(net.topic(peer::kChunkTopic, new wire::ChunkPubSubType()),
                                  peer::Profile::stream, partition);
  auto* acks = net.reader(net.topic(peer::kChunkAckTopic, new wire::ChunkAckPubSubType()),
                          peer::Profile::state, partition);
  const auto deadline = deadline_of(o);
  const auto patience =
      std::chrono::duration_cast<std::chrono::milliseconds>(deadline - clock_type::now());
  if (!peer::wait_matched(announcements, patience) || !peer::wait_matched(chunk_writer, patience)) {
    std::cerr << "no dynid-server matched\n";
    return 1;
  }
  wire::RunAnnouncement announcement = run;
  announcements->write(&announcement);

  wire::ChunkAck latest;
  latest.highest_contiguous(-1);
  const auto last = static_cast<std::int64_t>(chunks.size()) - 1;
  while (clock_type::now() < deadline && latest.highest_contiguous() < last) {
    // The server acknowledges what it stored; what it has not (a chunk that overtook the
    // announcement, or one lost before matching) is sent again, as dynid-car's spool does.
    for (auto k = static_cast<std::size_t>(latest.highest_contiguous() + 1); k < chunks.size(); ++k)
      chunk_writer->write(&chunks[k]);
    const auto wait_until = std::min(deadline, clock_type::now() + 2s);
    while (clock_type::now() < wait_until && latest.highest_contiguous() < last) {
      acks->wait_for_unread_message(eprosima::fastrtps::Duration_t(0, 100'000'000));
      take_acks(acks, run.run().to_string(), latest);
    }
  }
  std::cout << ack_json(latest).dump() << std::endl;
  return latest.highest_contiguous() == last ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGTERM, [](int) { stop_requested = 1; });
  try {
    const Options o = parse(argc, argv);
    peer::PeerNetwork net(o.profile, o.domain);
    if (o.command == "estimates") return estimates(net, o);
    if (o.command == "request") return request(net, o);
    if (o.command == "car") return car(net, o);
    std::cerr << "fastdds_peer: unknown command " << o.command << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "fastdds_peer: " << e.what() << "\n";
    return 2;
  }
}
