#include "dynid/cli/request_client.hpp"

#include <unistd.h>

#include <csignal>
#include <cstdlib>

#include "dynid/dds/conversions.hpp"

namespace dynid::cli {
namespace {

volatile std::sig_atomic_t stop_signal = 0;

extern "C" void on_stop_signal(int signal) {
  stop_signal = signal;
}

void throw_if_interrupted() {
  if (stop_signal != 0) throw Interrupted("interrupted by signal " + std::to_string(stop_signal));
}

}  // namespace

void stop_on_signals() {
  struct sigaction action = {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

std::string default_client_id() {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  const char* user = std::getenv("USER");
  std::string id = std::string(user ? user : "engineer") + "@" + host + "/" + std::to_string(getpid());
  return id.substr(0, 64);
}

RequestClient::RequestClient(const dds::Participant& participant, std::string client_id)
    : client_id_(std::move(client_id)), replies_(participant, {}), requests_(participant, {}) {}

bool RequestClient::exchange(const std::string& kind, const std::vector<dds::RequestArgument>& arguments,
                             std::chrono::milliseconds timeout, std::chrono::milliseconds resend,
                             const std::function<bool(const dds::Reply&)>& take) {
  using clock = std::chrono::steady_clock;
  const auto deadline = clock::now() + timeout;
  const auto left = [&] {
    return std::max(std::chrono::milliseconds(0),
                    std::chrono::duration_cast<std::chrono::milliseconds>(deadline - clock::now()));
  };
  // In slices of at most 250 ms, so that a stop signal ends the wait within one (as below).
  const auto matched = [&](const auto& wait_slice) {
    for (;;) {
      if (wait_slice(std::min(left(), std::chrono::milliseconds(250)))) return true;
      throw_if_interrupted();
      if (left().count() == 0) return false;
    }
  };
  if (!matched([&](std::chrono::milliseconds s) { return requests_.wait_for_readers(1, s); }) ||
      !matched([&](std::chrono::milliseconds s) { return replies_.wait_for_writers(1, s); }))
    throw NoServer("no dynid-server found within " + std::to_string(timeout.count()) +
                   " ms (is one running on this DDS domain with the same Cyclone configuration?)");
  const dds::Request request{client_id_, next_correlation_++, kind, arguments};
  const auto sample = dds::to_wire(request);
  while (clock::now() < deadline) {
    requests_.write(sample.data);
    const auto resend_at = std::min(deadline, clock::now() + resend);
    while (clock::now() < resend_at) {
      const auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(resend_at - clock::now());
      for (auto& received : replies_.wait_take(std::min(wait, std::chrono::milliseconds(250)))) {
        const dds::Reply reply = dds::from_wire(received.data);
        if (reply.client == client_id_ && reply.correlation_id == request.correlation_id && take(reply))
          return true;
      }
      throw_if_interrupted();
    }
  }
  return false;
}

dds::Reply RequestClient::call(const std::string& kind,
                               const std::vector<dds::RequestArgument>& arguments,
                               std::chrono::milliseconds timeout,
                               std::chrono::milliseconds resend) {
  dds::Reply first;
  if (exchange(kind, arguments, timeout, resend, [&](const dds::Reply& reply) {
        first = reply;
        return true;
      }))
    return first;
  std::string vehicle;
  for (const auto& a : arguments)
    if (a.name == "vehicle") vehicle = a.value;
  throw NoServer(
      vehicle.empty()
          ? "dynid-server did not answer '" + kind + "' within " + std::to_string(timeout.count()) +
                " ms"
          : "no dynid-server answered '" + kind + "' for vehicle " + vehicle + " within " +
                std::to_string(timeout.count()) +
                " ms. A server is running on this DDS domain (its request reader is matched), "
                "so the vehicle's server is still computing (raise --timeout; it stops computing "
                "this request once this program exits) or the server of the vehicle's shard is "
                "not running (dynid status lists the servers)");
}

ShardReplies RequestClient::call_all(const std::string& kind,
                                     const std::vector<dds::RequestArgument>& arguments,
                                     std::chrono::milliseconds timeout,
                                     std::chrono::milliseconds resend) {
  ShardReplies replies;
  exchange(kind, arguments, timeout, resend, [&](const dds::Reply& reply) {
    replies.add(reply);
    return replies.complete();
  });
  if (replies.empty())
    throw NoServer("dynid-server did not answer '" + kind + "' within " + std::to_string(timeout.count()) + " ms");
  return replies;
}

}  // namespace dynid::cli
