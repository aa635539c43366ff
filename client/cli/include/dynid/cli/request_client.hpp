#pragma once
// RequestClient: the engineer's side of the Request/Reply pair (DESIGN.md, "DDS interface").
//
// Contract:
// - call() numbers the request (correlation id), waits until a server's Request reader and
//   Reply writer are matched, writes the request, and returns the reply carrying the same
//   (client, correlation id); replies to others are ignored. It resends the same request
//   every `resend` while no reply came (a reply written before the server had discovered our
//   reader is lost; the server answers a repeat from its reply cache, it does not run the
//   request twice).
// - call_all() is for the requests every server answers (vehicles, status): it collects one
//   reply per shard (ShardReplies: the shard count comes with the replies), resending while
//   a shard is missing, and returns when all answered or at `timeout` with those that did.
//   A request naming a vehicle is answered by its shard's server alone: call() takes the
//   first reply.
// - Every wait is bounded by `timeout`: NoServer is thrown, with a message saying what was
//   waited for and what to check, when no server matched or none answered in time.
// - After stop_on_signals(), SIGINT and SIGTERM end a wait within a second with Interrupted,
//   so that the program exits through its destructors: the participant is deleted and the
//   server sees at once that the client has gone (it stops computing the request) instead of
//   after the participant's lease.
// - The Participant must outlive the client.
#include <chrono>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynid.h"
#include "dynid/cli/shard_replies.hpp"
#include "dynid/dds/participant.hpp"
#include "dynid/dds/reader.hpp"
#include "dynid/dds/request.hpp"
#include "dynid/dds/writer.hpp"

namespace dynid::cli {

class NoServer : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Installs the SIGINT and SIGTERM handlers that make waits throw Interrupted.
void stop_on_signals();

/// "<user>@<host>/<pid>", cut to the wire's id length.
std::string default_client_id();

class RequestClient {
 public:
  RequestClient(const dds::Participant& participant, std::string client_id);

  dds::Reply call(const std::string& kind, const std::vector<dds::RequestArgument>& arguments,
                  std::chrono::milliseconds timeout,
                  std::chrono::milliseconds resend = std::chrono::milliseconds(1000));

  /// The replies of every shard that answered within `timeout` (at least one, else NoServer);
  /// ShardMismatch when servers disagree on the shard count.
  ShardReplies call_all(const std::string& kind, const std::vector<dds::RequestArgument>& arguments,
                        std::chrono::milliseconds timeout,
                        std::chrono::milliseconds resend = std::chrono::milliseconds(1000));

  const std::string& client_id() const { return client_id_; }

 private:
  /// Sends the request (again every `resend`) and hands each reply to it to `take` until
  /// `take` returns true (true) or `timeout` passes (false). NoServer when none matched.
  bool exchange(const std::string& kind, const std::vector<dds::RequestArgument>& arguments,
                std::chrono::milliseconds timeout, std::chrono::milliseconds resend,
                const std::function<bool(const dds::Reply&)>& take);

  std::string client_id_;
  std::uint64_t next_correlation_ = 1;
  dds::Reader<dynid_wire_Reply> replies_;  // before the writer: ready when the request leaves
  dds::Writer<dynid_wire_Request> requests_;
};

}  // namespace dynid::cli
