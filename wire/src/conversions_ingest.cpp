// Conversions of the ingest topics: RunAnnouncement and Chunk.
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <string>

#include <dynid/input/ids.hpp>

#include "dynid/dds/conversions.hpp"
#include "wire_fields.hpp"

namespace dynid::dds {

using wire_fields::allocate;
using wire_fields::elements;
using wire_fields::get;
using wire_fields::put_id;

namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// A name -> value map as a bounded sequence of NamedValue (`what`: "constant", "channel noise").
template <typename Sequence>
void put_named(Sequence& out, const std::map<std::string, double>& values, std::size_t bound,
               const std::string& where, const std::string& what) {
  auto* entries = allocate(out, values.size(), bound, where + " " + what);
  std::size_t k = 0;
  for (const auto& [name, value] : values) {
    put_id(entries[k].name, name, where + " " + what + " name");
    entries[k++].value = value;
  }
}

template <typename Sequence>
std::map<std::string, double> get_named(const Sequence& in, std::size_t bound, const std::string& where,
                                        const std::string& what) {
  std::map<std::string, double> out;
  for (const auto& entry : elements(in, bound, where + " " + what)) {
    const std::string name = get(entry.name, where + " " + what + " name");
    if (!out.emplace(name, entry.value).second) throw InputError(where + ": duplicate " + what + " '" + name + "'");
  }
  return out;
}

void put_model(dynid_wire_ModelSpec& out, const ingest::ModelSpec& model, const std::string& where) {
  put_id(out.model, model.model, where + " model");
  put_named(out.constants, model.constants, dynid_wire_kMaxConstants, where, "constant");
  auto* effects =
      allocate(out.effects, model.effects.size(), dynid_wire_kMaxEffects, where + " effects");
  for (std::size_t e = 0; e < model.effects.size(); ++e)
    put_id(effects[e], model.effects[e], where + " effect");
}

ingest::ModelSpec get_model(const dynid_wire_ModelSpec& in, const std::string& where) {
  ingest::ModelSpec model;
  model.model = get(in.model, where + " model");
  const std::string at = where + " '" + model.model + "'";
  model.constants = get_named(in.constants, dynid_wire_kMaxConstants, at, "constant");
  for (const auto& effect : elements(in.effects, dynid_wire_kMaxEffects, at + " effects"))
    model.effects.push_back(get(effect, at + " effect"));
  return model;
}

/// "Chunk <vehicle>/<run>#<sequence>", readable even when the ids are malformed.
std::string chunk_name(const dynid_wire_Chunk& sample) {
  const auto id = [](const dynid_wire_Id& field) {
    return std::string(field, strnlen(field, sizeof field));
  };
  return "Chunk " + input::printable(id(sample.vehicle)) + "/" + input::printable(id(sample.run)) + "#" +
         std::to_string(sample.sequence_number);
}

}  // namespace

Sample<dynid_wire_RunAnnouncement> to_wire(const ingest::RunAnnouncement& announcement) {
  const std::string where = "RunAnnouncement " + announcement.vehicle + "/" + announcement.run;
  Sample<dynid_wire_RunAnnouncement> sample;
  auto& out = sample.data;
  put_id(out.vehicle, announcement.vehicle, where + " vehicle");
  put_id(out.run, announcement.run, where + " run");
  out.sample_rate_hz = announcement.sample_rate_hz;
  auto* channels = allocate(out.channels, announcement.channels.size(), dynid_wire_kMaxChannels,
                            where + " channels");
  for (std::size_t c = 0; c < announcement.channels.size(); ++c) {
    put_id(channels[c].name, announcement.channels[c].name, where + " channel name");
    put_id(channels[c].unit, announcement.channels[c].unit, where + " channel unit");
  }
  auto* models =
      allocate(out.models, announcement.models.size(), dynid_wire_kMaxModels, where + " models");
  for (std::size_t m = 0; m < announcement.models.size(); ++m)
    put_model(models[m], announcement.models[m], where);
  // Preprocessing: what the wire carries of it (the filter tolerance and the unfiltered
  // channels stay the server's defaults).
  const ingest::Preprocessing& p = announcement.preprocessing;
  out.butterworth_order = p.butterworth_order;
  out.cutoff_hz = p.cutoff_hz;
  out.odmf = p.odmf;
  put_named(out.channel_noise, p.channel_noise, dynid_wire_kMaxChannels, where, "channel noise");
  return sample;
}

ingest::RunAnnouncement from_wire(const dynid_wire_RunAnnouncement& sample) {
  ingest::RunAnnouncement announcement;
  announcement.vehicle = get(sample.vehicle, "RunAnnouncement vehicle");
  announcement.run = get(sample.run, "RunAnnouncement " + announcement.vehicle + " run");
  const std::string where = "RunAnnouncement " + announcement.vehicle + "/" + announcement.run;
  announcement.sample_rate_hz = sample.sample_rate_hz;
  for (const auto& channel : elements(sample.channels, dynid_wire_kMaxChannels, where + " channels"))
    announcement.channels.push_back(
        {get(channel.name, where + " channel name"), get(channel.unit, where + " channel unit")});
  for (const auto& model : elements(sample.models, dynid_wire_kMaxModels, where + " models"))
    announcement.models.push_back(get_model(model, where));
  // Zeros: the defaults (an older car sends no preprocessing). validate() judges the rest.
  ingest::Preprocessing& p = announcement.preprocessing;
  const auto& in = sample;
  if (in.butterworth_order != 0) p.butterworth_order = in.butterworth_order;
  p.cutoff_hz = in.cutoff_hz;
  if (in.odmf != 0) p.odmf = in.odmf;
  p.channel_noise = get_named(in.channel_noise, dynid_wire_kMaxChannels, where, "channel noise");
  return announcement;
}

Sample<dynid_wire_Chunk> to_wire(const ingest::Chunk& chunk) {
  const std::string where = "Chunk " + chunk.vehicle + "/" + chunk.run + "#" +
                            std::to_string(chunk.sequence);
  const auto rows = static_cast<std::size_t>(chunk.samples.rows());
  const auto channels = static_cast<std::size_t>(chunk.samples.cols());
  if (rows > dynid_wire_kMaxRows || channels > dynid_wire_kMaxChannels)
    throw InputError(where + ": " + std::to_string(rows) + " x " + std::to_string(channels) +
                     " samples, the wire holds at most " + std::to_string(dynid_wire_kMaxRows) +
                     " rows and " + std::to_string(dynid_wire_kMaxChannels) + " channels");
  if (chunk.valid.size() != rows)
    throw InputError(where + ": " + std::to_string(chunk.valid.size()) + " valid flags for " +
                     std::to_string(rows) + " rows");
  Sample<dynid_wire_Chunk> sample;
  auto& out = sample.data;
  put_id(out.vehicle, chunk.vehicle, where + " vehicle");
  put_id(out.run, chunk.run, where + " run");
  out.sequence_number = chunk.sequence;
  out.first_sample_index = chunk.first_sample_index;
  out.rows = static_cast<uint32_t>(rows);
  out.channels = static_cast<uint32_t>(channels);
  out.checksum = chunk.checksum;
  double* data = allocate(out.data, rows * channels, dynid_wire_kMaxChunkValues, where + " data");
  if (data != nullptr) Eigen::Map<RowMajor>(data, chunk.samples.rows(), chunk.samples.cols()) = chunk.samples;
  std::uint8_t* valid = allocate(out.valid, rows, dynid_wire_kMaxRows, where + " valid flags");
  if (valid != nullptr) std::copy(chunk.valid.begin(), chunk.valid.end(), valid);
  return sample;
}

ingest::Chunk from_wire(const dynid_wire_Chunk& sample) {
  const std::string where = chunk_name(sample);
  ingest::Chunk chunk;
  chunk.vehicle = get(sample.vehicle, where + " vehicle");
  chunk.run = get(sample.run, where + " run");
  chunk.sequence = sample.sequence_number;
  chunk.first_sample_index = sample.first_sample_index;
  chunk.checksum = sample.checksum;
  if (sample.rows == 0 || sample.channels == 0)
    throw InputError(where + ": empty chunk (" + std::to_string(sample.rows) + " rows x " +
                     std::to_string(sample.channels) + " channels)");
  if (sample.rows > dynid_wire_kMaxRows || sample.channels > dynid_wire_kMaxChannels)
    throw InputError(where + ": " + std::to_string(sample.rows) + " rows x " +
                     std::to_string(sample.channels) + " channels is over the limits (" +
                     std::to_string(dynid_wire_kMaxRows) + " rows, " +
                     std::to_string(dynid_wire_kMaxChannels) + " channels)");
  const auto data = elements(sample.data, dynid_wire_kMaxChunkValues, where + " data");
  const std::uint64_t expected = std::uint64_t{sample.rows} * sample.channels;
  if (data.size() != expected)
    throw InputError(where + ": data holds " + std::to_string(data.size()) +
                     " values, rows x channels = " + std::to_string(sample.rows) + " x " +
                     std::to_string(sample.channels) + " = " + std::to_string(expected));
  const auto valid = elements(sample.valid, dynid_wire_kMaxRows, where + " valid flags");
  if (valid.size() != sample.rows)
    throw InputError(where + ": " + std::to_string(valid.size()) + " valid flags for " +
                     std::to_string(sample.rows) + " rows");
  chunk.samples = Eigen::Map<const RowMajor>(data.data(), sample.rows, sample.channels);
  chunk.valid.assign(valid.begin(), valid.end());
  return chunk;
}

}  // namespace dynid::dds
