// dynid-server against hostile input (label hostile, e2e): numeric options at and past their
// limits, a store or configuration that is not a regular file, announcements and requests whose
// vehicle id or run name breaks the id rule (dynid/input/ids.hpp). The server runs as a child
// process under a time limit, on loopback with a discovery tag of this test process.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <memory>

#include <dynid/car/vehicle_profile.hpp>
#include <dynid/cli/request_client.hpp>
#include <dynid/dds/conversions.hpp>
#include <dynid/dds/participant.hpp>
#include <dynid/dds/writer.hpp>

#include "hostile_support.hpp"

namespace dynid::hostile {
namespace {

constexpr dds_domainid_t kDomain = 29;

std::string tagged_config() {
  return dds::config_file_uri(loopback_xml()) + ",<Discovery><Tag>dynid-hostile-" + std::to_string(getpid()) +
         "</Tag></Discovery>";
}

std::vector<std::string> server_args(const std::filesystem::path& store) {
  return {"--store", store.string(), "--cyclone-config", tagged_config(), "--domain", std::to_string(kDomain)};
}

// Case 3 of issue 19: --threads with a huge value aborted ("terminate called without an active
// exception", exit 134). Every numeric option refuses what is not a number within its limits,
// naming the option, before the store is created.
TEST(HostileServer, NumericOptionsOutsideTheirLimitsAreRefusedBeforeAnything) {
  ScratchDir scratch("hostile-server-numbers");
  const auto store = scratch.path() / "store.db";
  const std::vector<NumericOption> options{
      {"--threads", {"257", "1000000000", "4294967296", "-1"}, server_args(store)},
      {"--checkpoint-every", {"0", "1000001", "-1"}, server_args(store)},
      {"--publish-interval-ms", {"-1", "3600001"}, server_args(store)},
      {"--live-residual", {"-1", "86401"}, server_args(store)},
      {"--reorder-window", {"0", "1000001"}, server_args(store)},
      {"--domain", {"-1", "231"}, server_args(store)},
  };
  for (const auto& option : options) expect_refused(Program::Server, option, 2, scratch, store);
}

// A store or a configuration that is not a regular file (a FIFO, a directory, a device) is
// refused at once, naming it and what it is.
TEST(HostileServer, AStoreOrConfigurationThatIsNoRegularFileIsRefused) {
  ScratchDir scratch("hostile-server-files");
  for (const auto& [bad, kind] : not_regular_files(scratch)) {
    SCOPED_TRACE(kind);
    Outcome o = run(Program::Server, server_args(bad), scratch, 5s);
    EXPECT_EQ(o.exit, 2) << describe(o);
    EXPECT_NE(o.output.find(kind), std::string::npos) << describe(o);
    o = run(Program::Server, {"--store", (scratch.path() / "store.db").string(), "--cyclone-config", bad.string()},
            scratch, 5s);
    EXPECT_NE(o.exit, 0) << describe(o);
    EXPECT_TRUE(o.exit.has_value()) << describe(o);
    EXPECT_NE(o.output.find(kind), std::string::npos) << describe(o);
  }
}

// Case 6 of issue 19: an announcement of vehicle "../../../escaped-vehicle" was accepted and
// listed. It is refused now (counted, logged escaped), and so are requests naming such ids.
TEST(HostileServer, IdsOutsideTheRuleAreRefusedOnAnnouncementAndInRequests) {
  ScratchDir scratch("hostile-server-ids");
  const auto store = scratch.path() / "store.db";
  const auto server_log = scratch.path() / "server.log";
  const Running server(Program::Server, server_args(store), server_log);

  dds::Participant participant({kDomain, tagged_config()});
  const car::VehicleProfile profile = car::load_vehicle_profile(testcar_profile());
  auto good = profile.announcement("r1");
  good.vehicle = "good-car";
  auto escaped = good;
  escaped.vehicle = "../../../escaped-vehicle";
  auto forged = good;
  forged.vehicle = "forged";
  forged.run = "r1\nFAKE server line";
  // Each written in the partition of its own key, as a car of that id would (the partition is
  // made by hand here: vehicle_partition() refuses such ids now).
  std::vector<std::unique_ptr<dds::Writer<dynid_wire_RunAnnouncement>>> writers;
  for (const auto* a : {&escaped, &forged, &good}) {
    writers.push_back(std::make_unique<dds::Writer<dynid_wire_RunAnnouncement>>(
        participant, std::vector<std::string>{"vehicle/" + a->vehicle}));
    writers.back()->write(dds::to_wire(*a).data);
  }

  cli::RequestClient client(participant, cli::default_client_id());
  // The server answers once discovered; its list holds good-car once that announcement is in.
  std::string listed;
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (listed.find("good-car") == std::string::npos && std::chrono::steady_clock::now() < deadline) {
    try {
      listed = client.call("vehicles", {}, 2s).payload;
    } catch (const std::exception&) {  // not discovered yet
    }
  }
  ASSERT_NE(listed.find("good-car"), std::string::npos) << listed;
  EXPECT_EQ(listed.find("escaped"), std::string::npos) << listed;
  EXPECT_EQ(listed.find("forged"), std::string::npos) << listed;

  for (const auto& [argument, value] : std::vector<std::pair<std::string, std::string>>{
           {"vehicle", "../../../escaped-vehicle"}, {"vehicle", "a\nb"}, {"vehicle", "v*"}, {"run", "../r"}}) {
    SCOPED_TRACE(argument + "=" + value);
    std::vector<dds::RequestArgument> arguments{{"vehicle", "good-car"}, {"run", "r1"}};
    (argument == "vehicle" ? arguments[0] : arguments[1]).value = value;
    const dds::Reply reply = client.call("close", arguments, 5s);
    EXPECT_EQ(reply.status, dds::ReplyStatus::kBadRequest) << reply.error;
    EXPECT_NE(reply.error.find(argument == "vehicle" ? "vehicle id" : "run name"), std::string::npos) << reply.error;
    EXPECT_EQ(reply.error.find('\n'), std::string::npos) << "escaped: " << reply.error;
  }
  std::ifstream log(server_log);
  for (std::string line; std::getline(log, line);)
    EXPECT_NE(line.rfind("FAKE", 0), 0u) << "a line forged by a run name: " << line;
}

}  // namespace
}  // namespace dynid::hostile
