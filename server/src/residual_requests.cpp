#include "dynid/server/residual_requests.hpp"

#include "dynid/error.hpp"
#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/report/residual_html.hpp"
#include "dynid/report/residual_report.hpp"
#include "dynid/residual/effect_comparison.hpp"
#include "dynid/residual/effect_screen.hpp"

namespace dynid::server {
namespace {

const ingest::ModelSpec& announced_model(const ingest::RunAnnouncement& a, const std::string& model) {
  for (const ingest::ModelSpec& spec : a.models)
    if (spec.model == model) return spec;
  std::string known;
  for (const ingest::ModelSpec& spec : a.models) known += (known.empty() ? "" : ", ") + spec.model;
  throw InputError("run " + a.vehicle + "/" + a.run + " has no model '" + model + "' (its models: " + known + ")");
}

}  // namespace

ResidualReply residual_reply(const ingest::RunAnnouncement& announcement,
                             const std::vector<ingest::Chunk>& chunks, const ResidualRequest& request) {
  if (request.format != "text" && request.format != "html")
    throw InputError("residual report: format '" + request.format + "' (text or html)");
  const ingest::ModelSpec& spec = announced_model(announcement, request.model);
  const std::vector<std::string> declared = request.effects.value_or(spec.effects);
  const auto model = model::make_model(spec.model, spec.constants);
  const auto segments = ingest::preprocess_offline(ingest::assemble_run(announcement, chunks));
  if (segments.empty())
    throw InputError("run " + announcement.vehicle + "/" + announcement.run + ": no valid segment long enough to filter");
  const double rate = announcement.sample_rate_hz;
  const int odmf = announcement.preprocessing.odmf;
  const std::string title = announcement.vehicle + " / " + announcement.run + " / " + spec.model;
  if (request.effect.empty()) {
    residual::ScreenOptions options;
    options.only = request.candidates;
    const residual::ScreenResult screen = residual::screen_effects(*model, declared, segments, rate, odmf, options);
    if (request.format == "html") return {report::residual_html({title, &screen, nullptr}), "text/html"};
    return {report::format_screen_text(screen), "text/plain"};
  }
  const residual::EffectComparison cmp =
      residual::compare_effect(*model, declared, request.effect, segments, rate, odmf);
  if (request.format == "html") return {report::residual_html({title, nullptr, &cmp}), "text/html"};
  return {report::format_comparison_text(cmp), "text/plain"};
}

}  // namespace dynid::server
