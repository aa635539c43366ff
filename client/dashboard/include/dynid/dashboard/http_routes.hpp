#pragma once
// The dashboard's HTTP side (cpp-httplib): the page, its JSON and its live stream, only to who
// holds the token.
//
// Routes:
//   GET /login?token=T[&view=#/...]   with the right token: sets the HttpOnly, SameSite=Strict
//                        cookie `dynid_token` and redirects to / (and that view); else 401
//   GET /                the page (fleet and model views; no resource from the internet)
//   GET /api/fleet       FleetState::fleet_json
//   GET /api/history?vehicle=V&run=R&model=M   FleetState::history_json (404 when unknown)
//   GET /api/run?vehicle=V&run=R   the server's `estimate` reply for that run, JSON (channel
//                        health, notes, every model's table), asked through `ask_run`
//   GET /events          server-sent events: `estimate` with {vehicle, run, model, revision,
//                        sequence} per publication; a comment every 15 s keeps it open
// Every route but /login answers 401 with no data without the token, given as the cookie or
// as `Authorization: Bearer T`. Tokens are compared in constant time.
#include <functional>
#include <string>

#include "dynid/dashboard/fleet_state.hpp"

namespace httplib {
class Server;
}

namespace dynid::dashboard {

/// What /api/run answers: {status (HTTP), body}.
struct RunReply {
  int status = 200;
  std::string body;
};
using AskRun = std::function<RunReply(const std::string& vehicle, const std::string& run)>;

/// Installs the routes on `server`. `state`, `ask_run` and `page` must outlive it.
void install_routes(httplib::Server& server, const FleetState& state, const std::string& token,
                    const std::string& page, AskRun ask_run);

/// Equal, in a time that depends on the lengths only.
bool same_token(const std::string& given, const std::string& token);

}  // namespace dynid::dashboard
