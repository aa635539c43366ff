#include "dynid/car/vehicle_profile.hpp"

#include <cmath>
#include <functional>
#include <initializer_list>
#include <set>
#include <sstream>

#include <toml++/toml.h>

#include <dynid/ingest/model_channels.hpp>
#include <dynid/input/ids.hpp>
#include <dynid/input/input_file.hpp>
#include <dynid/model/model_needs.hpp>
#include <dynid/model/registry.hpp>

#include "dynid/model/channel_catalogue.hpp"
#include "dynid/error.hpp"

namespace dynid::car {
namespace {

// Limits of the grid's numbers: a car's CAN signals come at most at a few kHz; a chunk is one
// wire sample (dynid_wire_kMaxRows); a gap or jump limit beyond an hour is a typing error.
constexpr double kMaxRateHz = 10000.0;
constexpr std::size_t kMaxChunkRows = 10000;
constexpr double kMaxSeconds = 3600.0;

// Reads one profile file: every failure names the file, the line:column of the offending node
// when there is one, the key and the reason.
class Reader {
 public:
  explicit Reader(std::filesystem::path source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& reason,
                         const toml::node* node = nullptr) const {
    throw InputError(message(key, reason, node));
  }

  /// "<file>:<line>:<column>: <key>: <reason>" (line and column when the node has them).
  std::string message(const std::string& key, const std::string& reason,
                      const toml::node* node = nullptr) const {
    std::string where = source_.string();
    if (node != nullptr && node->source().begin.line > 0)
      where += ":" + std::to_string(node->source().begin.line) + ":" +
               std::to_string(node->source().begin.column);
    return where + ": " + input::printable_text(key + ": " + reason);  // the file's text, escaped
  }

  const toml::table& table(const toml::table& parent, const std::string& key,
                           const std::string& prefix = "") const {
    const toml::node* n = parent.get(key);
    if (n == nullptr) fail(prefix + key, "missing table");
    if (!n->is_table()) fail(prefix + key, "expected a table", n);
    return *n->as_table();
  }

  std::string string(const toml::table& t, const std::string& key, const std::string& full) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) fail(full, "missing key");
    auto v = n->value<std::string>();
    if (!n->is_string() || !v) fail(full, "expected a string", n);
    if (v->empty()) fail(full, "must not be empty", n);
    return *v;
  }

  double number(const toml::node& n, const std::string& full) const {
    if (!n.is_number()) fail(full, "expected a number", &n);
    const double v = *n.value<double>();
    if (!std::isfinite(v)) fail(full, "must be finite", &n);
    return v;
  }

  double at_most(const toml::table& t, const std::string& key, const std::string& full, double limit) const {
    const double v = positive(t, key, full);
    if (v > limit) fail(full, "must be at most " + std::to_string(limit), t.get(key));
    return v;
  }

  double positive(const toml::table& t, const std::string& key, const std::string& full) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) fail(full, "missing key");
    const double v = number(*n, full);
    if (!(v > 0.0)) fail(full, "must be > 0", n);
    return v;
  }

  std::vector<std::string> strings(const toml::node& n, const std::string& full) const {
    const toml::array* a = n.as_array();
    if (a == nullptr) fail(full, "expected an array of strings", &n);
    std::vector<std::string> out;
    for (std::size_t i = 0; i < a->size(); ++i) {
      const toml::node& e = *a->get(i);
      if (!e.is_string()) fail(full + "[" + std::to_string(i) + "]", "expected a string", &e);
      out.push_back(*e.value<std::string>());
    }
    return out;
  }

  // Typos in optional keys would silently change a car's data: every key must be known.
  void only_keys(const toml::table& t, std::initializer_list<std::string_view> known,
                 const std::string& prefix) const {
    for (const auto& [k, v] : t) {
      bool ok = false;
      for (auto name : known) ok = ok || k.str() == name;
      if (!ok) fail(prefix + std::string(k.str()), "unknown key", &v);
    }
  }

  std::filesystem::path relative_path(const std::string& p) const {
    const std::filesystem::path path(p);
    return path.is_absolute() ? path : source_.parent_path() / path;
  }

  const std::filesystem::path& source() const { return source_; }

 private:
  std::filesystem::path source_;
};

// The DBC and interfaces of a bus: [vehicle], or a type = "can" source (`prefix` its key).
void read_bus(const Reader& r, const toml::table& v, const std::string& prefix, VehicleProfile& p) {
  p.dbc_path = r.relative_path(r.string(v, "dbc", prefix + "dbc"));
  try {
    p.dbc = std::make_shared<const can::Database>(can::parse_dbc_file(p.dbc_path));
  } catch (const std::exception& e) {
    r.fail(prefix + "dbc", "cannot read the DBC '" + p.dbc_path.string() + "': " + e.what(), v.get("dbc"));
  }
  if (const toml::node* n = v.get("interfaces")) p.interfaces = r.strings(*n, prefix + "interfaces");
}

void read_vehicle(const Reader& r, const toml::table& root, VehicleProfile& p) {
  const toml::table& v = r.table(root, "vehicle");
  r.only_keys(v, {"id", "dbc", "interfaces"}, "vehicle.");
  p.vehicle = r.string(v, "id", "vehicle.id");
  if (const std::string problem = input::id_problem(p.vehicle); !problem.empty())
    r.fail("vehicle.id", "'" + input::printable(p.vehicle) + "' " + problem, v.get("id"));
  read_bus(r, v, "vehicle.", p);
}

void read_grid(const Reader& r, const toml::table& root, VehicleProfile& p) {
  const toml::table& g = r.table(root, "grid");
  r.only_keys(g, {"rate_hz", "chunk_seconds", "max_gap_periods", "max_time_jump"}, "grid.");
  p.rate_hz = r.at_most(g, "rate_hz", "grid.rate_hz", kMaxRateHz);
  const double seconds = r.positive(g, "chunk_seconds", "grid.chunk_seconds");
  const double rows = seconds * p.rate_hz;
  if (std::abs(rows - std::round(rows)) > 1e-9 * rows || std::round(rows) < 1.0)
    r.fail("grid.chunk_seconds", "must be a whole number (>= 1) of grid periods (1/rate_hz), got " +
                                     std::to_string(rows) + " periods", g.get("chunk_seconds"));
  if (rows > static_cast<double>(kMaxChunkRows))
    r.fail("grid.chunk_seconds", std::to_string(rows) + " rows per chunk, at most " + std::to_string(kMaxChunkRows),
           g.get("chunk_seconds"));
  p.chunk_rows = static_cast<std::size_t>(std::llround(rows));
  if (g.contains("max_gap_periods")) {
    p.max_gap_periods = r.at_most(g, "max_gap_periods", "grid.max_gap_periods", kMaxSeconds);
    if (p.max_gap_periods < 1.0)
      r.fail("grid.max_gap_periods", "must be >= 1 (a gap shorter than one period is no gap)",
             g.get("max_gap_periods"));
  }
  if (g.contains("max_time_jump")) p.max_time_jump = r.at_most(g, "max_time_jump", "grid.max_time_jump", kMaxSeconds);
}

void read_spool(const Reader& r, const toml::table& root, VehicleProfile& p) {
  const toml::table& s = r.table(root, "spool");
  r.only_keys(s, {"directory", "max_bytes"}, "spool.");
  p.spool_directory = r.relative_path(r.string(s, "directory", "spool.directory"));
  const toml::node* n = s.get("max_bytes");
  if (n == nullptr) r.fail("spool.max_bytes", "missing key");
  if (!n->is_integer()) r.fail("spool.max_bytes", "expected an integer (bytes)", n);
  const auto bytes = *n->value<std::int64_t>();
  if (bytes <= 0) r.fail("spool.max_bytes", "must be > 0", n);
  p.spool_max_bytes = static_cast<std::uint64_t>(bytes);
}

model::Constants read_constants(const Reader& r, const toml::table& t, const std::string& prefix) {
  model::Constants c;
  for (const auto& [k, v] : t) c[std::string(k.str())] = r.number(v, prefix + std::string(k.str()));
  return c;
}

void read_models(const Reader& r, const toml::table& root, VehicleProfile& p) {
  const toml::node* n = root.get("models");
  if (n == nullptr) return;  // a profile may only stream (no identification on the server yet)
  const toml::array* models = n->as_array();
  if (models == nullptr || !models->is_array_of_tables())
    r.fail("models", "expected an array of tables ([[models]])", n);
  for (std::size_t i = 0; i < models->size(); ++i) {
    const std::string key = "models[" + std::to_string(i) + "]";
    const toml::table& m = *models->get(i)->as_table();
    r.only_keys(m, {"name", "effects", "constants"}, key + ".");
    ingest::ModelSpec spec;
    spec.model = r.string(m, "name", key + ".name");
    spec.constants = p.constants;
    if (const toml::node* c = m.get("constants")) {
      if (!c->is_table()) r.fail(key + ".constants", "expected a table", c);
      for (auto& [name, value] : read_constants(r, *c->as_table(), key + ".constants."))
        spec.constants[name] = value;
    }
    if (const toml::node* e = m.get("effects")) spec.effects = r.strings(*e, key + ".effects");
    try {
      (void)model::make_model(spec.model, spec.constants);  // unknown model, missing constants
    } catch (const InputError& e) {
      r.fail(key + ".name", e.what(), m.get("name"));
    }
    p.models.push_back(std::move(spec));
  }
}

// A gain term: a number, or the name of a [constants] entry (e.g. "steering_ratio").
double gain_term(const Reader& r, const VehicleProfile& p, const toml::node& n, const std::string& key) {
  double v = 0.0;
  if (n.is_string()) {
    const std::string name = *n.value<std::string>();
    auto it = p.constants.find(name);
    if (it == p.constants.end()) r.fail(key, "no constant '" + name + "' in [constants]", &n);
    v = it->second;
  } else {
    v = r.number(n, key);
  }
  if (v == 0.0) r.fail(key, "must not be 0", &n);
  return v;
}

// "signal" or "signals", whichever the mapping uses, and its node.
std::string signals_key(const toml::table& t, const std::string& key) {
  return key + (t.contains("signal") ? ".signal" : ".signals");
}
const toml::node* signals_node(const toml::table& t) {
  return t.contains("signal") ? t.get("signal") : t.get("signals");
}

LinearConversion input_conversion(const Reader& r, const toml::table& t, const std::string& key,
                                  const ChannelMapping& m, const can::Signal& s, std::string& unit) {
  if (t.contains("factor") || t.contains("offset")) {
    const toml::node* f = t.get("factor");
    const toml::node* o = t.get("offset");
    unit.clear();
    return {f ? r.number(*f, key + ".factor") : 1.0, o ? r.number(*o, key + ".offset") : 0.0};
  }
  unit = s.unit;
  if (const toml::node* u = t.get("dbc_unit")) {
    if (!u->is_string()) r.fail(key + ".dbc_unit", "expected a string", u);
    unit = *u->value<std::string>();
  }
  const std::string what = "signal " + m.message + "." + s.name;
  if (unit.empty()) {
    // DBC files leave counts and states unitless; that is a unit only for a unitless channel.
    if (m.unit == "-") return {};
    r.fail(signals_key(t, key), "missing unit: " + what + " has no unit in the DBC and channel '" +
                                    m.channel + "' needs '" + m.unit + "'; give dbc_unit or factor/offset",
           signals_node(t));
  }
  auto c = conversion(unit, m.unit);
  if (!c)
    r.fail(signals_key(t, key), "cannot convert " + what + " from '" + unit + "' to '" + m.unit +
                                    "' (channel '" + m.channel + "'); give dbc_unit or factor/offset",
           signals_node(t));
  return *c;
}

std::vector<std::string> signal_names(const Reader& r, const toml::table& t, const std::string& key) {
  const toml::node* one = t.get("signal");
  const toml::node* many = t.get("signals");
  if ((one == nullptr) == (many == nullptr))
    r.fail(key, "give exactly one of 'signal' or 'signals'", one ? one : many);
  if (one != nullptr) return {r.string(t, "signal", key + ".signal")};
  auto names = r.strings(*many, key + ".signals");
  if (names.empty()) r.fail(key + ".signals", "must not be empty", many);
  return names;
}

double read_sign(const Reader& r, const toml::table& t, const std::string& key) {
  const toml::node* s = t.get("sign");
  if (s == nullptr) return 1.0;
  const auto v = s->value<std::int64_t>();
  if (!s->is_integer() || (*v != 1 && *v != -1)) r.fail(key + ".sign", "expected 1 or -1", s);
  return static_cast<double>(*v);
}

// "a", "a and b", "a, b and c".
std::string listing(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i)
    out += (i == 0 ? "" : (i + 1 == items.size() ? " and " : ", ")) + items[i];
  return out;
}

// The one usable message of the DBC called `name`; else the reason, with the DBC's lines.
const can::Message* dbc_message(const Reader& r, const VehicleProfile& p, const std::string& name,
                                const std::string& key, const toml::table& t) {
  const std::string file = p.dbc_path.filename().string();
  const auto found = p.dbc->find_messages(name);
  if (found.empty())
    r.fail(key + ".message", "unknown DBC message '" + name + "' in " + file, t.get("message"));
  if (found.size() > 1) {
    std::vector<std::string> ids;
    for (const can::Message* m : found)
      ids.push_back(can::id_text(*m) + " (line " + std::to_string(m->line) + ")");
    r.fail(key + ".message",
           "DBC message name '" + name + "' is ambiguous: " + file + " has " +
               std::to_string(found.size()) + " messages of that name, ids " + listing(ids),
           t.get("message"));
  }
  if (!found[0]->usable())
    r.fail(key + ".message", "DBC message '" + name + "' cannot be decoded: " + found[0]->problem,
           t.get("message"));
  return found[0];
}

// A channel's catalogue name and its SI unit.
ChannelMapping named_channel(const Reader& r, const toml::table& t, const std::string& key) {
  ChannelMapping m;
  m.channel = r.string(t, "name", key + ".name");
  const auto unit = model::channel_unit(m.channel);
  if (!unit)
    r.fail(key + ".name", "unknown channel '" + m.channel + "' (see docs/CHANNELS.md)",
           t.get("name"));
  m.unit = *unit;
  return m;
}

// `constant = <value>` in the channel's SI unit, instead of a message and signals: the value must
// be one the channel can physically take (the channel health's range, docs/CHANNELS.md).
ChannelMapping constant_channel(const Reader& r, const toml::table& t, const std::string& key) {
  r.only_keys(t, {"name", "constant"}, key + ".");
  ChannelMapping m = named_channel(r, t, key);
  const double value = r.number(*t.get("constant"), key + ".constant");
  if (const auto physics = model::channel_physics(m.channel);
      physics && (value < physics->lower || value > physics->upper)) {
    std::ostringstream reason;
    reason << "channel '" << m.channel << "' cannot be " << value << " " << m.unit
           << " (its physical range is " << physics->lower << " to " << physics->upper << " "
           << m.unit << ")";
    r.fail(key + ".constant", reason.str(), t.get("constant"));
  }
  m.message = "constant";
  m.constant = value;
  // Its samples come with every frame that carries a channel of the profile, irregular as the bus
  // is: no gap rule of its own, so a row's validity is that of the measured channels.
  m.max_gap = kMaxSeconds;
  return m;
}

ChannelMapping read_channel(const Reader& r, const VehicleProfile& p, const toml::table& t,
                            const std::string& key, bool in_source = false) {
  if (!in_source && t.contains("constant")) return constant_channel(r, t, key);
  if (in_source)  // a channel of a second bus (type = "can" source)
    r.only_keys(t, {"name", "message", "signal", "signals", "combine", "dbc_unit", "factor", "offset",
                    "scale", "divide_by", "sign", "max_gap", "interpolation", "replaces_bus"},
                key + ".");
  else
    r.only_keys(t, {"name", "message", "signal", "signals", "combine", "dbc_unit", "factor", "offset",
                    "scale", "divide_by", "sign", "max_gap", "interpolation"},
                key + ".");
  ChannelMapping m = named_channel(r, t, key);
  m.message = r.string(t, "message", key + ".message");
  m.dbc_message = dbc_message(r, p, m.message, key, t);
  for (const auto& name : signal_names(r, t, key)) {
    auto index = m.dbc_message->signal_index(name);
    if (const auto a = m.dbc_message->ambiguous_signals.find(name);
        a != m.dbc_message->ambiguous_signals.end()) {
      std::vector<std::string> lines;
      for (const std::size_t line : a->second) lines.push_back(std::to_string(line));
      r.fail(signals_key(t, key),
             "DBC signal '" + name + "' of message '" + m.message + "' is ambiguous: " +
                 p.dbc_path.filename().string() + " defines it " + std::to_string(lines.size()) +
                 " times, at lines " + listing(lines) + " (under different multiplexer values)",
             signals_node(t));
    }
    if (!index)
      r.fail(signals_key(t, key), "unknown DBC signal '" + name + "' in message '" + m.message + "' of " +
                                      p.dbc_path.filename().string(),
             signals_node(t));
    if (const std::string& never = m.dbc_message->signals[*index].never_present; !never.empty())
      r.fail(signals_key(t, key),
             "DBC signal '" + name + "' of message '" + m.message +
                 "' never gets a value (channel '" + m.channel +
                 "' would be invalid in every row): " + never,
             signals_node(t));
    SignalInput in{name, *index, {}, {}};
    in.to_si = input_conversion(r, t, key, m, m.dbc_message->signals[*index], in.dbc_unit);
    m.inputs.push_back(std::move(in));
  }
  if (const toml::node* c = t.get("combine")) {
    const auto v = c->value<std::string>();
    if (!c->is_string() || (*v != "sum" && *v != "mean"))
      r.fail(key + ".combine", "expected \"sum\" or \"mean\"", c);
    m.combine = *v == "mean" ? Combine::Mean : Combine::Sum;
  }
  if (const toml::node* s = t.get("scale")) m.gain *= gain_term(r, p, *s, key + ".scale");
  if (const toml::node* d = t.get("divide_by")) m.gain /= gain_term(r, p, *d, key + ".divide_by");
  m.gain *= read_sign(r, t, key);
  if (t.contains("max_gap")) m.max_gap = r.at_most(t, "max_gap", key + ".max_gap", kMaxSeconds);
  if (const toml::node* i = t.get("interpolation")) {
    const auto v = i->value<std::string>();
    if (!i->is_string() || (*v != "linear" && *v != "cubic"))
      r.fail(key + ".interpolation", "expected \"linear\" or \"cubic\"", i);
    m.interpolation = *v == "cubic" ? Interpolation::kCubic : Interpolation::kLinear;
  }
  return m;
}

void read_channels(const Reader& r, const toml::table& root, VehicleProfile& p) {
  const toml::node* n = root.get("channels");
  if (n == nullptr) r.fail("channels", "missing: at least one [[channels]] mapping");
  const toml::array* a = n->as_array();
  if (a == nullptr || !a->is_array_of_tables() || a->empty())
    r.fail("channels", "expected a non-empty array of tables ([[channels]])", n);
  std::set<std::string> seen;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const std::string key = "channels[" + std::to_string(i) + "]";
    const toml::table& t = *a->get(i)->as_table();
    if (!seen.insert(r.string(t, "name", key + ".name")).second)
      r.fail(key + ".name", "duplicate channel '" + *t["name"].value<std::string>() + "'", t.get("name"));
    p.channels.push_back(read_channel(r, p, t, key));
  }
}

bool read_bool(const Reader& r, const toml::table& t, const std::string& name, const std::string& key) {
  const toml::node* n = t.get(name);
  if (n == nullptr) return false;
  if (!n->is_boolean()) r.fail(key + "." + name, "expected true or false", n);
  return *n->value<bool>();
}

SourceChannel read_source_channel(const Reader& r, const VehicleProfile& p, const toml::table& t,
                                  const std::string& key) {
  r.only_keys(t, {"column", "derived", "channel", "unit", "scale", "sign", "max_gap", "replaces_bus"}, key + ".");
  SourceChannel c;
  c.channel = r.string(t, "channel", key + ".channel");
  const auto unit = model::channel_unit(c.channel);
  if (!unit) r.fail(key + ".channel", "unknown channel '" + c.channel + "' (see docs/CHANNELS.md)", t.get("channel"));
  c.unit = *unit;
  if (t.contains("derived")) {  // a quantity of the source's ECEF pose, in SI already
    if (t.contains("column") || t.contains("unit"))
      r.fail(key + ".derived", "a derived channel has no column and no unit", t.get("derived"));
    c.derived = r.string(t, "derived", key + ".derived");
    const char* derived_unit = c.derived == "grade" ? "rad" : c.derived == "speed" ? "m/s" : nullptr;
    if (derived_unit == nullptr)
      r.fail(key + ".derived", "unknown derived quantity '" + c.derived + "' (\"grade\" or \"speed\")", t.get("derived"));
    if (c.unit != derived_unit)
      r.fail(key + ".channel", "the " + c.derived + " is in " + derived_unit + ", channel '" + c.channel + "' in " + c.unit,
             t.get("channel"));
    c.column = c.derived;
    c.given_unit = c.unit;
    c.to_si = *conversion(c.unit, c.unit);
    if (const toml::node* s = t.get("scale")) c.gain *= gain_term(r, p, *s, key + ".scale");
    c.gain *= read_sign(r, t, key);
    if (t.contains("max_gap")) c.max_gap = r.at_most(t, "max_gap", key + ".max_gap", kMaxSeconds);
    c.replaces_bus = read_bool(r, t, "replaces_bus", key);
    return c;
  }
  c.column = r.string(t, "column", key + ".column");
  if (!t.contains("unit"))
    r.fail(key + ".unit", "missing unit: give the unit of column '" + c.column + "' (channel '" + c.channel +
                              "' is in '" + c.unit + "'; \"-\" for a unitless column)");
  c.given_unit = r.string(t, "unit", key + ".unit");
  const auto conv = conversion(c.given_unit, c.unit);
  if (!conv)
    r.fail(key + ".unit", "cannot convert column '" + c.column + "' from '" + c.given_unit + "' to '" + c.unit +
                              "' (channel '" + c.channel + "')", t.get("unit"));
  c.to_si = *conv;
  if (const toml::node* s = t.get("scale")) c.gain *= gain_term(r, p, *s, key + ".scale");
  c.gain *= read_sign(r, t, key);
  if (t.contains("max_gap")) c.max_gap = r.at_most(t, "max_gap", key + ".max_gap", kMaxSeconds);
  c.replaces_bus = read_bool(r, t, "replaces_bus", key);
  return c;
}

// ecef = { position = ["x", "y", "z"], velocity = ["vx", "vy", "vz"] }: three column names each.
AuxiliarySourceSpec::Ecef read_ecef(const Reader& r, const toml::table& src, const std::string& key) {
  const toml::node* n = src.get("ecef");
  if (!n->is_table()) r.fail(key + ".ecef", "expected a table { position = [...], velocity = [...] }", n);
  const toml::table& t = *n->as_table();
  r.only_keys(t, {"position", "velocity"}, key + ".ecef.");
  AuxiliarySourceSpec::Ecef e;
  const auto three = [&](const char* name, std::array<std::string, 3>& out) {
    const toml::node* a = t.get(name);
    const toml::array* arr = a == nullptr ? nullptr : a->as_array();
    if (arr == nullptr || arr->size() != 3)
      r.fail(key + ".ecef." + name, "expected three column names (x, y, z)", a);
    for (std::size_t i = 0; i < 3; ++i) {
      const auto v = arr->get(i)->value<std::string>();
      if (!v) r.fail(key + ".ecef." + name, "expected three column names (x, y, z)", a);
      out[i] = *v;
    }
  };
  three("position", e.position);
  three("velocity", e.velocity);
  return e;
}

SourceClockRelation read_clock(const Reader& r, const toml::table& src, const std::string& key) {
  const toml::node* n = src.get("clock");
  if (n == nullptr) r.fail(key + ".clock", "missing: give clock = { offset = <s> } or clock = { estimate_from = "
                                           "\"<channel of this source>\", reference = \"<bus channel>\" }");
  if (!n->is_table()) r.fail(key + ".clock", "expected a table", n);
  const toml::table& t = *n->as_table();
  r.only_keys(t, {"offset", "estimate_from", "reference", "reference_derivative", "max_offset"}, key + ".clock.");
  SourceClockRelation c;
  if (const toml::node* o = t.get("offset")) {
    if (t.contains("estimate_from") || t.contains("reference"))
      r.fail(key + ".clock", "give either offset or estimate_from/reference, not both", n);
    c.offset = r.number(*o, key + ".clock.offset");
    return c;
  }
  c.estimate_from = r.string(t, "estimate_from", key + ".clock.estimate_from");
  c.reference = r.string(t, "reference", key + ".clock.reference");
  c.reference_derivative = read_bool(r, t, "reference_derivative", key + ".clock");
  if (t.contains("max_offset")) c.max_offset = r.at_most(t, "max_offset", key + ".clock.max_offset", 60.0);
  return c;
}

void read_sources(const Reader& r, const toml::table& root, VehicleProfile& p) {
  const toml::node* n = root.get("sources");
  if (n == nullptr) return;
  const toml::array* a = n->as_array();
  if (a == nullptr || !a->is_array_of_tables()) r.fail("sources", "expected an array of tables ([[sources]])", n);
  std::set<std::string> names;
  std::set<std::string> channels;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const std::string key = "sources[" + std::to_string(i) + "]";
    const toml::table& t = *a->get(i)->as_table();
    AuxiliarySourceSpec s;
    s.type = r.string(t, "type", key + ".type");
    if (s.type != "csv" && s.type != "can" && s.type != "mdf4")
      r.fail(key + ".type", "unknown source type '" + s.type + "' (\"csv\", \"mdf4\" or \"can\")",
             t.get("type"));
    if (s.type == "csv")
      r.only_keys(t, {"name", "type", "file", "time_column", "time_unit", "clock", "wait", "ecef", "channels"}, key + ".");
    else if (s.type == "mdf4")
      r.only_keys(t, {"name", "type", "file", "clock", "channels"}, key + ".");
    else
      r.only_keys(t, {"name", "type", "file", "dbc", "interfaces", "clock", "channels"}, key + ".");
    s.name = r.string(t, "name", key + ".name");
    if (const std::string problem = input::id_problem(s.name); !problem.empty())
      r.fail(key + ".name", "'" + input::printable(s.name) + "' " + problem, t.get("name"));
    if (!names.insert(s.name).second) r.fail(key + ".name", "duplicate source '" + s.name + "'", t.get("name"));
    if (t.contains("file")) s.file = r.relative_path(r.string(t, "file", key + ".file"));
    std::shared_ptr<VehicleProfile> bus;
    if (s.type == "csv") {
      s.time_column = r.string(t, "time_column", key + ".time_column");
      const std::string unit = r.string(t, "time_unit", key + ".time_unit");
      if (unit == "s") s.time_scale = 1.0;
      else if (unit == "ms") s.time_scale = 1e-3;
      else if (unit == "us") s.time_scale = 1e-6;
      else if (unit == "ns") s.time_scale = 1e-9;
      else r.fail(key + ".time_unit", "expected \"s\", \"ms\", \"us\" or \"ns\"", t.get("time_unit"));
      if (t.contains("ecef")) s.ecef = read_ecef(r, t, key);
    } else if (s.type == "can") {
      bus = std::make_shared<VehicleProfile>();
      bus->source = p.source;
      bus->vehicle = p.vehicle;
      bus->constants = p.constants;
      read_bus(r, t, key + ".", *bus);
    }
    s.clock = read_clock(r, t, key);
    if (t.contains("wait")) s.wait = r.at_most(t, "wait", key + ".wait", kMaxSourceWait);
    const toml::node* cn = t.get("channels");
    const toml::array* ca = cn == nullptr ? nullptr : cn->as_array();
    if (ca == nullptr || !ca->is_array_of_tables() || ca->empty())
      r.fail(key + ".channels", "expected a non-empty array of tables ([[sources.channels]])", cn);
    for (std::size_t j = 0; j < ca->size(); ++j) {
      const std::string ckey = key + ".channels[" + std::to_string(j) + "]";
      const toml::table& ct = *ca->get(j)->as_table();
      SourceChannel c;
      if (bus) {  // a mapping of the second bus, as [[channels]]
        ChannelMapping m = read_channel(r, *bus, ct, ckey, true);
        c.column = m.message;
        c.channel = m.channel;
        c.unit = m.unit;
        c.max_gap = m.max_gap;
        c.interpolation = m.interpolation;
        c.replaces_bus = read_bool(r, ct, "replaces_bus", ckey);
        bus->channels.push_back(std::move(m));
      } else {
        c = read_source_channel(r, p, ct, ckey);
        if (s.type == "mdf4" && !c.derived.empty())
          r.fail(ckey + ".derived",
                 "an MDF4 source's channels are its file's channels, named by `column`",
                 ct.get("derived"));
      }
      if (!channels.insert(c.channel).second)
        r.fail(ckey + ".channel", "channel '" + c.channel + "' comes from two sources", ct.get("channel"));
      bool on_bus = false;
      for (const auto& m : p.channels) on_bus = on_bus || m.channel == c.channel;
      if (on_bus && !c.replaces_bus)
        r.fail(ckey + ".channel", "channel '" + c.channel + "' is also a bus channel ([[channels]]): say "
                                  "replaces_bus = true to take it from this source when the source is given",
               ct.get("channel"));
      if (!on_bus && c.replaces_bus)
        r.fail(ckey + ".replaces_bus", "no bus channel '" + c.channel + "' to replace", ct.get("replaces_bus"));
      s.channels.push_back(std::move(c));
    }
    s.bus = bus;
    for (const auto& c : s.channels)
      if (!c.derived.empty() && !s.ecef)
        r.fail(key + ".ecef", "channel '" + c.channel + "' is derived (" + c.derived +
                                  "): give the ECEF columns, ecef = { position = [...], velocity = [...] }");
    if (!s.clock.offset) {
      bool mine = false;
      for (const auto& c : s.channels) mine = mine || c.channel == s.clock.estimate_from;
      if (!mine) r.fail(key + ".clock.estimate_from", "'" + s.clock.estimate_from + "' is not a channel of this source");
      bool known = false;
      for (const auto& m : p.channels) known = known || m.channel == s.clock.reference;
      if (!known) r.fail(key + ".clock.reference", "'" + s.clock.reference + "' is not a bus channel ([[channels]])");
    }
    p.sources.push_back(std::move(s));
  }
}

// Optional; absent keys keep the server's defaults (ingest::Preprocessing: DYCARO's).
void read_preprocessing(const Reader& r, const toml::table& root, VehicleProfile& p) {
  if (!root.contains("preprocessing")) return;
  const toml::table& t = r.table(root, "preprocessing");
  r.only_keys(t, {"butterworth_order", "cut_off_hz", "odmf", "noise"}, "preprocessing.");
  ingest::Preprocessing& out = p.preprocessing;
  const auto integer = [&](const char* key, std::int64_t lowest, std::int64_t highest) {
    const toml::node* n = t.get(key);
    const std::string full = std::string("preprocessing.") + key;
    if (!n->is_integer()) r.fail(full, "expected an integer", n);
    const auto v = *n->value<std::int64_t>();
    if (v < lowest || v > highest)
      r.fail(full, "must be within " + std::to_string(lowest) + ".." + std::to_string(highest), n);
    return static_cast<int>(v);
  };
  if (t.contains("butterworth_order")) out.butterworth_order = integer("butterworth_order", 1, 8);
  if (t.contains("odmf")) out.odmf = integer("odmf", 1, 1000);
  if (t.contains("cut_off_hz")) {
    out.cutoff_hz = r.positive(t, "cut_off_hz", "preprocessing.cut_off_hz");
    if (out.cutoff_hz >= 0.5 * p.rate_hz)
      r.fail("preprocessing.cut_off_hz", "must be below the grid's Nyquist frequency " +
                                             std::to_string(0.5 * p.rate_hz) + " Hz", t.get("cut_off_hz"));
  }
  if (!t.contains("noise")) return;
  const toml::table& noise = r.table(t, "noise", "preprocessing.");
  for (const auto& [key, node] : noise) {
    const std::string channel(key.str());
    const std::string full = "preprocessing.noise." + channel;
    bool mapped = false;
    for (const auto& c : p.channels) mapped = mapped || c.channel == channel;
    if (!mapped) r.fail(full, "'" + channel + "' is not a channel of this profile", &node);
    out.channel_noise[channel] = r.positive(noise, channel, full);
  }
}

}  // namespace

double ChannelMapping::value(const std::vector<double>& physical_by_signal) const {
  double sum = 0.0;
  for (const auto& in : inputs) sum += in.to_si.apply(physical_by_signal[in.index]);
  if (combine == Combine::Mean) sum /= static_cast<double>(inputs.size());
  return gain * sum;
}

bool VehicleProfile::accepts_interface(std::string_view name) const {
  if (interfaces.empty()) return true;
  for (const auto& i : interfaces)
    if (i == name) return true;
  return false;
}

ingest::RunAnnouncement VehicleProfile::announcement(const std::string& run) const {
  ingest::RunAnnouncement a;
  a.vehicle = vehicle;
  a.run = run;
  a.sample_rate_hz = rate_hz;
  for (const auto& c : channels) a.channels.push_back({c.channel, c.unit});
  a.models = models;
  a.preprocessing = preprocessing;
  return a;
}

namespace {

// "'d_yaw_rate' (the derivative of 'yaw_rate')": a derived channel says what it is made from.
std::string described(const std::vector<std::string>& channels) {
  std::vector<std::string> out;
  for (const std::string& c : channels)
    out.push_back("'" + c + "'" +
                  (c.rfind("d_", 0) == 0 ? " (the derivative of '" + c.substr(2) + "')" : ""));
  return listing(out);
}

// Declared sources not in this run that have one of `channels` (or its base, for a d_<x>).
std::string sources_hint(const VehicleProfile& p, const std::vector<std::string>& channels,
                         const std::function<bool(const std::string&)>& provided) {
  std::vector<std::string> hints;
  for (const AuxiliarySourceSpec& s : p.sources)
    for (const SourceChannel& sc : s.channels)
      for (const std::string& c : channels)
        if ((c == sc.channel || c == "d_" + sc.channel) && !provided(sc.channel)) {
          hints.push_back("source '" + s.name + "' has '" + sc.channel + "' (--source " + s.name +
                          "=FILE)");
          break;
        }
  return hints.empty() ? "" : "; " + listing(hints);
}

}  // namespace

std::string lacking_channels(const VehicleProfile& p, std::size_t i) {
  const ingest::RunAnnouncement run = p.announcement("r");
  const std::function<bool(const std::string&)> provided = [&](const std::string& c) {
    return ingest::run_provides(run, c);
  };
  const ingest::ModelSpec& spec = p.models.at(i);
  const ingest::ChannelGaps gaps =
      ingest::channel_gaps(*model::make_model(spec.model, spec.constants), spec, provided);
  if (gaps.missing.empty()) return {};
  std::string line = "models[" + std::to_string(i) + "] '" + spec.model + "' needs " +
                     described(gaps.missing) + ", which this run does not have";
  if (!gaps.optional_absent.empty())
    line += " (it would also read " + described(gaps.optional_absent) + ", optional, absent too)";
  return line + sources_hint(p, gaps.missing, provided);
}

std::vector<std::string> models_lacking_channels(const VehicleProfile& p) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < p.models.size(); ++i)
    if (std::string line = lacking_channels(p, i); !line.empty()) out.push_back(std::move(line));
  return out;
}

namespace {

// Every string value of the document: a gain term names its constant by one (gain_term).
void collect_strings(const toml::node& node, std::set<std::string>& out) {
  if (const auto* s = node.as_string()) out.insert(s->get());
  if (const auto* t = node.as_table())
    for (const auto& [key, value] : *t) collect_strings(value, out);
  if (const auto* a = node.as_array())
    for (const auto& value : *a) collect_strings(value, out);
}

std::set<std::string> constants_read(const std::string& model) {
  std::set<std::string> out;
  for (const model::ConstantUse& use : model::model_needs(model).constants) out.insert(use.name);
  return out;
}

std::string unread_reason(const std::string& name, const std::string& readers) {
  if (model::channel_unit(name))
    return "'" + name + "' is a channel, not a constant: constants never stand in for a channel " +
           "(map it under [[channels]], or give it there as `constant = <value>`)";
  return "read by " + readers + ": it has no effect (a misspelling? `dynid models` lists what " +
         "each model reads)";
}

// A constant nobody reads is a misspelling or a channel given as a constant: said at load, not
// silently ignored (the profile still loads: it may serve models or tools to come).
void warn_unread_constants(const Reader& r, const toml::table& root, VehicleProfile& p) {
  std::set<std::string> named, read;
  if (const toml::node* channels = root.get("channels")) collect_strings(*channels, named);
  if (const toml::node* sources = root.get("sources")) collect_strings(*sources, named);
  const toml::array* models = root.get("models") ? root.get("models")->as_array() : nullptr;
  for (std::size_t i = 0; i < p.models.size(); ++i) {
    const std::set<std::string> own = constants_read(p.models[i].model);
    read.insert(own.begin(), own.end());
    const toml::table* entry = models != nullptr ? models->get(i)->as_table() : nullptr;
    const toml::node* table = entry != nullptr ? entry->get("constants") : nullptr;
    if (table == nullptr || !table->is_table()) continue;
    for (const auto& [key, value] : *table->as_table())
      if (const std::string name(key.str()); !own.contains(name))
        p.warnings.push_back(r.message(
            "models[" + std::to_string(i) + "].constants." + name,
            unread_reason(name, "no constant of model '" + p.models[i].model + "'"), &value));
  }
  const toml::node* constants = root.get("constants");
  if (constants == nullptr || !constants->is_table()) return;
  for (const auto& [key, value] : *constants->as_table())
    if (const std::string name(key.str()); !read.contains(name) && !named.contains(name))
      p.warnings.push_back(r.message(
          "constants." + name,
          unread_reason(name, "no model of this profile and named by no channel's gain"), &value));
}

}  // namespace

VehicleProfile parse_vehicle_profile(std::string_view text, const std::filesystem::path& source) {
  const Reader r(source);
  toml::table root;
  try {
    root = toml::parse(text, source.string());
  } catch (const toml::parse_error& e) {
    std::ostringstream msg;
    msg << source.string() << ":" << e.source().begin.line << ":" << e.source().begin.column
        << ": TOML syntax: " << e.description();
    throw InputError(msg.str());
  }
  r.only_keys(root, {"vehicle", "grid", "spool", "constants", "models", "channels", "sources", "preprocessing"}, "");
  VehicleProfile p;
  p.source = source;
  read_vehicle(r, root, p);
  read_grid(r, root, p);
  read_spool(r, root, p);
  if (root.contains("constants")) p.constants = read_constants(r, r.table(root, "constants"), "constants.");
  read_models(r, root, p);
  read_channels(r, root, p);
  read_sources(r, root, p);
  read_preprocessing(r, root, p);
  warn_unread_constants(r, root, p);
  return p;
}

VehicleProfile load_vehicle_profile(const std::filesystem::path& path) {
  return parse_vehicle_profile(input::read_input_file(path, "vehicle profile"), path);
}

}  // namespace dynid::car
