#include "dynid/car/profile_check.hpp"

#include <cstdio>

#include "dynid/error.hpp"
#include "dynid/ingest/channel_health.hpp"
#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/registry.hpp"

namespace dynid::car {
namespace {

std::string figure(const char* format, double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string source_of(const VehicleProfile& profile, const ChannelMapping& c) {
  if (c.source) return "source '" + profile.sources.at(*c.source).name + "'";
  if (c.constant) return "constant " + figure("%g", *c.constant) + " " + c.unit;
  std::string signals;
  for (const SignalInput& in : c.inputs)
    signals += (signals.empty() ? c.message + "." : "+") + in.signal;
  return signals;
}

}  // namespace

bool ProfileCheck::runs() const {
  for (const ModelCheck& m : models)
    if (!m.runs) return false;
  return true;
}

std::string ProfileCheck::text() const {
  std::string out = "profile of " + vehicle + ": " + std::to_string(models.size()) + " models, " +
                    std::to_string(channels.size()) + " channels on a " + figure("%g", grid_hz) +
                    " Hz grid\n";
  if (with_log) {
    out += "log " + log + ": " + figure("%.1f", seconds) + " s, " + std::to_string(rows) +
           " rows (" + std::to_string(invalid_rows) + " invalid)\n";
    out += "channels:\n";
    for (const ChannelCheck& c : channels) {
      out += "  " + c.channel + " [" + c.unit + "] from " + c.source + ": " +
             figure("%.1f", c.rate_hz) + " Hz";
      out += c.missing_share > 0.0
                 ? ", no value in " + figure("%.2g", 100.0 * c.missing_share) + " % of the rows"
                 : ", a value in every row";
      out += "\n";
      for (const std::string& f : c.findings) out += "    " + f + "\n";
    }
    for (const std::string& f : run_findings) out += "  " + f + "\n";
  }
  out += with_log ? "models on this log:\n" : "models:\n";
  std::size_t cannot = 0;
  for (const ModelCheck& m : models) {
    out += "  " + m.model + ": " + (m.runs ? "can run" : "cannot run: " + m.why) + "\n";
    cannot += m.runs ? 0 : 1;
  }
  out += cannot == 0 ? "every model can run\n"
                     : std::to_string(cannot) + " of " + std::to_string(models.size()) +
                           " models cannot run\n";
  return out;
}

ProfileCheck check_profile(const VehicleProfile& profile) {
  ProfileCheck out;
  out.vehicle = profile.vehicle;
  out.grid_hz = profile.rate_hz;
  for (std::size_t i = 0; i < profile.models.size(); ++i) {
    const std::string why = lacking_channels(profile, i);
    out.models.push_back({profile.models[i].model, why.empty(), why});
  }
  for (const ChannelMapping& c : profile.channels) {
    ChannelCheck channel;
    channel.channel = c.channel;
    channel.unit = c.unit;
    channel.source = source_of(profile, c);
    out.channels.push_back(std::move(channel));
  }
  return out;
}

void check_log(ProfileCheck& check, const VehicleProfile& profile, const std::string& log_name,
               const CarPipeline& pipe, const std::vector<ingest::Chunk>& chunks) {
  check.with_log = true;
  check.log = log_name;
  const ResamplerStats& r = pipe.resampler_stats();
  check.rows = r.rows;
  check.invalid_rows = r.invalid_rows;
  // The log's own span (first to last frame), not the grid's rows: the grid ends where the last
  // channel's gap rule does.
  if (pipe.first_time()) check.seconds = pipe.newest_frame_time() - *pipe.first_time();
  for (std::size_t c = 0; c < check.channels.size(); ++c) {
    ChannelCheck& channel = check.channels[c];
    if (c < r.samples_by_channel.size() && check.seconds > 0.0)
      channel.rate_hz = static_cast<double>(r.samples_by_channel[c]) / check.seconds;
    if (c < r.missing_by_channel.size() && r.rows > 0)
      channel.missing_share =
          static_cast<double>(r.missing_by_channel[c]) / static_cast<double>(r.rows);
  }
  if (chunks.empty()) {
    for (ModelCheck& m : check.models)
      if (m.runs) m.runs = false, m.why = "the log gave no row";
    return;
  }
  const ingest::RunAnnouncement announcement = profile.announcement(chunks.front().run);
  const ingest::RecordedRun run = ingest::assemble_run(announcement, chunks);
  const ingest::RunHealth health = ingest::channel_health(run);
  for (const ingest::ChannelFinding& f : health.findings) {
    bool placed = false;
    for (ChannelCheck& c : check.channels)
      if (!f.channel.empty() && c.channel == f.channel)
        c.findings.push_back(f.statement), placed = true;
    if (!placed) check.run_findings.push_back(f.statement);
  }
  const bool segments = !ingest::preprocess_offline(run).empty();
  for (std::size_t i = 0; i < check.models.size(); ++i) {
    ModelCheck& m = check.models[i];
    if (!m.runs) continue;
    if (!segments) {
      m.runs = false, m.why = "no valid segment long enough to filter on this log";
      continue;
    }
    const ingest::ModelSpec& spec = profile.models[i];
    if (const auto why = ingest::unhealthy_reason(
            health, announcement, *model::make_model(spec.model, spec.constants), spec.effects))
      m.runs = false, m.why = ingest::not_identified(*why);
  }
}

}  // namespace dynid::car
