// The fleet estimate (SuiteSparseQR of the block-angular stack of vehicles' R factors) equals a
// dense LAPACK dgels of the same rows stacked explicitly: every group's raw rows weighted by
// 1/sigma_j of its own batch fit, shared columns common to all vehicles, locals per vehicle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "batch_reference.hpp"
#include "dynid/error.hpp"
#include "dynid/ls/fleet.hpp"

namespace dynid::test {
namespace {

struct RawGroup {
  Eigen::MatrixXd W;
  Eigen::VectorXd y;
};

struct Vehicle {
  ls::FleetMember member;
  std::vector<RawGroup> raw;
};

struct Fleet {
  std::vector<Vehicle> vehicles;
  std::vector<std::string> shared;

  std::vector<ls::FleetMember> members() const {
    std::vector<ls::FleetMember> out;
    for (const auto& v : vehicles) out.push_back(v.member);
    return out;
  }
};

// Vehicle v: the shared parameters and 1..4 locals in a shuffled column order, 1..3 groups with
// their own row counts and noise levels. `dead` names a shared parameter nobody excites.
Vehicle make_vehicle(std::mt19937_64& rng, const std::string& id, const std::vector<std::string>& shared,
                     const std::string& dead = "") {
  std::uniform_int_distribution<int> locals_count(1, 4), groups_count(1, 3), rows(30, 300);
  std::uniform_real_distribution<double> noise_exponent(-3.0, 0.0), value(-5.0, 5.0);
  std::normal_distribution<double> gauss;
  std::vector<ls::FleetParameter> parameters;
  for (const auto& s : shared) parameters.push_back({s, "N"});
  const int locals = locals_count(rng);
  for (int k = 0; k < locals; ++k) parameters.push_back({"local" + std::to_string(k), "kg"});
  std::shuffle(parameters.begin(), parameters.end(), rng);
  const auto n = static_cast<Eigen::Index>(parameters.size());

  // True values: shared ones fixed across the fleet (1, 2, ...), locals per vehicle.
  Eigen::VectorXd x(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const auto& name = parameters[static_cast<std::size_t>(j)].name;
    const auto it = std::find(shared.begin(), shared.end(), name);
    x(j) = it != shared.end() ? 1.0 + static_cast<double>(it - shared.begin()) : value(rng);
  }
  std::vector<std::string> names;
  const int groups = groups_count(rng);
  for (int g = 0; g < groups; ++g) names.push_back("eq" + std::to_string(g));
  Vehicle v{{id, parameters, ls::EquationGroups(n, names)}, {}};
  for (int g = 0; g < groups; ++g) {
    const Eigen::Index m = rows(rng);
    RawGroup raw{Eigen::MatrixXd(m, n), Eigen::VectorXd(m)};
    for (Eigen::Index i = 0; i < m; ++i)
      for (Eigen::Index j = 0; j < n; ++j)
        raw.W(i, j) = parameters[static_cast<std::size_t>(j)].name == dead ? 0.0 : gauss(rng) * (1.0 + j);
    const double noise = std::pow(10.0, noise_exponent(rng));
    raw.y = raw.W * x;
    for (Eigen::Index i = 0; i < m; ++i) raw.y(i) += noise * gauss(rng);
    for (Eigen::Index first = 0; first < m; first += 50)
      v.member.groups.fold(static_cast<std::size_t>(g), raw.W.middleRows(first, std::min<Eigen::Index>(50, m - first)),
                           raw.y.segment(first, std::min<Eigen::Index>(50, m - first)));
    v.raw.push_back(std::move(raw));
  }
  return v;
}

Fleet make_fleet(std::mt19937_64& rng, const std::string& dead = "") {
  std::uniform_int_distribution<int> vehicles(3, 20), shared_count(1, 3);
  Fleet f;
  const int s = shared_count(rng);
  for (int k = 0; k < s; ++k) f.shared.push_back("shared" + std::to_string(k));
  const int count = vehicles(rng);
  for (int v = 0; v < count; ++v) f.vehicles.push_back(make_vehicle(rng, "car-" + std::to_string(v), f.shared, dead));
  return f;
}

// The fleet's columns in report order (shared, then locals vehicle by vehicle), leaving out
// `skip`; column index of (vehicle, name).
struct DenseColumns {
  std::vector<std::pair<std::string, std::string>> columns;  // (vehicle or "", name)
  Eigen::Index index(const std::string& vehicle, const std::string& name, bool shared) const {
    const auto key = std::make_pair(shared ? std::string() : vehicle, name);
    const auto it = std::find(columns.begin(), columns.end(), key);
    return it == columns.end() ? -1 : static_cast<Eigen::Index>(it - columns.begin());
  }
};

struct Dense {
  DenseColumns columns;
  Eigen::MatrixXd W;
  Eigen::VectorXd y;
};

// The explicit weighted stack of every raw row of the fleet.
Dense dense_stack(const Fleet& f, const std::string& skip = "") {
  Dense d;
  for (const auto& s : f.shared)
    if (s != skip) d.columns.columns.emplace_back("", s);
  Eigen::Index rows = 0;
  for (const auto& v : f.vehicles) {
    for (const auto& p : v.member.parameters)
      if (std::find(f.shared.begin(), f.shared.end(), p.name) == f.shared.end())
        d.columns.columns.emplace_back(v.member.vehicle, p.name);
    for (const auto& g : v.raw) rows += g.W.rows();
  }
  d.W = Eigen::MatrixXd::Zero(rows, static_cast<Eigen::Index>(d.columns.columns.size()));
  d.y.resize(rows);
  Eigen::Index row = 0;
  for (const auto& v : f.vehicles) {
    for (const auto& g : v.raw) {
      // The group's own sigma from its own batch fit, without the dead column.
      std::vector<Eigen::Index> live;
      for (Eigen::Index j = 0; j < g.W.cols(); ++j)
        if (v.member.parameters[static_cast<std::size_t>(j)].name != skip) live.push_back(j);
      const double weight = 1.0 / batch_solve(g.W(Eigen::all, live), g.y).sigma;
      for (const Eigen::Index j : live) {
        const auto& name = v.member.parameters[static_cast<std::size_t>(j)].name;
        const bool shared = std::find(f.shared.begin(), f.shared.end(), name) != f.shared.end();
        d.W.col(d.columns.index(v.member.vehicle, name, shared)).segment(row, g.W.rows()) = weight * g.W.col(j);
      }
      d.y.segment(row, g.W.rows()) = weight * g.y;
      row += g.W.rows();
    }
  }
  return d;
}

// The fleet's values and std in the dense stack's column order.
std::pair<Eigen::VectorXd, Eigen::VectorXd> in_dense_order(const ls::FleetEstimate& e, const DenseColumns& c) {
  Eigen::VectorXd value = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(c.columns.size()), NAN);
  Eigen::VectorXd std_dev = value;
  for (const auto& p : e.parameters) {
    const Eigen::Index k = c.index(p.vehicle, p.name, p.vehicle.empty());
    if (k < 0) continue;
    value(k) = p.value;
    std_dev(k) = p.standard_deviation;
  }
  return {value, std_dev};
}

TEST(Fleet, RandomFleetsEqualDenseBatchSolve) {
  std::mt19937_64 rng(4);
  for (int trial = 0; trial < 12; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const Fleet f = make_fleet(rng);
    const ls::FleetEstimate e = ls::fleet_estimate(f.members(), f.shared);
    const Dense d = dense_stack(f);
    const BatchSolution batch = batch_solve(d.W, d.y);
    const auto [value, std_dev] = in_dense_order(e, d.columns);
    EXPECT_FALSE(e.rank_deficient());
    EXPECT_EQ(e.unknowns, d.W.cols());
    EXPECT_EQ(e.rows, static_cast<std::uint64_t>(d.W.rows()));
    EXPECT_LT(relative_error(value, batch.x), 1e-10);
    EXPECT_LT(relative_error(std_dev, batch.standard_deviation), 1e-10);
    EXPECT_NEAR(e.residual_norm, batch.residual_norm, 1e-10 * batch.residual_norm);
    EXPECT_NEAR(e.sigma, batch.sigma, 1e-10 * batch.sigma);
    // Report order: shared first, as asked.
    for (std::size_t k = 0; k < f.shared.size(); ++k) {
      EXPECT_EQ(e.parameters[k].name, f.shared[k]);
      EXPECT_TRUE(e.parameters[k].vehicle.empty());
      EXPECT_EQ(e.parameters[k].status, ls::ParameterStatus::kIdentified);
    }
    // Per-vehicle unweighted residual RMS from the raw rows at the dense solution.
    for (std::size_t v = 0; v < f.vehicles.size(); ++v) {
      double rss = 0.0;
      Eigen::Index rows = 0;
      for (const auto& g : f.vehicles[v].raw) {
        Eigen::VectorXd x(g.W.cols());
        for (Eigen::Index j = 0; j < g.W.cols(); ++j) {
          const auto& name = f.vehicles[v].member.parameters[static_cast<std::size_t>(j)].name;
          const bool shared = std::find(f.shared.begin(), f.shared.end(), name) != f.shared.end();
          x(j) = batch.x(d.columns.index(f.vehicles[v].member.vehicle, name, shared));
        }
        rss += (g.W * x - g.y).squaredNorm();
        rows += g.W.rows();
      }
      const double rms = std::sqrt(rss / static_cast<double>(rows));
      EXPECT_EQ(e.vehicles[v].vehicle, f.vehicles[v].member.vehicle);
      EXPECT_NEAR(e.vehicles[v].residual_rms, rms, 1e-10 * rms);
    }
    // The shared values are recovered (true values 1, 2, 3).
    for (std::size_t k = 0; k < f.shared.size(); ++k)
      EXPECT_NEAR(e.parameters[k].value, 1.0 + static_cast<double>(k), 0.05);
  }
}

TEST(Fleet, SharedParameterNobodyExcitesIsEliminatedAndTheRestStillEqualsTheDenseSolve) {
  std::mt19937_64 rng(44);
  const Fleet f = make_fleet(rng, "shared0");
  const ls::FleetEstimate e = ls::fleet_estimate(f.members(), f.shared);
  EXPECT_TRUE(e.rank_deficient());
  EXPECT_EQ(e.rank, e.unknowns - 1);
  EXPECT_EQ(e.parameters[0].name, "shared0");
  EXPECT_EQ(e.parameters[0].status, ls::ParameterStatus::kEliminated);
  EXPECT_TRUE(std::isnan(e.parameters[0].value));
  EXPECT_TRUE(std::isnan(e.parameters[0].standard_deviation));
  // The identified rest equals the dense solve without the dead column.
  const Dense d = dense_stack(f, "shared0");
  const BatchSolution batch = batch_solve(d.W, d.y);
  const auto [value, std_dev] = in_dense_order(e, d.columns);
  EXPECT_LT(relative_error(value, batch.x), 1e-10);
  EXPECT_LT(relative_error(std_dev, batch.standard_deviation), 1e-10);
}

TEST(Fleet, DependentColumnsAreReportedNotSolved) {
  // Two vehicles whose local column is exactly twice the shared one: the shared parameter and
  // those locals cannot be separated there, and the stacked system is rank deficient.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  std::vector<ls::FleetMember> members;
  for (int v = 0; v < 3; ++v) {
    ls::FleetMember m{"car-" + std::to_string(v), {{"mu", "1"}, {"mass", "kg"}}, ls::EquationGroups(2, {"x"})};
    Eigen::MatrixXd W(100, 2);
    for (Eigen::Index i = 0; i < 100; ++i) {
      W(i, 0) = gauss(rng);
      W(i, 1) = 2.0 * W(i, 0);
    }
    Eigen::VectorXd y = W * Eigen::Vector2d(0.3, 1000.0);
    for (Eigen::Index i = 0; i < 100; ++i) y(i) += 0.01 * gauss(rng);
    m.groups.fold(0, W, y);
    members.push_back(std::move(m));
  }
  const ls::FleetEstimate e = ls::fleet_estimate(members, {"mu"});
  EXPECT_TRUE(e.rank_deficient());
  EXPECT_EQ(e.rank, 3);
  EXPECT_EQ(e.unknowns, 4);
  // Solve order is locals first, so the shared column is the dependent one and each mass
  // absorbs it: mass + mu / 2.
  EXPECT_EQ(e.parameters[0].status, ls::ParameterStatus::kDependent);
  EXPECT_TRUE(std::isnan(e.parameters[0].value));
  for (std::size_t k = 1; k < e.parameters.size(); ++k) {
    EXPECT_EQ(e.parameters[k].status, ls::ParameterStatus::kIdentified);
    EXPECT_NEAR(e.parameters[k].value, 1000.15, 0.01);
  }
}

TEST(Fleet, BadInputIsRejectedWithAReason) {
  std::mt19937_64 rng(9);
  const Fleet f = make_fleet(rng);
  const auto expect_error = [](const std::vector<ls::FleetMember>& members, const std::vector<std::string>& shared,
                               const std::string& fragment) {
    try {
      (void)ls::fleet_estimate(members, shared);
      ADD_FAILURE() << "no error, expected '" << fragment << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect_error({}, {"shared0"}, "no vehicle");
  expect_error(f.members(), {"shared0", "nope"}, "has no parameter 'nope'");
  expect_error(f.members(), {"shared0", "shared0"}, "repeated");
  {
    auto units = f.members();
    for (auto& p : units[2].parameters)
      if (p.name == "shared0") p.unit = "kN";
    expect_error(units, {"shared0"}, "in 'kN' for vehicle 'car-2'");
  }
  {
    auto twice = f.members();
    twice[1].vehicle = twice[0].vehicle;
    expect_error(twice, {"shared0"}, "appears twice");
  }
  {
    auto width = f.members();
    width[0].parameters.push_back({"extra", "m"});
    expect_error(width, {"shared0"}, "columns");
  }
  {
    auto empty = f.members();
    empty[0].groups = ls::EquationGroups(empty[0].groups.group(0).parameter_count(), {"eq0"});
    expect_error(empty, {"shared0"}, "vehicle 'car-0': equation groups: no group has rows");
  }
}

}  // namespace
}  // namespace dynid::test
