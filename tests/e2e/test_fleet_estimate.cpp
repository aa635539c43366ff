// (f) The fleet estimate: three vehicles with different masses and the same drag area stream a
// run each and close it; `fleet longitudinal_wheel SCx --vehicles ...` equals the offline dense
// batch solve (LAPACK dgels) of the same rows to 1e-10, std included, and `dynid fleet` prints
// the table with the shared parameter first.
//
// "The same rows": the raw rows are not kept by a RunProcessor, so the reference stacks each
// group's [R_g | z_g; 0 | rho_g] of the offline processors (an exact factor of the group's raw
// rows: same least-squares problem, same residual) weighted by 1/sigma_g of the group's own
// dgels fit, with the shared column common to all and the others per vehicle.
#include <lapacke.h>

#include <regex>

#include "e2e_fixture.hpp"

namespace dynid::e2e {
namespace {

constexpr const char* kModel = "longitudinal_wheel";
constexpr const char* kShared = "SCx";

struct Dense {
  std::vector<std::string> columns;  // "SCx", then "<vehicle>/<name>"
  Eigen::MatrixXd W;
  Eigen::VectorXd y;
  double raw_rows = 0.0;
};

// dgels of W x = y: the solution and the R factor (W is overwritten on a copy).
std::pair<Eigen::VectorXd, Eigen::MatrixXd> dgels(Eigen::MatrixXd W, Eigen::VectorXd y) {
  const auto m = static_cast<lapack_int>(W.rows()), n = static_cast<lapack_int>(W.cols());
  const lapack_int info = LAPACKE_dgels(LAPACK_COL_MAJOR, 'N', m, n, 1, W.data(), m, y.data(), m);
  EXPECT_EQ(info, 0);
  return {y.head(n), W.topRows(n).triangularView<Eigen::Upper>()};
}

Dense stack(const std::map<std::string, ingest::RunProcessor>& fleet) {
  Dense d{{kShared}, {}, {}, 0.0};
  std::vector<Eigen::MatrixXd> blocks;  // [W | y] per group, columns mapped later
  std::vector<std::vector<Eigen::Index>> maps;
  for (const auto& [vehicle, processor] : fleet) {
    const auto estimates = processor.estimates();
    std::size_t m = 0;
    while (estimates[m].model != kModel) ++m;
    std::vector<Eigen::Index> map;
    for (const auto& p : estimates[m].parameters) {
      if (p.name == kShared) {
        map.push_back(0);
        continue;
      }
      map.push_back(static_cast<Eigen::Index>(d.columns.size()));
      d.columns.push_back(vehicle + "/" + p.name);
    }
    const ls::EquationGroups& groups = *processor.groups(m);
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const ls::Accumulator& a = groups.group(g);
      if (a.row_count() == 0) continue;
      const Eigen::MatrixXd r = a.augmented_r();
      const Eigen::Index n = a.parameter_count();
      const Eigen::VectorXd own = dgels(r.leftCols(n), r.col(n)).first;
      const double rss = (r.leftCols(n) * own - r.col(n)).squaredNorm();
      const double sigma = std::sqrt(rss / (static_cast<double>(a.row_count()) - static_cast<double>(n)));
      blocks.push_back(r / sigma);
      maps.push_back(map);
      d.raw_rows += static_cast<double>(a.row_count());
    }
  }
  Eigen::Index rows = 0;
  for (const auto& b : blocks) rows += b.rows();
  d.W = Eigen::MatrixXd::Zero(rows, static_cast<Eigen::Index>(d.columns.size()));
  d.y.resize(rows);
  Eigen::Index row = 0;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const Eigen::Index n = blocks[k].cols() - 1;
    for (Eigen::Index j = 0; j < n; ++j)
      d.W.col(maps[k][static_cast<std::size_t>(j)]).segment(row, blocks[k].rows()) = blocks[k].col(j);
    d.y.segment(row, blocks[k].rows()) = blocks[k].col(n);
    row += blocks[k].rows();
  }
  return d;
}

struct Published {
  double value = 0.0, std = 0.0;
};

// "SCx" or "<vehicle>/<name>" -> value and std, from the reply's JSON parameters.
std::map<std::string, Published> parse_parameters(const std::string& json) {
  static const std::regex entry(
      R"re(\{"vehicle":(null|"([^"]*)"),"name":"([^"]*)","unit":"[^"]*","value":([^,]*),"std":([^,]*),)re");
  std::map<std::string, Published> out;
  for (std::sregex_iterator it(json.begin(), json.end(), entry), end; it != end; ++it) {
    const auto& m = *it;
    const std::string key = m[1] == "null" ? m[3].str() : m[2].str() + "/" + m[3].str();
    out[key] = {std::stod(m[4].str()), std::stod(m[5].str())};
  }
  return out;
}

TEST(E2eFleetEstimate, SharedDragAreaOverThreeVehiclesEqualsDenseBatchSolve) {
  TempDir dir;
  InProcessServer server(server_options(dir.file("store.db")));
  const std::map<std::string, double> masses{{"fleet-a", 1250.0}, {"fleet-b", 2100.0}, {"fleet-c", 1700.0}};
  std::map<std::string, ingest::RunProcessor> offline_runs;
  unsigned seed = 70;
  for (const auto& [vehicle, mass] : masses) {
    ingest::test::Truth truth;  // same SCx for all
    truth.mass = mass;
    const auto run = test_run(vehicle, vehicle + "-run", ++seed, truth);
    const auto chunks = cut_run(run, seed + 100);
    TestCar car(vehicle);
    ASSERT_TRUE(car.stream(run.announcement, chunks)) << vehicle;
    const auto closed = request("close", {{"vehicle", vehicle}, {"run", vehicle + "-run"}});
    ASSERT_EQ(closed.status, dds::ReplyStatus::kOk) << closed.error;
    auto processor = offline(run, chunks);
    processor.finish();
    offline_runs.emplace(vehicle, std::move(processor));
  }

  const auto reply = request("fleet", {{"model", kModel}, {"shared", kShared},
                                       {"vehicles", "fleet-a,fleet-b,fleet-c"}, {"format", "json"}});
  ASSERT_EQ(reply.status, dds::ReplyStatus::kOk) << reply.error;
  const std::string json(reply.payload.begin(), reply.payload.end());
  const auto published = parse_parameters(json);

  const Dense d = stack(offline_runs);
  const auto [x, r] = dgels(d.W, d.y);
  const double residual = (d.W * x - d.y).norm();
  const double sigma = residual / std::sqrt(d.raw_rows - static_cast<double>(x.size()));
  const Eigen::MatrixXd r_inv = r.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(r.rows(), r.cols()));
  const Eigen::VectorXd std_dev = sigma * r_inv.rowwise().norm();

  ASSERT_EQ(published.size(), d.columns.size()) << json;
  EXPECT_EQ(json.find("\"rank_deficient\":false"), json.find("\"rank_deficient\":")) << json;
  const double scale = x.cwiseAbs().maxCoeff();
  for (std::size_t k = 0; k < d.columns.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    ASSERT_TRUE(published.count(d.columns[k])) << d.columns[k] << " missing in " << json;
    const Published& p = published.at(d.columns[k]);
    EXPECT_NEAR(p.value, x(i), 1e-10 * scale) << d.columns[k];
    EXPECT_NEAR(p.std, std_dev(i), 1e-10 * std_dev(i)) << d.columns[k];
  }
  EXPECT_NEAR(published.at(kShared).value, ingest::test::Truth{}.scx, 0.05 * ingest::test::Truth{}.scx);
  for (const auto& [vehicle, mass] : masses)
    EXPECT_NEAR(published.at(vehicle + "/mass").value, mass, 0.05 * mass) << vehicle;

  // The CLI prints the same estimate as a table, shared parameter first.
  const auto table = run_command({DYNID_CLI_EXE, "--cyclone-config", loopback_config(), "--domain",
                                  std::to_string(kDomain), "--timeout", "10", "fleet", kModel, kShared,
                                  "--vehicles", "fleet-a,fleet-b,fleet-c"},
                                 20s);
  ASSERT_EQ(table.exit_code, 0) << table.err;
  const auto shared_line = table.out.find("\nSCx ");
  ASSERT_NE(shared_line, std::string::npos) << table.out;
  EXPECT_LT(shared_line, table.out.find("fleet-a/mass")) << table.out;
  for (const std::string word : {"fleet longitudinal_wheel over 3 vehicles", "fleet-b/rolling_resistance",
                                 "identified", "residual rms", "fleet-c-run"})
    EXPECT_NE(table.out.find(word), std::string::npos) << "missing '" << word << "' in\n" << table.out;

  // An unknown vehicle or shared parameter is refused with a reason.
  const auto unknown = request("fleet", {{"model", kModel}, {"shared", kShared}, {"vehicles", "fleet-a,nobody"}});
  EXPECT_EQ(unknown.status, dds::ReplyStatus::kNotFound) << unknown.error;
  const auto bad = request("fleet", {{"model", kModel}, {"shared", "no_such"}, {"vehicles", "fleet-a,fleet-b"}});
  EXPECT_EQ(bad.status, dds::ReplyStatus::kBadRequest);
  EXPECT_NE(bad.error.find("no parameter 'no_such'"), std::string::npos) << bad.error;
}

}  // namespace
}  // namespace dynid::e2e
