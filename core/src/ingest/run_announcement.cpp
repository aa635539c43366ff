#include "dynid/ingest/run_announcement.hpp"

#include <cmath>
#include <set>

#include "byte_codec.hpp"
#include "dynid/error.hpp"
#include "dynid/input/ids.hpp"
#include "dynid/signal/butterworth.hpp"
#include "dynid/signal/zero_phase_filter.hpp"

namespace dynid::ingest {
namespace {

constexpr std::string_view kMagic = "DYNIDRUN";
// Version 2 appends the declared channel noise; an announcement without any is written as
// version 1, byte for byte as before (stored announcements and checkpoints keep matching).
constexpr std::uint16_t kVersion = 1;
constexpr std::uint16_t kVersionWithNoise = 2;

[[noreturn]] void reject(const RunAnnouncement& a, const std::string& field,
                         const std::string& why) {
  throw InputError("run announcement " + input::printable(a.vehicle) + "/" + input::printable(a.run) + ": " + field +
                   " " + why);
}

void validate_preprocessing(const RunAnnouncement& a) {
  const Preprocessing& p = a.preprocessing;
  if (p.butterworth_order < 1 || p.butterworth_order > 8)
    reject(a, "preprocessing.butterworth_order",
           std::to_string(p.butterworth_order) + " is outside 1..8");
  if (p.odmf < 1) reject(a, "preprocessing.odmf", std::to_string(p.odmf) + " must be >= 1");
  const double fc = p.cutoff(a.sample_rate_hz);
  if (!(fc > 0.0 && fc < 0.5 * a.sample_rate_hz))
    reject(a, "preprocessing.cutoff_hz",
           std::to_string(fc) + " Hz is not strictly between 0 and the Nyquist frequency " +
               std::to_string(0.5 * a.sample_rate_hz) + " Hz");
  if (!(p.filter_tolerance >= 1e-13 && p.filter_tolerance <= 1e-3))
    reject(a, "preprocessing.filter_tolerance",
           std::to_string(p.filter_tolerance) + " is outside [1e-13, 1e-3]");
  for (const auto& [channel, sigma] : p.channel_noise) {
    const std::string field = "preprocessing.channel_noise '" + input::printable(channel) + "'";
    if (!(std::isfinite(sigma) && sigma > 0.0)) reject(a, field, std::to_string(sigma) + " is not a finite std > 0");
    bool announced = false;
    for (const ChannelSpec& c : a.channels) announced = announced || c.name == channel;
    if (!announced) reject(a, field, "is not an announced channel");
  }
}

void validate_models(const RunAnnouncement& a) {
  for (std::size_t i = 0; i < a.models.size(); ++i) {
    const ModelSpec& m = a.models[i];
    const std::string field = "models[" + std::to_string(i) + "]";
    if (m.model.empty()) reject(a, field + ".model", "is empty");
    for (const auto& [name, value] : m.constants)
      if (!std::isfinite(value))
        reject(a, field + " (" + m.model + ") constant '" + name + "'", "is not finite");
  }
}

}  // namespace

double Preprocessing::cutoff(double sample_rate_hz) const {
  if (cutoff_hz != 0.0) return cutoff_hz;
  return signal::dycaro_cutoff(sample_rate_hz, odmf);
}

Eigen::Index Preprocessing::edge_samples(double sample_rate_hz) const {
  const signal::Sos sos =
      signal::butterworth_lowpass(butterworth_order, cutoff(sample_rate_hz), sample_rate_hz);
  return signal::zero_phase_edge_reach(sos, kEdgeOutsideShare);
}

void RunAnnouncement::validate() const {
  if (const std::string problem = input::id_problem(vehicle); !problem.empty())
    reject(*this, "vehicle id", problem);
  if (const std::string problem = input::id_problem(run); !problem.empty()) reject(*this, "run name", problem);
  if (!(std::isfinite(sample_rate_hz) && sample_rate_hz > 0.0))
    reject(*this, "sample_rate_hz", std::to_string(sample_rate_hz) + " is not positive and finite");
  if (channels.empty()) reject(*this, "channels", "is empty");
  std::set<std::string> seen;
  for (std::size_t i = 0; i < channels.size(); ++i) {
    const std::string field = "channels[" + std::to_string(i) + "]";
    if (channels[i].name.empty()) reject(*this, field, "has an empty name");
    if (!seen.insert(channels[i].name).second)
      reject(*this, field, "'" + channels[i].name + "' is announced twice");
  }
  validate_models(*this);
  validate_preprocessing(*this);
}

std::size_t RunAnnouncement::column_of(const std::string& channel) const {
  for (std::size_t i = 0; i < channels.size(); ++i)
    if (channels[i].name == channel) return i;
  throw InputError("run " + vehicle + "/" + run + ": unknown channel '" + channel + "'");
}

std::string encode_announcement(const RunAnnouncement& a) {
  detail::ByteWriter w;
  w.bytes().append(kMagic);
  w.put<std::uint16_t>(a.preprocessing.channel_noise.empty() ? kVersion : kVersionWithNoise);
  w.put_string(a.vehicle);
  w.put_string(a.run);
  w.put<double>(a.sample_rate_hz);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(a.channels.size()));
  for (const ChannelSpec& c : a.channels) {
    w.put_string(c.name);
    w.put_string(c.unit);
  }
  w.put<std::uint32_t>(static_cast<std::uint32_t>(a.models.size()));
  for (const ModelSpec& m : a.models) {
    w.put_string(m.model);
    w.put<std::uint32_t>(static_cast<std::uint32_t>(m.constants.size()));
    for (const auto& [name, value] : m.constants) {
      w.put_string(name);
      w.put<double>(value);
    }
    w.put<std::uint32_t>(static_cast<std::uint32_t>(m.effects.size()));
    for (const std::string& e : m.effects) w.put_string(e);
  }
  const Preprocessing& p = a.preprocessing;
  w.put<std::int32_t>(p.butterworth_order);
  w.put<double>(p.cutoff_hz);
  w.put<std::int32_t>(p.odmf);
  w.put<double>(p.filter_tolerance);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(p.unfiltered.size()));
  for (const std::string& u : p.unfiltered) w.put_string(u);
  if (!p.channel_noise.empty()) {
    w.put<std::uint32_t>(static_cast<std::uint32_t>(p.channel_noise.size()));
    for (const auto& [channel, sigma] : p.channel_noise) {
      w.put_string(channel);
      w.put<double>(sigma);
    }
  }
  w.seal();
  return w.take();
}

RunAnnouncement decode_announcement(std::string_view bytes) {
  detail::ByteReader r(bytes, "run announcement encoding");
  const std::uint16_t version = r.open(kMagic, kVersion, kVersionWithNoise);
  RunAnnouncement a;
  a.vehicle = r.get_string("vehicle");
  a.run = r.get_string("run");
  a.sample_rate_hz = r.get<double>("sample rate");
  // Each element takes at least 4 bytes, which bounds the counts before any allocation.
  const auto count = [&r](const char* field) {
    const auto n = r.get<std::uint32_t>(field);
    if (n > r.remaining() / 4)
      r.fail(std::string("corrupted: ") + field + " count " + std::to_string(n));
    return n;
  };
  a.channels.resize(count("channel"));
  for (ChannelSpec& c : a.channels) {
    c.name = r.get_string("channel name");
    c.unit = r.get_string("channel unit");
  }
  a.models.resize(count("model"));
  for (ModelSpec& m : a.models) {
    m.model = r.get_string("model name");
    for (auto n = count("constant"); n > 0; --n) {
      std::string name = r.get_string("constant name");
      m.constants[name] = r.get<double>("constant value");
    }
    m.effects.resize(count("effect"));
    for (std::string& e : m.effects) e = r.get_string("effect");
  }
  Preprocessing& p = a.preprocessing;
  p.butterworth_order = r.get<std::int32_t>("butterworth order");
  p.cutoff_hz = r.get<double>("cut-off");
  p.odmf = r.get<std::int32_t>("odmf");
  p.filter_tolerance = r.get<double>("filter tolerance");
  p.unfiltered.resize(count("unfiltered channel"));
  for (std::string& u : p.unfiltered) u = r.get_string("unfiltered channel");
  if (version >= kVersionWithNoise)
    for (auto n = count("channel noise"); n > 0; --n) {
      std::string channel = r.get_string("noise channel");
      p.channel_noise[channel] = r.get<double>("channel noise");
    }
  r.expect_end();
  return a;
}

}  // namespace dynid::ingest
