#include "sim_test_support.hpp"

#include "dynid/error.hpp"
#include "dynid/sim/outputs.hpp"

namespace dynid::sim::test {

const can::Database& testcar_dbc() {
  static const can::Database db = can::parse_dbc_file(DYNID_TESTCAR_DBC);
  return db;
}

Scenario scenario(const std::string& toml) { return parse_scenario(toml, "test scenario"); }

Run run(const std::string& toml, std::uint64_t seed) { return simulate(scenario(toml), seed, testcar_dbc()); }

std::vector<double> column(const Run& r, const std::string& channel, bool truth) {
  const std::size_t c = channel_index(channel);
  std::vector<double> out;
  for (const auto& row : truth ? r.truth : r.measured) out.push_back(row[c]);
  return out;
}

double truth_value(const Run& r, const std::string& key) {
  const auto table = truth_table(r);
  const auto v = table.at_path(key).value<double>();
  if (!v) throw InputError("truth.toml has no number at " + key);
  return *v;
}

}  // namespace dynid::sim::test

#include <fstream>
#include <sstream>

namespace dynid::sim::test {
std::string load_scenario_text(const std::string& file) {
  std::ifstream in(std::string(DYNID_SCENARIO_DIR) + "/" + file);
  if (!in) throw InputError("cannot open scenario " + file);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace dynid::sim::test
