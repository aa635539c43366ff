// Diagnosis of the noise-free bias (issue 16): one clean run of the bench car, one model, the rows
// built four ways, each fitted by weighted LS with the product's group weights, and the residual at
// the TRUE parameters row by row:
//   product       the product's path (CAN log, resampler, zero-phase filter, central differences)
//   truth-filt    the simulator's truth sampled on the grid (no CAN), then the same filter
//   truth-raw     the truth on the grid, no filter, central differences at the grid rate
//   truth-raw-1k  the truth on the grid, no filter, derivatives from the 1 kHz truth
// Bias of the weighted LS = (W'PW)^-1 W'P r(theta_true); the per-row contribution to it is printed.
// Also each channel's measured noise (with --noise 1: against the sigma bench/trace/car/sensors.cpp draws).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <unistd.h>

#include <Eigen/Dense>

#include "car/clean_run.hpp"
#include "car/declared_fit.hpp"
#include "car/product_path.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/residual/noise_floor.hpp"
#include "dynid/signal/butterworth.hpp"
#include "dynid/signal/derivative.hpp"
#include "dynid/signal/zero_phase_filter.hpp"

using namespace dynid;

namespace {

struct Stacked {
  Eigen::MatrixXd W;
  Eigen::VectorXd y;
  std::vector<double> t;
  std::vector<std::string> group;
};

Stacked stack(const model::Model& m, const std::vector<std::string>& effects,
              const std::vector<ingest::PreprocessedSegment>& segs, int odmf, double rate,
              const std::map<std::string, double>& weight) {
  std::vector<Eigen::RowVectorXd> rows;
  Stacked s;
  std::vector<double> ys;
  for (const auto& seg : segs) {
    std::vector<Eigen::Index> idx;
    for (Eigen::Index i = 0; i < seg.channels.samples(); ++i)
      if (ingest::row_at(seg, i, odmf)) idx.push_back(i);
    for (const auto& g : m.rows_at(seg.channels, idx, effects)) {
      const double w = weight.count(g.group) ? weight.at(g.group) : 1.0;
      for (Eigen::Index r = 0; r < g.W.rows(); ++r) {
        rows.push_back(w * g.W.row(r));
        ys.push_back(w * g.y(r));
        s.t.push_back(static_cast<double>(seg.first + g.samples[static_cast<std::size_t>(r)]) / rate);
        s.group.push_back(g.group);
      }
    }
  }
  const Eigen::Index n = static_cast<Eigen::Index>(rows.size());
  s.W.resize(n, rows.empty() ? 0 : rows.front().size());
  s.y.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    s.W.row(i) = rows[static_cast<std::size_t>(i)];
    s.y(i) = ys[static_cast<std::size_t>(i)];
  }
  return s;
}

// The truth on the run grid as a RecordedRun of the profile's announcement.
ingest::RecordedRun truth_run(const car::VehicleProfile& profile, const benchcar::Truth& truth, Eigen::Index n) {
  ingest::RecordedRun r;
  r.announcement = profile.announcement("truth");
  const double rate = r.announcement.sample_rate_hz;
  r.samples.resize(n, static_cast<Eigen::Index>(r.announcement.channels.size()));
  for (std::size_t c = 0; c < r.announcement.channels.size(); ++c)
    for (Eigen::Index k = 0; k < n; ++k)
      r.samples(k, static_cast<Eigen::Index>(c)) = truth.at(r.announcement.channels[c].name, static_cast<double>(k) / rate);
  r.valid.assign(static_cast<std::size_t>(n), 1);
  return r;
}

// segs with every filtered channel replaced by the raw truth, and d_<x> by derivatives of it
// (at the grid rate, or at 1 kHz from the truth).
std::vector<ingest::PreprocessedSegment> raw(std::vector<ingest::PreprocessedSegment> segs,
                                             const benchcar::Truth& truth, double rate, bool deriv_1k) {
  for (auto& seg : segs) {
    const Eigen::Index n = seg.channels.samples();
    for (const std::string& name : seg.channels.names()) {
      if (name.rfind("d_", 0) == 0) continue;
      if (!truth.channels.count(name)) continue;
      Eigen::VectorXd v(n);
      for (Eigen::Index k = 0; k < n; ++k) v(k) = truth.at(name, static_cast<double>(seg.first + k) / rate);
      seg.channels.replace(name, v);
      const std::string d = "d_" + name;
      if (!seg.channels.has(d)) continue;
      Eigen::VectorXd dv;
      if (!deriv_1k) {
        dv = signal::derivative(v, 1.0 / rate).col(0);
      } else {
        dv.resize(n);
        const double h = 1e-3;
        for (Eigen::Index k = 0; k < n; ++k) {
          const double t = static_cast<double>(seg.first + k) / rate;
          dv(k) = (truth.at(name, t + h) - truth.at(name, t - h)) / (2 * h);
        }
      }
      seg.channels.replace(d, dv);
    }
  }
  return segs;
}

void report(const char* label, const Stacked& s, const Eigen::VectorXd& theta,
            const std::vector<model::ParameterInfo>& params, int top, FILE* dump) {
  const Eigen::MatrixXd A = s.W.transpose() * s.W;
  const Eigen::VectorXd est = A.ldlt().solve(s.W.transpose() * s.y);
  const Eigen::VectorXd r = s.y - s.W * theta;
  const Eigen::MatrixXd G = A.ldlt().solve(s.W.transpose());  // p x n: contribution per row / r_i
  std::printf("== %s: %ld rows, |r(theta_true)| rms %.4g, max %.4g\n", label, static_cast<long>(s.y.size()),
              std::sqrt(r.squaredNorm() / static_cast<double>(std::max<Eigen::Index>(1, r.size()))), r.cwiseAbs().maxCoeff());
  for (Eigen::Index j = 0; j < theta.size(); ++j)
    std::printf("   %-26s true %-12.6g LS %-12.6g rel.err %+.4f %%\n", params[static_cast<std::size_t>(j)].name.c_str(),
                theta(j), est(j), theta(j) != 0 ? 100 * (est(j) - theta(j)) / std::abs(theta(j)) : 0.0);
  // Rows by |contribution| to the first two parameters' relative bias.
  std::vector<Eigen::Index> order(static_cast<std::size_t>(r.size()));
  for (Eigen::Index i = 0; i < r.size(); ++i) order[static_cast<std::size_t>(i)] = i;
  auto contrib = [&](Eigen::Index j, Eigen::Index i) {
    return theta(j) != 0 ? 100 * G(j, i) * r(i) / std::abs(theta(j)) : G(j, i) * r(i);
  };
  std::sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) {
    return std::abs(contrib(0, a)) + std::abs(contrib(1, a)) > std::abs(contrib(0, b)) + std::abs(contrib(1, b));
  });
  for (int k = 0; k < top && k < static_cast<int>(order.size()); ++k) {
    const Eigen::Index i = order[static_cast<std::size_t>(k)];
    std::printf("   t %8.3f %-8s r %+10.4g  contrib %% ", s.t[static_cast<std::size_t>(i)], s.group[static_cast<std::size_t>(i)].c_str(), r(i));
    for (Eigen::Index j = 0; j < theta.size(); ++j) std::printf(" %+9.4f", contrib(j, i));
    std::printf("   W");
    for (Eigen::Index j = 0; j < theta.size(); ++j) std::printf(" %.5g", s.W(i, j));
    std::printf("\n");
  }
  if (dump) {
    for (Eigen::Index i = 0; i < r.size(); ++i) {
      std::fprintf(dump, "%s,%.4f,%s,%.6g,%.6g", label, s.t[static_cast<std::size_t>(i)], s.group[static_cast<std::size_t>(i)].c_str(), s.y(i), r(i));
      for (Eigen::Index j = 0; j < theta.size(); ++j) std::fprintf(dump, ",%.6g", s.W(i, j));
      for (Eigen::Index j = 0; j < theta.size(); ++j) std::fprintf(dump, ",%.6g", contrib(j, i));
      std::fprintf(dump, "\n");
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string profile_path = DYNID_BENCHCAR_PROFILE, manoeuvre = "launch", model_name = "clutch_slip", dump_path;
  double noise = 0.0;
  std::uint64_t seed = 1001;
  int top = 15;
  std::map<std::string, double> extra_truth;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--profile") profile_path = v;
    else if (a == "--manoeuvre") manoeuvre = v;
    else if (a == "--model") model_name = v;
    else if (a == "--noise") noise = std::atof(v.c_str());
    else if (a == "--seed") seed = std::strtoull(v.c_str(), nullptr, 10);
    else if (a == "--top") top = std::atoi(v.c_str());
    else if (a == "--dump") dump_path = v;
    else if (a == "--truth") {  // name=value
      const auto eq = v.find('=');
      extra_truth[v.substr(0, eq)] = std::atof(v.substr(eq + 1).c_str());
    } else {
      std::fprintf(stderr, "unknown %s\n", a.c_str());
      return 2;
    }
  }
  const benchcar::Manoeuvre m = manoeuvre == "launch" ? benchcar::Manoeuvre::kLaunch
                                : manoeuvre == "lateral" ? benchcar::Manoeuvre::kLateral
                                : manoeuvre == "cruise" ? benchcar::Manoeuvre::kCruise
                                                        : benchcar::Manoeuvre::kLongitudinal;
  const car::VehicleProfile& profile = benchcar::profile(profile_path);
  const auto dir = std::filesystem::temp_directory_path() / ("dynid-diag-" + std::to_string(::getpid()));
  const benchcar::CleanRun run = benchcar::clean_run(profile, m, seed, noise, dir);
  std::filesystem::remove_all(dir);
  const auto& rec = run.product.recorded;
  const double rate = rec.announcement.sample_rate_hz;
  const int odmf = rec.announcement.preprocessing.odmf;
  std::printf("preprocessing: order %d cutoff %.3f Hz odmf %d; run first sample %llu, %ld samples\n",
              rec.announcement.preprocessing.butterworth_order, rec.announcement.preprocessing.cutoff(rate), odmf,
              static_cast<unsigned long long>(rec.first_sample_index), static_cast<long>(rec.samples.rows()));
  // What SIMEX and the noise floor take as each channel's noise (against the car's sensors.cpp).
  for (const auto& c : residual::measure_channel_noise(rec, run.segments, {}))
    std::printf("noise %-22s sigma %.5g (%s)\n", c.channel.c_str(), c.sigma, c.source.c_str());
  const ingest::ModelSpec spec = benchcar::model_spec(profile, model_name);
  const auto mdl = model::make_model(spec.model, spec.constants);
  const auto params = mdl->parameters_with(spec.effects);
  Eigen::VectorXd theta(static_cast<Eigen::Index>(params.size()));
  for (std::size_t j = 0; j < params.size(); ++j) {
    auto t = run.truth.parameters.find(params[j].name);
    double v = 0.0;
    if (extra_truth.count(params[j].name)) v = extra_truth[params[j].name];
    else if (t != run.truth.parameters.end()) v = t->second;
    else std::printf("(no truth for %s: 0)\n", params[j].name.c_str());
    theta(static_cast<Eigen::Index>(j)) = v;
  }
  const residual::ModelFit fit = benchcar::declared_fit(profile, model_name, rec, run.segments);
  std::map<std::string, double> weight;
  for (const auto& g : fit.group_statistics) {
    weight[g.name] = g.weight;
    std::printf("group %s: rows %llu sigma %.4g weight %.4g\n", g.name.c_str(), static_cast<unsigned long long>(g.rows), g.sigma, g.weight);
  }
  std::printf("fit_model:");
  for (std::size_t j = 0; j < params.size(); ++j)
    std::printf(" %s %.6g", params[j].name.c_str(), fit.estimate.value(static_cast<Eigen::Index>(j)));
  std::printf("\n");
  FILE* dump = dump_path.empty() ? nullptr : std::fopen(dump_path.c_str(), "w");
  if (dump) {
    std::fprintf(dump, "variant,t,group,y,r");
    for (const auto& p : params) std::fprintf(dump, ",W_%s", p.name.c_str());
    for (const auto& p : params) std::fprintf(dump, ",c_%s", p.name.c_str());
    std::fprintf(dump, "\n");
  }
  report("product", stack(*mdl, spec.effects, run.segments, odmf, rate, weight), theta, params, top, dump);
  const ingest::RecordedRun tr = truth_run(profile, run.truth, rec.samples.rows() + static_cast<Eigen::Index>(rec.first_sample_index));
  // The recorded (unfiltered) product samples against the truth on the grid, channel by channel.
  for (std::size_t c = 0; c < rec.announcement.channels.size(); ++c) {
    double mx = 0, rms = 0;
    Eigen::Index cnt = 0, at = 0;
    for (Eigen::Index k = 0; k < rec.samples.rows(); ++k) {
      if (!rec.valid[static_cast<std::size_t>(k)]) continue;
      const double d = rec.samples(k, static_cast<Eigen::Index>(c)) -
                       tr.samples(static_cast<Eigen::Index>(rec.first_sample_index) + k, static_cast<Eigen::Index>(c));
      if (std::abs(d) > mx) { mx = std::abs(d); at = k; }
      rms += d * d;
      ++cnt;
    }
    std::printf("channel %-22s recorded - truth: rms %.4g max %.4g at t %.3f\n", rec.announcement.channels[c].name.c_str(),
                std::sqrt(rms / static_cast<double>(std::max<Eigen::Index>(cnt, 1))), mx,
                static_cast<double>(static_cast<Eigen::Index>(rec.first_sample_index) + at) / rate);
  }
  const auto tsegs = ingest::preprocess_offline(tr);
  report("truth-filt", stack(*mdl, spec.effects, tsegs, odmf, rate, weight), theta, params, top, dump);
  report("truth-raw", stack(*mdl, spec.effects, raw(tsegs, run.truth, rate, false), odmf, rate, weight), theta, params, top, dump);
  report("truth-raw-1k", stack(*mdl, spec.effects, raw(tsegs, run.truth, rate, true), odmf, rate, weight), theta, params, top, dump);
  if (dump) std::fclose(dump);
  return 0;
}
