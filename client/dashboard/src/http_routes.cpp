#include "dynid/dashboard/http_routes.hpp"

#include <httplib.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <memory>

namespace dynid::dashboard {
namespace {

constexpr const char* kCookie = "dynid_token";

std::string cookie_value(const httplib::Request& req, const std::string& name) {
  const std::string cookies = req.get_header_value("Cookie");
  std::size_t at = 0;
  while (at < cookies.size()) {
    std::size_t end = cookies.find(';', at);
    if (end == std::string::npos) end = cookies.size();
    std::string item = cookies.substr(at, end - at);
    item.erase(0, item.find_first_not_of(' '));
    if (item.rfind(name + "=", 0) == 0) return item.substr(name.size() + 1);
    at = end + 1;
  }
  return {};
}

bool authorised(const httplib::Request& req, const std::string& token) {
  const std::string header = req.get_header_value("Authorization");
  if (header.rfind("Bearer ", 0) == 0 && same_token(header.substr(7), token)) return true;
  return same_token(cookie_value(req, kCookie), token);
}

void json_reply(httplib::Response& res, const std::string& body) {
  res.set_header("Cache-Control", "no-store");
  res.set_content(body, "application/json");
}

std::string event_text(const EstimateEvent& e) {
  const nlohmann::json data = {{"vehicle", e.vehicle},
                               {"run", e.run},
                               {"model", e.model},
                               {"revision", e.revision},
                               {"sequence", e.sequence}};
  return "id: " + std::to_string(e.sequence) + "\nevent: estimate\ndata: " + data.dump() + "\n\n";
}

// The stream of one browser: every publication after the one it last saw (Last-Event-ID after a
// reconnection), until the browser goes (a failed write) or the server stops.
void stream_events(const FleetState& state, const httplib::Request& req, httplib::Response& res) {
  std::uint64_t after = state.sequence();
  if (const std::string last = req.get_header_value("Last-Event-ID"); !last.empty()) {
    try {
      // A number past the newest is of a dashboard that restarted since: from now on.
      after = std::min<std::uint64_t>(after, std::stoull(last));
    } catch (const std::exception&) {  // not a number: from now on
    }
  }
  struct Stream {
    std::uint64_t seen = 0;
    int quiet_seconds = 0;
  };
  auto stream = std::make_shared<Stream>(Stream{after, 0});
  res.set_header("Cache-Control", "no-store");
  res.set_chunked_content_provider(
      "text/event-stream", [&state, stream](std::size_t, httplib::DataSink& sink) {
        if (state.closed()) return false;
        std::string text;
        // Waits of a second: a stopping dashboard ends its streams within one.
        for (const EstimateEvent& e : state.wait_events(stream->seen, std::chrono::seconds(1)))
          text += event_text(e), stream->seen = e.sequence;
        if (!text.empty()) {
          stream->quiet_seconds = 0;
        } else if (++stream->quiet_seconds >= 15) {
          stream->quiet_seconds = 0;
          text = ": waiting\n\n";  // keeps proxies and the browser from timing the stream out
        }
        return text.empty() || sink.write(text.data(), text.size());
      });
}

}  // namespace

bool same_token(const std::string& given, const std::string& token) {
  if (given.size() != token.size() || token.empty()) return false;
  unsigned char diff = 0;
  for (std::size_t k = 0; k < token.size(); ++k)
    diff |= static_cast<unsigned char>(given[k] ^ token[k]);
  return diff == 0;
}

void install_routes(httplib::Server& server, const FleetState& state, const std::string& token,
                    const std::string& page, AskRun ask_run) {
  server.set_pre_routing_handler([token](const httplib::Request& req, httplib::Response& res) {
    if (req.path == "/login" || authorised(req, token))
      return httplib::Server::HandlerResponse::Unhandled;
    res.status = 401;
    res.set_header("WWW-Authenticate", "Bearer realm=\"dynid-dashboard\"");
    res.set_content(
        "401: this dashboard needs its token (open /login?token=... once, or send "
        "Authorization: Bearer ...)\n",
        "text/plain");
    return httplib::Server::HandlerResponse::Handled;
  });
  server.Get("/login", [token](const httplib::Request& req, httplib::Response& res) {
    if (!same_token(req.get_param_value("token"), token)) {
      res.status = 401;
      res.set_content("401: wrong or missing token\n", "text/plain");
      return;
    }
    res.set_header("Set-Cookie",
                   std::string(kCookie) + "=" + token + "; HttpOnly; SameSite=Strict; Path=/");
    // `view`: a view of the page to open (#/...); nothing else, so the login redirects nowhere
    // but this dashboard.
    const std::string view = req.get_param_value("view");
    res.set_redirect(view.rfind("#/", 0) == 0 ? "/" + view : "/", 303);
  });
  server.Get("/", [&page](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(page, "text/html; charset=utf-8");
  });
  server.Get("/api/fleet", [&state](const httplib::Request&, httplib::Response& res) {
    json_reply(res, state.fleet_json());
  });
  server.Get("/api/history", [&state](const httplib::Request& req, httplib::Response& res) {
    const std::string body = state.history_json(
        req.get_param_value("vehicle"), req.get_param_value("run"), req.get_param_value("model"));
    if (body.empty()) {
      res.status = 404;
      json_reply(res,
                 R"({"error":"no estimate of that vehicle, run and model was published yet"})");
      return;
    }
    json_reply(res, body);
  });
  server.Get("/api/run", [ask_run](const httplib::Request& req, httplib::Response& res) {
    const RunReply reply = ask_run(req.get_param_value("vehicle"), req.get_param_value("run"));
    res.status = reply.status;
    json_reply(res, reply.body);
  });
  server.Get("/events", [&state](const httplib::Request& req, httplib::Response& res) {
    stream_events(state, req, res);
  });
}

}  // namespace dynid::dashboard
