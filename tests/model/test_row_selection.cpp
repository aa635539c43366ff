// Model::rows_at: the rows at chosen samples are exactly (bit for bit) the rows rows() builds at
// those samples, for every registered model with all its effects and dictionary lags, on data
// with gaps (models read their neighbours' validity: the locked driveline's gear test, the
// dictionary's lags, the clutch's stick margin); a bad selection is an InputError.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "dynid/error.hpp"
#include "dynid/model/channel_catalogue.hpp"
#include "dynid/model/channel_set.hpp"
#include "dynid/model/registry.hpp"

namespace dynid::test {
namespace {

// Every constant a registered model reads (the gear selects the locked driveline's rows).
const model::Constants kConstants{
    {"a", 1.1},           {"b", 1.6},
    {"mass", 1500.0},     {"wheel_radius", 0.3},
    {"air_density", 1.2}, {"driveline_efficiency", 0.9},
    {"gear", 2.0},        {"clutch_friction_radius", 0.11},
    {"stribeck_speed", 0.2}, {"stick_margin", 0.05},
    {"hub_x_fl", 1.2},    {"hub_y_fl", 0.8},
    {"hub_z_fl", -0.3},   {"hub_x_fr", 1.2},
    {"hub_y_fr", -0.8},   {"hub_z_fr", -0.3},
    {"hub_x_rl", -1.5},   {"hub_y_rl", 0.8},
    {"hub_z_rl", -0.3},   {"hub_x_rr", -1.5},
    {"hub_y_rr", -0.8},   {"hub_z_rr", -0.3}};

// Every channel the model or its effects read, random (the gear in runs of 1..3 so that
// shifts and gaps sit next to rows), with a few gaps.
model::ChannelSet random_channels(const model::Model& m, Eigen::Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_int_distribution<int> gear(1, 3), run(1, 6);
  std::vector<std::string> names;
  for (const model::ChannelNeed& c : m.channels()) names.push_back(c.name);
  for (const model::Effect& e : m.candidate_effects())
    names.insert(names.end(), e.channels.begin(), e.channels.end());
  model::ChannelSet set(0.01, n);
  for (const std::string& name : names) {
    if (set.has(name)) continue;
    Eigen::VectorXd v(n);
    if (name == "gear") {
      for (Eigen::Index k = 0; k < n;) {
        const double g = gear(rng);
        for (int r = run(rng); r > 0 && k < n; --r) v(k++) = g;
      }
    } else {
      for (Eigen::Index k = 0; k < n; ++k) v(k) = 2.0 + normal(rng);
    }
    set.add(name, *model::channel_unit(name), v);
  }
  set.invalidate(7, 2);
  set.invalidate(40, 1);
  set.invalidate(n - 5, 3);
  return set;
}

std::vector<std::string> every_effect(const model::Model& m, const model::ChannelSet& set) {
  std::vector<std::string> out;
  for (const model::Effect& e : m.candidate_effects()) out.push_back(e.name);
  const std::string channel = set.names().front();
  out.push_back("dict:lag2:" + channel);
  out.push_back("dict:d:" + channel);
  return out;
}

// rows_at(selection) equals rows() restricted to the selection, bit for bit.
void expect_selection_matches(const model::Model& m, const model::ChannelSet& set,
                              const std::vector<std::string>& effects,
                              const std::vector<Eigen::Index>& selection) {
  const std::vector<model::GroupRows> all = m.rows(set, effects);
  const std::vector<model::GroupRows> some = m.rows_at(set, selection, effects);
  ASSERT_EQ(all.size(), some.size()) << m.name();
  for (std::size_t g = 0; g < all.size(); ++g) {
    std::vector<Eigen::Index> expected;  // rows of `all` at selected samples
    for (std::size_t r = 0; r < all[g].samples.size(); ++r)
      if (std::binary_search(selection.begin(), selection.end(), all[g].samples[r]))
        expected.push_back(static_cast<Eigen::Index>(r));
    const std::string where = m.name() + " group " + all[g].group;
    ASSERT_EQ(some[g].samples.size(), expected.size()) << where;
    EXPECT_EQ(some[g].group, all[g].group);
    for (std::size_t r = 0; r < expected.size(); ++r) {
      const Eigen::Index row = expected[r];
      EXPECT_EQ(some[g].samples[r], all[g].samples[static_cast<std::size_t>(row)]) << where;
      EXPECT_EQ(some[g].y(static_cast<Eigen::Index>(r)), all[g].y(row)) << where;
      EXPECT_TRUE((some[g].W.row(static_cast<Eigen::Index>(r)).array() == all[g].W.row(row).array()).all())
          << where << " sample " << some[g].samples[r];
    }
  }
}

TEST(RowSelection, EveryModelGivesTheSameRowsAtTheChosenSamples) {
  constexpr Eigen::Index n = 120;
  std::vector<Eigen::Index> every_third, around_gaps, all;
  for (Eigen::Index k = 1; k < n; k += 3) every_third.push_back(k);
  for (Eigen::Index k : {0, 5, 6, 7, 9, 10, 39, 41, 100, 114, 115, 119}) around_gaps.push_back(k);
  for (Eigen::Index k = 0; k < n; ++k) all.push_back(k);
  for (const std::string& name : model::model_names()) {
    const auto m = model::make_model(name, kConstants);
    const model::ChannelSet set = random_channels(*m, n, 11);
    for (const auto& effects : {std::vector<std::string>{}, every_effect(*m, set)}) {
      std::size_t rows = 0;
      for (const model::GroupRows& g : m->rows(set, effects)) rows += g.samples.size();
      EXPECT_GT(rows, 0u) << name << ": the data give no row, the comparison would be empty";
      for (const auto* selection : {&every_third, &around_gaps, &all})
        expect_selection_matches(*m, set, effects, *selection);
    }
  }
}

TEST(RowSelection, OutOfRangeOrUnorderedSelectionIsNamed) {
  const auto m = model::make_model("body", kConstants);
  const model::ChannelSet set = random_channels(*m, 60, 3);
  for (const std::vector<Eigen::Index>& bad :
       {std::vector<Eigen::Index>{3, 60}, std::vector<Eigen::Index>{-1}, std::vector<Eigen::Index>{4, 4},
        std::vector<Eigen::Index>{5, 2}}) {
    try {
      (void)m->rows_at(set, bad);
      ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("model 'body'"), std::string::npos) << what;
      EXPECT_NE(what.find("selected sample"), std::string::npos) << what;
    }
  }
  EXPECT_TRUE(m->rows_at(set, {}).front().samples.empty());
}

}  // namespace
}  // namespace dynid::test
