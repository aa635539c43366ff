#include "dynid/cli/catalogue_view.hpp"

#include <fmt/format.h>

#include "dynid/model/model_needs.hpp"
#include "dynid/model/registry.hpp"

namespace dynid::cli {
namespace {

using model::ModelNeeds;

// "a, b, c" of the names `pick` chooses, or `none`.
template <typename Items, typename Pick>
std::string names(const Items& items, Pick pick, const std::string& none = "none") {
  std::string out;
  for (const auto& item : items)
    if (const std::string name = pick(item); !name.empty()) out += (out.empty() ? "" : ", ") + name;
  return out.empty() ? none : out;
}

std::string required_channels(const ModelNeeds& m) {
  return names(m.channels, [](const model::ChannelNeed& c) { return c.optional ? "" : c.name; });
}

std::string optional_channels(const ModelNeeds& m) {
  return names(m.channels, [](const model::ChannelNeed& c) { return c.optional ? c.name : ""; });
}

std::string required_constants(const ModelNeeds& m) {
  return names(m.constants, [](const model::ConstantUse& c) { return c.required ? c.name : ""; });
}

std::string optional_constants(const ModelNeeds& m) {
  return names(m.constants, [](const model::ConstantUse& c) {
    if (c.required) return std::string();
    return c.fallback ? fmt::format("{} (default {:g})", c.name, *c.fallback) : c.name;
  });
}

std::string parameter_names(const ModelNeeds& m) {
  return names(m.parameters, [](const model::ParameterInfo& p) { return p.name; });
}

// `head` then `text`, wrapped after its `breaks` (", " in a list, " " in prose) so that no line
// is wider than kColumns, continued under `indent` spaces.
constexpr std::size_t kColumns = 100;

std::string wrapped(const std::string& head, const std::string& list, std::size_t indent_size,
                    const std::string& breaks) {
  const std::string indent(indent_size, ' ');
  std::string out = head;
  std::size_t width = head.size();
  for (std::size_t start = 0; start < list.size();) {
    std::size_t end = list.find(breaks, start);
    end = end == std::string::npos ? list.size() : end + breaks.size();
    const std::string item = list.substr(start, end - start);
    // The item's trailing space may pass the margin: it is dropped at the break.
    const std::size_t visible = item.back() == ' ' ? item.size() - 1 : item.size();
    if (width > head.size() && width + visible > kColumns) {
      while (out.back() == ' ') out.pop_back();
      out += "\n" + indent;
      width = indent.size();
    }
    out += item;
    width += item.size();
    start = end;
  }
  return out + "\n";
}

// "  <label> <list>", the list under column 22.
std::string field(const std::string& label, const std::string& list) {
  std::string head = "  " + label;
  head.resize(22, ' ');
  return wrapped(head, list, head.size(), ", ");
}

std::string model_block(const ModelNeeds& m) {
  const std::string effects = names(m.effects, [](const model::Effect& e) { return e.name; });
  return m.model + "\n" + field("channels:", required_channels(m)) +
         field("optional channels:", optional_channels(m)) +
         field("constants:", required_constants(m)) +
         field("optional constants:", optional_constants(m)) +
         field("identifies:", parameter_names(m)) +
         field("effects:", effects + " (`dynid effects --model " + m.model + "`)");
}

}  // namespace

std::string models_text(const std::string& model) {
  if (!model.empty()) return model_block(model::model_needs(model));
  std::string out;
  for (const ModelNeeds& m : model::all_model_needs())
    out += (out.empty() ? "" : "\n") + model_block(m);
  return out;
}

std::string models_markdown() {
  std::string out =
      "| model | channels | optional channels | constants | optional constants |\n"
      "|---|---|---|---|---|\n";
  for (const ModelNeeds& m : model::all_model_needs())
    out += fmt::format("| `{}` | {} | {} | {} | {} |\n", m.model, required_channels(m),
                       optional_channels(m), required_constants(m), optional_constants(m));
  return out;
}

std::string effects_text(const std::string& model) {
  const ModelNeeds m = model::model_needs(model);
  std::string out = m.model + ": candidate effects (a profile's [[models]] effects, `--effects`)\n";
  for (const model::Effect& e : m.effects) {
    out += wrapped("  " + e.name + ": ", e.description, 4, " ");
    out += wrapped("    adds channels: ", names(e.channels, [](const std::string& c) { return c; }),
                   19, ", ");
    out += wrapped("    parameters:    ",
                   names(e.parameters,
                         [](const model::ParameterInfo& p) {
                           return p.unit.empty() || p.unit == "-" ? p.name
                                                                  : p.name + " (" + p.unit + ")";
                         }),
                   19, ", ");
    if (!e.separated_by.empty()) out += wrapped("    told apart by: ", e.separated_by, 19, " ");
  }
  out += wrapped("  dict:<op>:<channel>: ",
                 "the generic dictionary over a channel of the run, op one of x, sq, absx, sgn, "
                 "d, lag1, lag2, lag3; dict:prod:<a>*<b> a product (docs/RESIDUAL.md)",
                 4, " ");
  return out;
}

}  // namespace dynid::cli
