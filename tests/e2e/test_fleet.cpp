// (e) Three vehicles stream at once: each one's published estimates are its own (no
// crosstalk, equal to its own offline processor), and a pooled estimate over two runs of one
// vehicle equals the offline pooled solve (the runs' group accumulators merged, then DYCARO's
// weighted estimate).
#include "e2e_fixture.hpp"

namespace dynid::e2e {
namespace {

struct Stream {
  ingest::test::TestRun run;
  std::vector<ingest::Chunk> chunks;
};

// The offline pooled solve of one model over several runs' processors.
Reference pooled_reference(const std::vector<const ingest::RunProcessor*>& runs, std::size_t model) {
  const auto first = runs.front()->estimates()[model];
  const ls::EquationGroups& groups = *runs.front()->groups(model);
  std::vector<std::string> names;
  for (std::size_t g = 0; g < groups.size(); ++g) names.push_back(groups.name(g));
  ls::EquationGroups pool(static_cast<Eigen::Index>(first.parameters.size()), names);
  for (const auto* run : runs)
    for (std::size_t g = 0; g < groups.size(); ++g) pool.group(g).merge(run->groups(model)->group(g));
  return reference_of(first.model, first.parameters, pool.estimate());
}

TEST(E2eFleet, ThreeVehiclesNoCrosstalkAndPooledRuns) {
  TempDir dir;
  InProcessServer server(server_options(dir.file("store.db")));
  ingest::test::Truth heavy;
  heavy.mass = 2100.0;
  heavy.scx = 0.95;
  std::map<std::string, std::vector<Stream>> fleet;
  fleet["car-a"] = {{test_run("car-a", "a-1", 51u), {}}, {test_run("car-a", "a-2", 52u), {}}};
  fleet["car-b"] = {{test_run("car-b", "b-1", 53u, heavy), {}}};
  fleet["car-c"] = {{test_run("car-c", "c-1", 54u), {}}};
  for (auto& [vehicle, streams] : fleet)
    for (std::size_t k = 0; k < streams.size(); ++k) streams[k].chunks = cut_run(streams[k].run, 60u + static_cast<unsigned>(k));

  std::map<std::string, std::unique_ptr<EstimateWatcher>> watchers;
  for (const auto& [vehicle, streams] : fleet) watchers[vehicle] = std::make_unique<EstimateWatcher>(vehicle);
  std::vector<std::thread> cars;
  for (auto& [vehicle, streams] : fleet) {
    cars.emplace_back([&, v = vehicle] {
      TestCar car(v);
      for (const auto& stream : fleet[v]) {
        EXPECT_TRUE(car.stream(stream.run.announcement, stream.chunks)) << v;
      }
    });
  }
  for (auto& car : cars) car.join();

  std::map<std::string, std::vector<ingest::RunProcessor>> processors;
  for (const auto& [vehicle, streams] : fleet) {
    for (const auto& stream : streams) processors[vehicle].push_back(offline(stream.run, stream.chunks));
    const auto& last = streams.back().run.announcement.run;
    const auto expected = references(processors[vehicle].back().estimates());
    ASSERT_TRUE(watchers[vehicle]->wait_for(expected, last))
        << vehicle;
    for (const auto& reference : expected) expect_equal(reference, watchers[vehicle]->latest(last).at(reference.model));
    EXPECT_EQ(watchers[vehicle]->foreign(), 0u) << vehicle << " saw another vehicle's estimates";
  }
  EXPECT_NE(watchers["car-b"]->latest("b-1").at("longitudinal_wheel").parameters[0].value,
            watchers["car-c"]->latest("c-1").at("longitudinal_wheel").parameters[0].value);

  const auto reply = request("pooled", {{"vehicle", "car-a"}, {"run", "a-1"}, {"run", "a-2"}});
  ASSERT_EQ(reply.status, dds::ReplyStatus::kOk) << reply.error;
  const std::vector<const ingest::RunProcessor*> runs{&processors["car-a"][0], &processors["car-a"][1]};
  std::vector<Reference> expected;
  for (std::size_t m = 0; m < runs.front()->model_count(); ++m) expected.push_back(pooled_reference(runs, m));
  ASSERT_TRUE(watchers["car-a"]->wait_for(expected, "pool:a-1+a-2")) << "seen " << watchers["car-a"]->seen();
  for (const auto& reference : expected) expect_equal(reference, watchers["car-a"]->latest("pool:a-1+a-2").at(reference.model));
  // The pool holds both runs' rows.
  EXPECT_EQ(expected[0].rows, processors["car-a"][0].estimates()[0].estimate->estimate.rows +
                                  processors["car-a"][1].estimates()[0].estimate->estimate.rows);
  const auto& mass = watchers["car-a"]->latest("pool:a-1+a-2").at("longitudinal_wheel").parameters[0];
  EXPECT_NEAR(mass.value, ingest::test::Truth{}.mass, 0.05 * ingest::test::Truth{}.mass);
}

}  // namespace
}  // namespace dynid::e2e
