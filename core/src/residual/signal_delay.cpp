#include "dynid/residual/signal_delay.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/error.hpp"
#include "dynid/input/number.hpp"

namespace dynid::residual {
namespace {

constexpr const char* kPrefix = "delay:";

// `values` read `samples` later, clamped at the ends (the clamped samples are invalidated).
Eigen::VectorXd shifted(const Eigen::VectorXd& values, Eigen::Index samples) {
  const Eigen::Index n = values.size();
  Eigen::VectorXd out(n);
  for (Eigen::Index k = 0; k < n; ++k) out(k) = values(std::clamp<Eigen::Index>(k + samples, 0, n - 1));
  return out;
}

// A copy of `set` (sharing the channels no delay touches) with the delayed channels, and their
// derivatives, read on time.
model::ChannelSet delayed_set(const model::ChannelSet& set, const std::vector<SignalDelay>& delays) {
  const Eigen::Index n = set.samples();
  model::ChannelSet out = set;
  for (const std::string& name : set.names()) {
    const std::string base = name.rfind("d_", 0) == 0 ? name.substr(2) : name;
    const auto d = std::find_if(delays.begin(), delays.end(), [&](const SignalDelay& s) { return s.channel == base; });
    if (d != delays.end()) out.replace(name, shifted(set[name], d->samples));
  }
  for (Eigen::Index k = 0; k < n; ++k) {
    bool ok = set.valid(k);
    for (const SignalDelay& d : delays) {
      const Eigen::Index source = k + d.samples;
      ok = ok && source >= 0 && source < n && set.valid(source);
    }
    if (!ok) out.invalidate(k, 1);
  }
  return out;
}

}  // namespace

bool is_delay_effect(const std::string& name) { return name.rfind(kPrefix, 0) == 0; }

SignalDelay parse_delay_effect(const std::string& name, double sample_rate_hz) {
  const std::string form = "effect '" + name + "': expected delay:<channel>@<milliseconds>ms";
  if (!is_delay_effect(name)) throw InputError(form);
  const std::string rest = name.substr(std::string(kPrefix).size());
  const auto at = rest.rfind('@');
  if (at == std::string::npos || at == 0 || rest.size() < at + 4 || rest.compare(rest.size() - 2, 2, "ms") != 0)
    throw InputError(form);
  const std::string number = rest.substr(at + 1, rest.size() - at - 3);
  const std::optional<double> ms = input::parse_finite(number);
  if (!ms || std::abs(*ms) > 10000.0)
    throw InputError("effect '" + name + "': '" + number + "' is not a delay in milliseconds (|d| <= 10 s)");
  return {rest.substr(0, at), static_cast<Eigen::Index>(std::llround(*ms * sample_rate_hz / 1000.0))};
}

std::string delay_effect_name(const std::string& channel, Eigen::Index samples, double sample_rate_hz) {
  return kPrefix + channel + "@" +
         std::to_string(std::llround(static_cast<double>(samples) * 1000.0 / sample_rate_hz)) + "ms";
}

std::vector<ingest::PreprocessedSegment> delayed(const std::vector<ingest::PreprocessedSegment>& run,
                                                 const std::vector<SignalDelay>& delays) {
  for (const SignalDelay& d : delays)
    if (!run.empty() && !run.front().channels.has(d.channel))
      throw InputError("effect 'delay:" + d.channel + "': the run has no channel '" + d.channel + "'");
  std::vector<ingest::PreprocessedSegment> out;
  out.reserve(run.size());
  for (const ingest::PreprocessedSegment& s : run) out.push_back({s.first, delayed_set(s.channels, delays), s.edge});
  return out;
}

}  // namespace dynid::residual
