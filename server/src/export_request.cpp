#include "dynid/server/export_request.hpp"

#include <fmt/format.h>

#include "dynid.h"  // the reply's payload limit (idl/dynid.idl)
#include "dynid/error.hpp"
#include "dynid/ingest/channel_health.hpp"
#include "dynid/ingest/recorded_run.hpp"
#include "dynid/model/registry.hpp"
#include "dynid/report/run_export.hpp"

namespace dynid::server {

ResidualReply export_reply(const ingest::RunAnnouncement& announcement,
                           const std::vector<ingest::Chunk>& chunks,
                           const ResidualRequest& request) {
  const std::string run_name = announcement.vehicle + "/" + announcement.run;
  std::string announced;
  bool found = false;
  for (const ingest::ModelSpec& spec : announcement.models) {
    announced += (announced.empty() ? "" : ", ") + spec.model;
    found = found || spec.model == request.model;
  }
  const bool one = !request.model.empty();
  if (one && !found)
    throw InputError("run " + run_name + " has no model '" + request.model +
                     "' (its models: " + announced + ")");
  const ingest::RecordedRun run = ingest::assemble_run(announcement, chunks);
  const auto segments = ingest::preprocess_offline(run);
  if (segments.empty())
    throw InputError("run " + run_name + ": no valid segment long enough to filter");
  const ingest::RunHealth health = ingest::channel_health(run);
  report::Mdf4Document document;
  std::string exported, left_out;
  for (const ingest::ModelSpec& spec : announcement.models) {
    if (one && spec.model != request.model) continue;
    const std::vector<std::string> effects =
        one ? request.effects.value_or(spec.effects) : spec.effects;
    try {
      const auto model = model::make_model(spec.model, spec.constants);
      if (const auto reason = ingest::unhealthy_reason(health, announcement, *model, effects))
        throw InputError(ingest::not_identified(*reason));
      for (auto& table :
           report::export_tables(*model, effects, segments, announcement.sample_rate_hz,
                                 announcement.preprocessing.odmf))
        document.tables.push_back(std::move(table));
      exported += (exported.empty() ? "" : ", ") + spec.model;
    } catch (const InputError& e) {
      if (one) throw InputError("export of " + run_name + " " + spec.model + ": " + e.what());
      left_out += (left_out.empty() ? "" : "; ") + spec.model + ": " + e.what();
    }
  }
  if (document.tables.empty())
    throw InputError("run " + run_name + ": no model can be exported (" + left_out + ")");
  document.comment = report::export_comment(run_name, exported, left_out);
  auto parts =
      report::export_parts(std::move(document.tables), dynid_wire_kMaxPayload, document.comment);
  if (request.part < 1 || static_cast<std::size_t>(request.part) > parts.size())
    throw InputError(fmt::format("the export of {} has {} part{}: no part {}", run_name,
                                 parts.size(), parts.size() == 1 ? "" : "s", request.part));
  document.tables = std::move(parts[static_cast<std::size_t>(request.part - 1)]);
  return {report::write_mdf4(document),
          fmt::format("application/x-mdf4; part={}/{}", request.part, parts.size())};
}

}  // namespace dynid::server
