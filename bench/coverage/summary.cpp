#include "summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

namespace dynid::benchcoverage {
namespace {

bool usable(const ParameterSample& s) {
  return std::isfinite(s.value) && std::isfinite(s.std) && std::isfinite(s.hac_std);
}

double mean(const std::vector<double>& x) {
  double sum = 0.0;
  for (double v : x) sum += v;
  return x.empty() ? kNaN : sum / static_cast<double>(x.size());
}

double scatter(const std::vector<double>& x) {
  if (x.size() < 2) return kNaN;
  const double m = mean(x);
  double sum = 0.0;
  for (double v : x) sum += (v - m) * (v - m);
  return std::sqrt(sum / static_cast<double>(x.size() - 1));
}

// errors and std in % of the truth, seed by seed.
StdCoverage coverage_of(const std::vector<double>& errors, const std::vector<double>& stds) {
  StdCoverage c;
  c.mean_std_pct = mean(stds);
  int within = 0;
  for (std::size_t i = 0; i < errors.size(); ++i) within += std::abs(errors[i]) <= 2.0 * stds[i] ? 1 : 0;
  c.within_2std = errors.empty() ? kNaN : static_cast<double>(within) / static_cast<double>(errors.size());
  c.error_over_std = std::abs(mean(errors)) / c.mean_std_pct;
  return c;
}

IvCoverage iv_of(const std::vector<const ParameterSample*>& samples) {
  IvCoverage c;
  std::vector<double> textbook, hac;
  int rejections = 0;
  for (const ParameterSample* s : samples) {
    if (!s->iv_refused.empty()) ++c.refused;
    if (!std::isfinite(s->iv_value) || !std::isfinite(s->iv_std) || !std::isfinite(s->iv_hac_std)) continue;
    c.errors_pct.push_back(100.0 * s->iv_relative_error());
    textbook.push_back(100.0 * s->iv_std / std::abs(s->truth));
    hac.push_back(100.0 * s->iv_hac_std / std::abs(s->truth));
    rejections += s->dwh_rejects ? 1 : 0;
  }
  c.seeds = static_cast<int>(c.errors_pct.size());
  c.mean_error_pct = mean(c.errors_pct);
  c.scatter_pct = scatter(c.errors_pct);
  c.textbook = coverage_of(c.errors_pct, textbook);
  c.hac = coverage_of(c.errors_pct, hac);
  c.dwh_rejections = c.seeds > 0 ? static_cast<double>(rejections) / c.seeds : kNaN;
  return c;
}

SimexCoverage simex_of(const std::vector<const ParameterSample*>& samples) {
  SimexCoverage c;
  std::vector<double> stds, monte_carlo;
  for (const ParameterSample* s : samples) {
    if (!std::isfinite(s->simex_value) || !std::isfinite(s->simex_std)) continue;
    c.corrected += s->simex_corrected ? 1 : 0;
    c.errors_pct.push_back(100.0 * s->simex_relative_error());
    stds.push_back(100.0 * s->simex_std / std::abs(s->truth));
    monte_carlo.push_back(100.0 * s->simex_mc_std / std::abs(s->truth));
  }
  c.seeds = static_cast<int>(c.errors_pct.size());
  c.mean_error_pct = mean(c.errors_pct);
  c.scatter_pct = scatter(c.errors_pct);
  c.mean_monte_carlo_std_pct = mean(monte_carlo);
  c.std = coverage_of(c.errors_pct, stds);
  return c;
}

// What the product publishes (residual::publish, the server's own rule; ParameterSample's
// published_*), with SIMEX or, with_simex false, with the IV fit alone.
PublishedCoverage published_of(const std::vector<const ParameterSample*>& samples, bool with_simex) {
  PublishedCoverage c;
  std::vector<double> stds;
  for (const ParameterSample* s : samples) {
    const double value = with_simex ? s->published_value : s->without_simex_value;
    const double std = with_simex ? s->published_std : s->without_simex_std;
    const residual::PublishedEstimator by = with_simex ? s->published_by : s->without_simex_by;
    if (!std::isfinite(value) || !std::isfinite(std)) continue;
    c.by_iv += by == residual::PublishedEstimator::kInstrumentalVariables ? 1 : 0;
    c.by_simex += by == residual::PublishedEstimator::kSimex ? 1 : 0;
    c.errors_pct.push_back(100.0 * (value - s->truth) / std::abs(s->truth));
    stds.push_back(100.0 * std / std::abs(s->truth));
  }
  c.seeds = static_cast<int>(c.errors_pct.size());
  c.mean_error_pct = mean(c.errors_pct);
  c.scatter_pct = scatter(c.errors_pct);
  c.std = coverage_of(c.errors_pct, stds);
  return c;
}

ParameterCoverage row_of(const std::vector<const ParameterSample*>& samples) {
  ParameterCoverage row;
  row.model = samples.front()->model;
  row.parameter = samples.front()->parameter;
  row.truth = samples.front()->truth;
  std::vector<double> errors, table, hac;
  for (const ParameterSample* s : samples) {
    if (!usable(*s)) continue;
    errors.push_back(100.0 * s->relative_error());
    table.push_back(100.0 * s->std / std::abs(s->truth));
    hac.push_back(100.0 * s->hac_std / std::abs(s->truth));
  }
  row.seeds = static_cast<int>(errors.size());
  row.errors_pct = errors;
  row.mean_error_pct = mean(errors);
  row.scatter_pct = scatter(errors);
  row.table = coverage_of(errors, table);
  row.hac = coverage_of(errors, hac);
  row.iv = iv_of(samples);
  row.simex = simex_of(samples);
  row.without_simex = published_of(samples, false);
  row.published = published_of(samples, true);
  return row;
}

std::string cells(const StdCoverage& c) {
  char b[120];
  std::snprintf(b, sizeof b, " %.3g %% | %.0f %% | %.2f |", c.mean_std_pct, 100.0 * c.within_2std, c.error_over_std);
  return b;
}

// printf into a string (the cells of a table line).
template <typename... Args>
std::string formatted(const char* pattern, Args... args) {
  char b[200];
  std::snprintf(b, sizeof b, pattern, args...);
  return b;
}

// A table line's first cells, "| model | parameter | ", then `pattern`.
template <typename... Args>
std::string start(const ParameterCoverage& r, const char* pattern, Args... args) {
  return "| " + r.model + " | " + r.parameter + " | " + formatted(pattern, args...);
}

// A markdown table: the header line, its separator, one line per row.
std::string table(const std::string& header, const std::vector<ParameterCoverage>& rows,
                  const std::function<std::string(const ParameterCoverage&)>& line) {
  std::string out = header + "\n";
  for (std::size_t c = 1; c < static_cast<std::size_t>(std::count(header.begin(), header.end(), '|')); ++c) out += "|---";
  out += "|\n";
  for (const ParameterCoverage& r : rows) out += line(r) + "\n";
  return out;
}

}  // namespace

std::vector<ParameterCoverage> summarize(const std::vector<SeedRun>& runs) {
  std::vector<std::pair<std::string, std::string>> keys;
  for (const SeedRun& r : runs)
    for (const ParameterSample& s : r.samples)
      if (std::find(keys.begin(), keys.end(), std::make_pair(s.model, s.parameter)) == keys.end())
        keys.emplace_back(s.model, s.parameter);
  std::vector<ParameterCoverage> rows;
  for (const auto& [model, parameter] : keys) {
    std::vector<const ParameterSample*> samples;
    for (const SeedRun& r : runs)
      for (const ParameterSample& s : r.samples)
        if (s.model == model && s.parameter == parameter) samples.push_back(&s);
    rows.push_back(row_of(samples));
  }
  return rows;
}

std::string markdown_table(const std::vector<ParameterCoverage>& rows) {
  return table("| model | parameter | truth | runs | mean error | scatter | table std | within 2 table std | mean error / "
               "table std | HAC std | within 2 HAC std | mean error / HAC std |",
               rows, [](const ParameterCoverage& r) {
                 return start(r, "%.6g | %d | %+.3g %% | %.3g %% |", r.truth, r.seeds, r.mean_error_pct, r.scatter_pct) +
                        cells(r.table) + cells(r.hac);
               });
}

std::string iv_markdown_table(const std::vector<ParameterCoverage>& rows) {
  return table("| model | parameter | LS mean error | IV runs | IV mean error | IV scatter | IV std | within 2 IV std | "
               "mean error / IV std | IV HAC std | within 2 IV HAC std | mean error / IV HAC std | DWH rejects at 1 % |",
               rows, [](const ParameterCoverage& r) {
                 return start(r, "%+.3g %% | %d | %+.3g %% | %.3g %% |", r.mean_error_pct, r.iv.seeds,
                              r.iv.mean_error_pct, r.iv.scatter_pct) +
                        cells(r.iv.textbook) + cells(r.iv.hac) + formatted(" %.0f %% |", 100.0 * r.iv.dwh_rejections);
               });
}

}  // namespace dynid::benchcoverage

namespace dynid::benchcoverage {

std::string without_simex_markdown_table(const std::vector<ParameterCoverage>& rows) {
  return table("| model | parameter | runs | by IV | mean error | scatter | std | within 2 std | mean error / std |", rows,
               [](const ParameterCoverage& r) {
                 return start(r, "%d | %d | %+.3g %% | %.3g %% |", r.without_simex.seeds, r.without_simex.by_iv,
                              r.without_simex.mean_error_pct, r.without_simex.scatter_pct) +
                        cells(r.without_simex.std);
               });
}

std::string simex_markdown_table(const std::vector<ParameterCoverage>& rows) {
  return table("| model | parameter | LS mean error | IV mean error | SIMEX runs | corrected | SIMEX mean error | SIMEX "
               "scatter | SIMEX std | within 2 SIMEX std | mean error / SIMEX std | of it Monte Carlo |",
               rows, [](const ParameterCoverage& r) {
                 return start(r, "%+.3g %% | %+.3g %% | %d | %d | %+.3g %% | %.3g %% |", r.mean_error_pct,
                              r.iv.mean_error_pct, r.simex.seeds, r.simex.corrected, r.simex.mean_error_pct,
                              r.simex.scatter_pct) +
                        cells(r.simex.std) + formatted(" %.3g %% |", r.simex.mean_monte_carlo_std_pct);
               });
}

std::string published_markdown_table(const std::vector<ParameterCoverage>& rows) {
  return table("| model | parameter | runs | by IV | by SIMEX | mean error | scatter | std | within 2 std | mean error / "
               "std |",
               rows, [](const ParameterCoverage& r) {
                 return start(r, "%d | %d | %d | %+.3g %% | %.3g %% |", r.published.seeds, r.published.by_iv,
                              r.published.by_simex, r.published.mean_error_pct, r.published.scatter_pct) +
                        cells(r.published.std);
               });
}

}  // namespace dynid::benchcoverage
