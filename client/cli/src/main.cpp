// dynid: the engineers' command line. Every command but `watch` is one request to dynid-server
// (RequestClient); `watch` reads the transient-local Estimate topic of a vehicle, so it shows
// the latest estimates at once and every update after, for --seconds.
//
// Several servers (dynid-server --shard K/N, docs/DESIGN.md "Scale-out"): a command naming a
// vehicle is answered by the server of the vehicle's shard; `vehicles` and `status` ask every
// server, wait until all N shards answered (N comes with the replies) or --timeout, and merge:
// what the missing shards hold is left out, said on stderr, and the exit code is 6.
//
// Exit codes: 0 ok, 2 bad request (or bad command line: a number outside its limits, a vehicle
// id or run name that breaks the id rule of dynid/input/ids.hpp), 3 not found, 4 the server failed
// (or the servers disagree on the shard count), 5 no server answered in time, 6 some shards did not
// answer (the output holds the others'), 7 no DDS participant index was free on this host (other
// DDS programs hold them all: retried for 20 s first).
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include <dynid/options/option_checks.hpp>

#include "dynid/cli/catalogue_view.hpp"
#include "dynid/cli/export_file.hpp"
#include "dynid/cli/request_client.hpp"
#include "dynid/cli/shard_replies.hpp"
#include "dynid/cli/watch_view.hpp"
#include "dynid/dds/conversions.hpp"
#include "dynid/dds/participant.hpp"
#include "dynid/dds/protocol.hpp"
#include "dynid/dds/topics.hpp"
#include "dynid/report/estimate_report.hpp"

namespace {

using namespace std::chrono_literals;
using dynid::dds::RequestArgument;

// Limits of --timeout and --seconds: beyond a day a duration is a typing error (and past ~9e15
// it overflows the count of milliseconds).
constexpr double kMinSeconds = 1e-3;
constexpr double kMaxSeconds = 86400.0;

struct Common {
  std::string config;
  dds_domainid_t domain = 0;
  double timeout_s = 10.0;
  bool json = false;
};

// A request is cheap to repeat, and a storm of them (a script starting many at once) may hold
// every participant index of the host for a moment: the creation is retried for up to 20 s
// (participant.hpp), before the CLI gives up with exit 7. Long enough for a few rounds of
// ordinary requests ahead of it to end, short against a request's own timeout.
constexpr std::chrono::seconds kParticipantWait{20};

dynid::dds::ParticipantOptions participant_options(const Common& c) {
  dynid::dds::ParticipantOptions o{c.domain, dynid::dds::config_uri(c.config)};
  o.index_wait = kParticipantWait;
  return o;
}

int exit_code(dynid::dds::ReplyStatus status) {
  switch (status) {
    case dynid::dds::ReplyStatus::kOk: return 0;
    case dynid::dds::ReplyStatus::kBadRequest: return 2;
    case dynid::dds::ReplyStatus::kNotFound: return 3;
    case dynid::dds::ReplyStatus::kFailed: return 4;
  }
  return 4;
}

std::chrono::milliseconds timeout_of(const Common& c) {
  return std::chrono::milliseconds(static_cast<long long>(c.timeout_s * 1000));
}

int print(const std::string& kind, const dynid::dds::Reply& reply) {
  if (reply.status != dynid::dds::ReplyStatus::kOk) {
    std::cerr << "dynid " << kind << ": " << reply.error << "\n";
    return exit_code(reply.status);
  }
  std::cout << reply.payload;
  if (!reply.payload.empty() && reply.payload.back() != '\n') std::cout << "\n";
  return 0;
}

// A request every server answers (vehicles, status): one reply per shard, merged.
int request_all(const Common& c, dynid::cli::RequestClient& client, const std::string& kind) {
  // The vehicle lists are merged from JSON whatever the output format.
  const std::vector<RequestArgument> arguments{{"format", "json"}};
  const auto replies = client.call_all(kind, arguments, timeout_of(c));
  if (const auto failure = replies.failure()) return print(kind, *failure);
  if (kind == "status")
    std::cout << (c.json ? dynid::cli::merged_status(replies) + "\n" : dynid::cli::status_text(replies));
  else if (const auto vehicles = dynid::cli::merged_vehicles(replies); vehicles.empty() && !c.json)
    std::cout << (replies.complete() ? "no vehicles yet: a car's first run announces its vehicle\n"
                                     : "no vehicles on the servers that answered\n");
  else
    std::cout << dynid::cli::render_vehicles(vehicles, c.json) << (c.json ? "\n" : "");
  const std::string note =
      dynid::cli::missing_note(replies, timeout_of(c).count(), kind == "status" ? "counters" : "vehicles");
  if (note.empty()) return 0;
  std::cerr << "dynid " << kind << ": " << note << "\n";
  return 6;
}

// The requests follow the protocol's table (dynid/dds/protocol.hpp), the one the server checks
// them against: a kind or an argument it does not list is this program's bug, said so before
// anything is sent.
void check_against_protocol(const std::string& kind,
                            const std::vector<RequestArgument>& arguments) {
  const auto* spec = dynid::dds::protocol::find_request_kind(kind);
  if (spec == nullptr)
    throw std::logic_error("internal error: request kind '" + kind + "' is not in the protocol");
  for (const auto& argument : arguments)
    if (!spec->takes(argument.name))
      throw std::logic_error("internal error: '" + kind + "' takes no argument '" + argument.name +
                             "'");
}

int request(const Common& c, const std::string& kind, std::vector<RequestArgument> arguments) {
  check_against_protocol(kind, arguments);
  dynid::dds::Participant participant(participant_options(c));
  dynid::cli::RequestClient client(participant, dynid::cli::default_client_id());
  if (kind == "vehicles" || kind == "status") return request_all(c, client, kind);
  if (c.json) arguments.push_back({"format", "json"});
  return print(kind, client.call(kind, arguments, timeout_of(c)));
}

// A residual report: printed, or with --html written to that file (the page is self-contained).
int report_request(const Common& c, const std::string& kind, const std::vector<RequestArgument>& arguments,
                   const std::string& html_file) {
  if (html_file.empty()) return request(c, kind, arguments);
  check_against_protocol(kind, arguments);
  dynid::dds::Participant participant(participant_options(c));
  dynid::cli::RequestClient client(participant, dynid::cli::default_client_id());
  const dynid::dds::Reply reply = client.call(kind, arguments, timeout_of(c));
  if (reply.status != dynid::dds::ReplyStatus::kOk) return print(kind, reply);
  std::ofstream out(html_file, std::ios::binary);
  out << reply.payload;
  if (!out.flush()) {
    std::cerr << "dynid " << kind << ": cannot write " << html_file << "\n";
    return 2;
  }
  std::cout << "report written to " << html_file << " (" << reply.payload.size() << " bytes)\n";
  return 0;
}

dynid::can::Mdf4File mdf4_of(const std::string& bytes, const std::string& what) {
  return dynid::can::Mdf4File(std::vector<std::uint8_t>(bytes.begin(), bytes.end()), what);
}

// An export (server/export_request.hpp): the server's MDF4 file, its parts asked for and joined
// when it is past a reply's limit, read back with the product's reader (a file that does not read
// is not written), then written as it came or as one CSV table.
int export_request(const Common& c, std::vector<RequestArgument> arguments,
                   const std::string& format, const std::string& output) {
  arguments.push_back({"part", "1"});
  check_against_protocol("export", arguments);
  dynid::dds::Participant participant(participant_options(c));
  dynid::cli::RequestClient client(participant, dynid::cli::default_client_id());
  dynid::dds::Reply reply = client.call("export", arguments, timeout_of(c));
  if (reply.status != dynid::dds::ReplyStatus::kOk) return print("export", reply);
  std::string mdf4 = std::move(reply.payload);
  if (const std::size_t parts = dynid::cli::part_count(reply.payload_format); parts > 1) {
    std::vector<dynid::can::Mdf4File> files{mdf4_of(mdf4, "the server's export, part 1")};
    for (std::size_t k = 2; k <= parts; ++k) {
      arguments.back().value = std::to_string(k);
      reply = client.call("export", arguments, timeout_of(c));
      if (reply.status != dynid::dds::ReplyStatus::kOk) return print("export", reply);
      files.push_back(mdf4_of(reply.payload, "the server's export, part " + std::to_string(k)));
    }
    mdf4 = dynid::cli::joined_export(files);
  }
  const dynid::can::Mdf4File file = mdf4_of(mdf4, "the server's export");
  const std::string bytes = format == "csv" ? dynid::cli::export_csv(file) : mdf4;
  std::ofstream out(output, std::ios::binary);
  out << bytes;
  if (!out.flush()) {
    std::cerr << "dynid export: cannot write " << output << "\n";
    return 2;
  }
  std::cout << "export written to " << output << " (" << bytes.size() << " bytes, "
            << (format == "csv" ? "CSV" : "MDF " + file.version()) << ")\n"
            << dynid::cli::export_summary(file);
  return 0;
}

// Without --model: every model's full table (or its JSON) at each publication. With --model:
// that model only, compact (WatchView): redrawn in place on a terminal, appended blocks on a
// pipe or file, JSON lines with --json.
int watch(const Common& c, const std::string& vehicle, const std::string& model, double seconds) {
  dynid::dds::Participant participant(participant_options(c));
  dynid::dds::Reader<dynid_wire_Estimate> reader(participant, {dynid::dds::vehicle_partition(vehicle)});
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<long long>(seconds * 1000));
  const bool terminal = isatty(STDOUT_FILENO) == 1;
  dynid::cli::WatchView view;
  std::size_t shown = 0;
  while (std::chrono::steady_clock::now() < end) {
    for (auto& sample : reader.wait_take(200ms)) {
      const auto table = dynid::dds::from_wire(sample.data);
      if (model.empty()) {
        std::cout << (c.json ? dynid::report::estimate_json(table) + "\n"
                             : dynid::report::format_estimate_text(table) + "\n");
      } else if (table.model != model) {
        continue;
      } else if (c.json) {
        std::cout << view.json_line(table);
      } else {
        std::cout << (terminal ? view.redraw(table) : view.text(table) + "\n");
      }
      std::cout << std::flush;
      ++shown;
    }
  }
  if (shown == 0)
    std::cerr << "dynid watch: no estimate of " << vehicle << (model.empty() ? "" : " model " + model) << " in "
              << seconds << " s\n";
  return shown ? 0 : 5;
}

// Vehicle ids and run names follow the id rule (dynid/input/ids.hpp) before anything is sent.
void check_ids(std::initializer_list<std::pair<const char*, std::string>> single, const std::vector<std::string>& runs,
               const std::string& vehicle_list) {
  const auto check = [](const std::string& option, const std::string& value) {
    const bool vehicle = option.find("vehicle") != std::string::npos;
    try {
      vehicle ? dynid::input::check_vehicle_id(value) : dynid::input::check_run_name(value);
    } catch (const dynid::InputError& e) {
      throw dynid::InputError(option + ": " + e.what());
    }
  };
  for (const auto& [option, value] : single)
    if (!value.empty()) check(option, value);
  for (const auto& r : runs) check("--run", r);
  std::istringstream list(vehicle_list);
  for (std::string item; std::getline(list, item, ',');)
    if (!item.empty()) check("--vehicles", item);
}

// The options most subcommands share, with one help text each.
CLI::Option* vehicle_option(CLI::App* command, std::string& vehicle) {
  return command
      ->add_option("--vehicle", vehicle,
                   "the vehicle id (its profile's [vehicle] id; `dynid vehicles` lists them)")
      ->required();
}

CLI::Option* run_option(CLI::App* command, std::string& run, bool required) {
  auto* option = command->add_option(
      "--run", run,
      required ? "the run name (`dynid runs --vehicle V` lists them)"
               : "the run name (`dynid runs --vehicle V` lists them; default: the latest run)");
  return required ? option->required() : option;
}

CLI::Option* model_option(CLI::App* command, std::string& model, bool required) {
  auto* option = command->add_option(
      "--model", model,
      required ? "a model of the run (`dynid models` lists the models and what each needs)"
               : "only this model of the run (default: every model; `dynid models` lists them)");
  return required ? option->required() : option;
}

std::vector<RequestArgument> args(std::initializer_list<std::pair<const char*, std::string>> list) {
  std::vector<RequestArgument> out;
  for (const auto& [name, value] : list)
    if (!value.empty()) out.push_back({name, value});
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  Common c;
  if (const char* env = std::getenv("DYNID_CYCLONE_CONFIG")) c.config = env;
  CLI::App app{"dynid: vehicles, runs and parameter estimates from dynid-server"};
  app.require_subcommand(1);
  app.fallthrough();  // --json and the connection options may also follow the subcommand
  app.add_option(
      "--cyclone-config", c.config,
      "Cyclone DDS configuration: file, file:// URI or XML (or $DYNID_CYCLONE_CONFIG). When "
      "other DDS programs hold every participant index it allows, joining is retried for up "
      "to 20 s, then exit 7");
  app.add_option("--domain", c.domain, "DDS domain id")->check(dynid::input::within(0, 230));
  auto* timeout = app.add_option("--timeout", c.timeout_s,
                                 "seconds to wait for the server (default 10; 120 for residual, add-effect, trace, consistency, iv)")
                      ->check(dynid::input::within(kMinSeconds, kMaxSeconds));
  app.add_flag("--json", c.json, "JSON instead of text");

  std::string vehicle, run, model, effects;
  std::vector<std::string> runs;
  double seconds = 10.0;
  auto* vehicles_cmd = app.add_subcommand("vehicles", "list the vehicles");
  auto* runs_cmd = app.add_subcommand("runs", "list a vehicle's runs: chunks stored, in order, folded; complete or not");
  vehicle_option(runs_cmd, vehicle);
  auto* estimates_cmd = app.add_subcommand("estimates", "estimate tables (latest run by default)");
  vehicle_option(estimates_cmd, vehicle);
  run_option(estimates_cmd, run, false);
  model_option(estimates_cmd, model, false);
  auto* excitation_cmd = app.add_subcommand(
      "excitation", "what a run (latest by default) identifies, and the manoeuvres that would identify the rest");
  vehicle_option(excitation_cmd, vehicle);
  run_option(excitation_cmd, run, false);
  auto* watch_cmd = app.add_subcommand(
      "watch", "print estimates as they are published (--model: one model, compact, updated in place)");
  vehicle_option(watch_cmd, vehicle);
  watch_cmd->add_option("--model", model,
                        "follow this model: one line per parameter (value, std, status, how it moved); "
                        "JSON lines with --json");
  watch_cmd->add_option("--seconds", seconds, "how long to watch")
      ->check(dynid::input::within(kMinSeconds, kMaxSeconds));
  auto* pooled_cmd = app.add_subcommand("pooled", "estimate over several runs of a vehicle");
  vehicle_option(pooled_cmd, vehicle);
  pooled_cmd->add_option("--run", runs, "runs to pool (repeat)")->required();
  model_option(pooled_cmd, model, false);
  auto* reprocess_cmd = app.add_subcommand("reprocess", "replay a run with another model/effects");
  vehicle_option(reprocess_cmd, vehicle);
  run_option(reprocess_cmd, run, true);
  model_option(reprocess_cmd, model, true);
  reprocess_cmd->add_option("--effects", effects, "comma-separated candidate effects");
  std::string candidates, effect, html;
  std::vector<std::string> references;
  auto* residual_cmd = app.add_subcommand("residual", "which effect does a run's model lack? (docs/RESIDUAL.md)");
  vehicle_option(residual_cmd, vehicle);
  run_option(residual_cmd, run, true);
  model_option(residual_cmd, model, true);
  residual_cmd->add_option("--effects", effects, "the model's declared effects (default: the run's)");
  residual_cmd->add_option("--candidates", candidates, "test only these candidates (comma-separated)");
  residual_cmd->add_option("--html", html, "write the HTML report with plots to this file")
      ->check(dynid::input::output_file("HTML report"));
  auto* add_effect_cmd = app.add_subcommand("add-effect", "a run's model with one more effect: before and after");
  vehicle_option(add_effect_cmd, vehicle);
  run_option(add_effect_cmd, run, true);
  model_option(add_effect_cmd, model, true);
  add_effect_cmd->add_option("--effect", effect, "the effect to add, e.g. road_grade")->required();
  add_effect_cmd->add_option("--effects", effects, "the model's declared effects (default: the run's)");
  add_effect_cmd->add_option("--html", html, "write the HTML report with plots to this file")
      ->check(dynid::input::output_file("HTML report"));
  add_effect_cmd->add_option("--reference", references, "a known value, name=value (repeat), e.g. mass=1457.5");
  bool series = false;
  const char* series_help =
      "with --json: the added effect's fitted contribution row by row (effect_series)";
  add_effect_cmd->add_flag("--series", series, series_help);
  int rounds = -1;  // unset: the server's default
  auto* trace_cmd = app.add_subcommand(
      "trace", "the residual loop: diagnose, add the effect that explains the residual, again (docs/RESIDUAL.md)");
  vehicle_option(trace_cmd, vehicle);
  run_option(trace_cmd, run, true);
  model_option(trace_cmd, model, true);
  trace_cmd->add_option("--effects", effects, "the model's declared effects (default: the run's; none: no effect)");
  trace_cmd->add_option("--reference", references, "a known value, name=value (repeat), e.g. mass=1457.5");
  trace_cmd->add_option("--rounds", rounds, "effects the loop may add (0 to 10, default 4)")
      ->check(dynid::input::within(0, 10));
  trace_cmd->add_flag("--series", series, series_help);
  trace_cmd->add_option("--html", html, "write the HTML report with plots to this file")
      ->check(dynid::input::output_file("HTML report"));
  auto* consistency_cmd = app.add_subcommand(
      "consistency", "do a run's models agree with each other and with known values? (docs/RESIDUAL.md)");
  vehicle_option(consistency_cmd, vehicle);
  run_option(consistency_cmd, run, true);
  consistency_cmd->add_option("--reference", references, "a known value, name=value (repeat), e.g. mass=1457.5");
  // Another estimator of one model on one stored run, beside least squares.
  const auto estimator_command = [&](const char* name, const char* description) {
    auto* command = app.add_subcommand(name, description);
    vehicle_option(command, vehicle);
    run_option(command, run, true);
    model_option(command, model, true);
    command->add_option("--effects", effects, "the model's declared effects (default: the run's; none: no effect)");
    return command;
  };
  auto* iv_cmd = estimator_command(
      "iv", "is least squares biased by noisy regressors? the instrumental-variable estimate and the "
            "Durbin-Wu-Hausman test (docs/ACCURACY.md)");
  auto* simex_cmd = estimator_command(
      "simex", "least squares corrected for the measured sensor noise (SIMEX), beside least squares, and "
               "which one the server publishes (docs/ACCURACY.md)");
  std::string export_format = "mdf4", output;
  auto* export_cmd = app.add_subcommand(
      "export",
      "a run's channels, and each model's measured side, fitted values and residual on its "
      "rows, as an MDF4 file (asammdf, MATLAB, CANape) or one CSV table");
  vehicle_option(export_cmd, vehicle);
  run_option(export_cmd, run, true);
  model_option(export_cmd, model, false);
  export_cmd->add_option(
      "--effects", effects,
      "with --model: the model's declared effects (default: the run's; none: no effect)");
  export_cmd->add_option("--format", export_format, "mdf4 (default) or csv")
      ->check(CLI::IsMember({"mdf4", "csv"}));
  export_cmd->add_option("--output", output, "the file to write")
      ->required()
      ->check(dynid::input::output_file("export"));
  auto* base_cmd = app.add_subcommand("base", "base-parameter report of a run's model");
  vehicle_option(base_cmd, vehicle);
  run_option(base_cmd, run, true);
  model_option(base_cmd, model, true);
  auto* close_cmd = app.add_subcommand("close", "close a run (final estimates)");
  vehicle_option(close_cmd, vehicle);
  run_option(close_cmd, run, true);
  auto* status_cmd = app.add_subcommand(
      "status", "the server's counters, one per line with what it counts; with servers sharing one "
                "PostgreSQL store, which server holds which vehicles (--json: raw)");
  std::vector<std::string> shared;
  std::string fleet_vehicles;
  auto* fleet_cmd = app.add_subcommand(
      "fleet", "one estimate over several vehicles: shared parameters common to all, the others per vehicle");
  fleet_cmd->add_option("model", model, "the model, e.g. longitudinal_wheel")->required();
  fleet_cmd->add_option("shared", shared, "parameters shared by the fleet")->required();
  fleet_cmd->add_option("--vehicles", fleet_vehicles,
                     "comma-separated vehicles (closed runs, else the latest), all of one shard")
      ->required();
  bool markdown = false;
  auto* models_cmd = app.add_subcommand(
      "models",
      "the models, with the channels and constants each needs and what it identifies "
      "(answered here, no server)");
  models_cmd->add_option("--model", model, "only this model");
  models_cmd->add_flag("--markdown", markdown,
                       "one table of every model, as docs/PROFILES.md has it");
  auto* effects_cmd = app.add_subcommand(
      "effects",
      "a model's candidate effects: the physics, the channels each adds, its parameters "
      "(answered here, no server)");
  effects_cmd->add_option("--model", model, "the model (`dynid models` lists them)")->required();
  try {
    app.parse(argc, argv);
    check_ids({{"--vehicle", vehicle}, {"--run", run}}, runs, fleet_vehicles);
  } catch (const CLI::Success& e) {  // --help
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  } catch (const dynid::InputError& e) {
    std::cerr << "dynid: " << e.what() << "\n";
    return 2;
  }
  try {
    if (*models_cmd) {
      std::cout << (markdown ? dynid::cli::models_markdown() : dynid::cli::models_text(model));
      return 0;
    }
    if (*effects_cmd) {
      std::cout << dynid::cli::effects_text(model);
      return 0;
    }
  } catch (const dynid::InputError& e) {
    std::cerr << "dynid: " << e.what() << "\n";
    return 2;
  }
  if (c.config.empty()) {
    std::cerr << "dynid: --cyclone-config (or DYNID_CYCLONE_CONFIG) is required, e.g. "
                 "deploy/cyclonedds/loopback.xml\n";
    return 2;
  }
  dynid::cli::stop_on_signals();  // Ctrl-C: exit through the destructors (request_client.hpp)
  try {
    if (*vehicles_cmd) return request(c, "vehicles", {});
    if (*runs_cmd) return request(c, "runs", args({{"vehicle", vehicle}}));
    if (*estimates_cmd)
      return request(c, "estimate", args({{"vehicle", vehicle}, {"run", run}, {"model", model}}));
    if (*excitation_cmd) return request(c, "excitation", args({{"vehicle", vehicle}, {"run", run}}));
    if (*watch_cmd) return watch(c, vehicle, model, seconds);
    if (*pooled_cmd) {
      auto a = args({{"vehicle", vehicle}, {"model", model}});
      for (const auto& r : runs) a.push_back({"run", r});
      return request(c, "pooled", a);
    }
    if (*reprocess_cmd)
      return request(c, "reprocess", args({{"vehicle", vehicle}, {"run", run}, {"model", model}, {"effects", effects}}));
    if (*residual_cmd || *add_effect_cmd || *trace_cmd) {
      // The server replays the run and fits it many times (the noise floor's draws, every
      // candidate, every round): longer than a table look-up on a long run.
      if (timeout->count() == 0) c.timeout_s = 120.0;
      auto a = args({{"vehicle", vehicle},
                     {"run", run},
                     {"model", model},
                     {"effects", effects},
                     {"candidates", candidates},
                     {"effect", effect},
                     {"rounds", rounds < 0 ? "" : std::to_string(rounds)},
                     {"format", html.empty() ? "" : "html"},
                     {"series", series ? "yes" : ""}});
      for (const auto& r : references) a.push_back({"reference", r});
      return report_request(c, *residual_cmd ? "residual" : (*add_effect_cmd ? "add-effect" : "trace"), a, html);
    }
    if (*consistency_cmd) {
      if (timeout->count() == 0) c.timeout_s = 120.0;  // every model of the run fitted
      auto a = args({{"vehicle", vehicle}, {"run", run}});
      for (const auto& r : references) a.push_back({"reference", r});
      return request(c, "consistency", a);
    }
    if (*iv_cmd) {
      if (timeout->count() == 0) c.timeout_s = 120.0;  // the run replayed and assembled
      return request(c, "iv", args({{"vehicle", vehicle}, {"run", run}, {"model", model}, {"effects", effects}}));
    }
    if (*simex_cmd) {
      if (timeout->count() == 0) c.timeout_s = 120.0;  // the run replayed, refitted 2 x lambdas x draws times
      return request(c, "simex", args({{"vehicle", vehicle}, {"run", run}, {"model", model}, {"effects", effects}}));
    }
    if (*export_cmd) {
      if (c.json) throw dynid::InputError("export: --json: the export is a file, its summary text");
      if (!effects.empty() && model.empty())
        throw dynid::InputError("export: --effects needs --model");
      if (timeout->count() == 0) c.timeout_s = 120.0;  // the run replayed, every model fitted
      return export_request(
          c, args({{"vehicle", vehicle}, {"run", run}, {"model", model}, {"effects", effects}}),
          export_format, output);
    }
    if (*base_cmd) return request(c, "base", args({{"vehicle", vehicle}, {"run", run}, {"model", model}}));
    if (*close_cmd) return request(c, "close", args({{"vehicle", vehicle}, {"run", run}}));
    if (*status_cmd) return request(c, "status", {});
    if (*fleet_cmd) {
      auto a = args({{"model", model}, {"vehicles", fleet_vehicles}});
      for (const auto& s : shared) a.push_back({"shared", s});
      return request(c, "fleet", a);
    }
  } catch (const dynid::cli::NoServer& e) {
    std::cerr << "dynid: " << e.what() << "\n";
    return 5;
  } catch (const dynid::cli::Interrupted& e) {  // the participant is deleted on the way out
    std::cerr << "dynid: " << e.what() << "\n";
    return 130;
  } catch (const dynid::cli::ShardMismatch& e) {
    std::cerr << "dynid: " << e.what() << "\n";
    return 4;
  } catch (const dynid::dds::NoParticipantIndex& e) {
    std::cerr << "dynid: " << e.what() << "\n";
    return 7;
  } catch (const std::exception& e) {
    std::cerr << "dynid: " << e.what() << "\n";
    return 2;
  }
  return 2;
}
