// Conversions of the state and request topics: ChunkAck, Estimate, Request, Reply.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "dynid/dds/conversions.hpp"

#include <cmath>
#include "wire_fields.hpp"

namespace dynid::dds {

using wire_fields::allocate;
using wire_fields::elements;
using wire_fields::get;
using wire_fields::put_id;
using wire_fields::put_text;

namespace {

// The wire's (status, verdict) pair: the refined statuses travel as IDENTIFIED plus a verdict,
// so that a reader of the first release's types still reads them (as identified).
std::pair<dynid_wire_ParameterStatus, dynid_wire_ParameterVerdict> to_wire_status(ls::ParameterStatus status) {
  switch (status) {
    case ls::ParameterStatus::kIdentified: return {dynid_wire_IDENTIFIED, dynid_wire_NO_VERDICT};
    case ls::ParameterStatus::kRegrouped: return {dynid_wire_REGROUPED, dynid_wire_NO_VERDICT};
    case ls::ParameterStatus::kDependent: return {dynid_wire_DEPENDENT, dynid_wire_NO_VERDICT};
    case ls::ParameterStatus::kEliminated: return {dynid_wire_ELIMINATED, dynid_wire_NO_VERDICT};
    case ls::ParameterStatus::kPoorlyIdentified: return {dynid_wire_IDENTIFIED, dynid_wire_POORLY_IDENTIFIED};
    case ls::ParameterStatus::kNotExcited: return {dynid_wire_IDENTIFIED, dynid_wire_NOT_EXCITED};
    case ls::ParameterStatus::kImplausible: return {dynid_wire_IDENTIFIED, dynid_wire_IMPLAUSIBLE};
  }
  throw InputError("Estimate: unknown parameter status");
}

// A wire enum holds whatever integer the peer sent. Its bits are read as an integer before they
// are compared: loading an out-of-range value through the enum type is undefined behaviour
// (UBSan's -fsanitize=enum caught it on a malformed sample).
template <typename Enum>
long long wire_enum_value(const Enum& field) {
  std::underlying_type_t<Enum> raw;
  std::memcpy(&raw, &field, sizeof raw);
  return static_cast<long long>(raw);
}

ls::ParameterStatus parameter_status_from_wire(long long raw, const std::string& where) {
  if (raw == dynid_wire_IDENTIFIED) return ls::ParameterStatus::kIdentified;
  if (raw == dynid_wire_REGROUPED) return ls::ParameterStatus::kRegrouped;
  if (raw == dynid_wire_DEPENDENT) return ls::ParameterStatus::kDependent;
  if (raw == dynid_wire_ELIMINATED) return ls::ParameterStatus::kEliminated;
  throw InputError(where + ": unknown status " + std::to_string(raw));
}

// A verdict refines IDENTIFIED only (NO_VERDICT leaves the status as it is).
ls::ParameterStatus refined_from_wire(ls::ParameterStatus status, long long verdict, const std::string& where) {
  if (verdict == dynid_wire_NO_VERDICT) return status;
  if (status != ls::ParameterStatus::kIdentified)
    throw InputError(where + ": verdict " + std::to_string(verdict) + " on a parameter that is not identified");
  if (verdict == dynid_wire_POORLY_IDENTIFIED) return ls::ParameterStatus::kPoorlyIdentified;
  if (verdict == dynid_wire_NOT_EXCITED) return ls::ParameterStatus::kNotExcited;
  if (verdict == dynid_wire_IMPLAUSIBLE) return ls::ParameterStatus::kImplausible;
  throw InputError(where + ": unknown verdict " + std::to_string(verdict));
}

dynid_wire_ReplyStatus to_wire_status(ReplyStatus status) {
  switch (status) {
    case ReplyStatus::kOk: return dynid_wire_OK;
    case ReplyStatus::kBadRequest: return dynid_wire_BAD_REQUEST;
    case ReplyStatus::kNotFound: return dynid_wire_NOT_FOUND;
    case ReplyStatus::kFailed: return dynid_wire_FAILED;
  }
  throw InputError("Reply: unknown status");
}

ReplyStatus reply_status_from_wire(long long raw, const std::string& where) {
  if (raw == dynid_wire_OK) return ReplyStatus::kOk;
  if (raw == dynid_wire_BAD_REQUEST) return ReplyStatus::kBadRequest;
  if (raw == dynid_wire_NOT_FOUND) return ReplyStatus::kNotFound;
  if (raw == dynid_wire_FAILED) return ReplyStatus::kFailed;
  throw InputError(where + ": unknown status " + std::to_string(raw));
}

void check_reply_shard(std::uint32_t shard, std::uint32_t count, const std::string& where) {
  if (count != 0 && shard >= count)
    throw InputError(where + ": shard " + std::to_string(shard) + " of " + std::to_string(count) +
                     " (expected K < N)");
}

void put_parameter(dynid_wire_ParameterRow& out, const ParameterEntry& entry,
                   const std::string& where) {
  put_id(out.name, entry.name, where + " parameter name");
  put_id(out.unit, entry.unit, where + " parameter unit");
  out.value = entry.value;
  out.standard_deviation = entry.standard_deviation;
  out.relative_std_percent = entry.relative_std_percent;
  std::tie(out.status, out.verdict) = to_wire_status(entry.status);
  put_text(out.relation, entry.relation);
  put_text(out.reason, entry.reason);
  out.least_squares_value = entry.least_squares_value;
  out.least_squares_std = entry.least_squares_std;
}

ParameterEntry get_parameter(const dynid_wire_ParameterRow& in, const std::string& where) {
  ParameterEntry entry;
  entry.name = get(in.name, where + " parameter name");
  const std::string at = where + " parameter '" + entry.name + "'";
  entry.unit = get(in.unit, at + " unit");
  entry.value = in.value;
  entry.standard_deviation = in.standard_deviation;
  entry.relative_std_percent = in.relative_std_percent;
  entry.status = refined_from_wire(parameter_status_from_wire(wire_enum_value(in.status), at),
                                   wire_enum_value(in.verdict), at);
  entry.relation = get(in.relation, at + " relation");
  entry.reason = get(in.reason, at + " reason");
  entry.least_squares_value = in.least_squares_value;  // meaningful under IV only: from_wire
  entry.least_squares_std = in.least_squares_std;
  return entry;
}

}  // namespace

Sample<dynid_wire_ChunkAck> to_wire(const ChunkReceipt& receipt) {
  const std::string where = "ChunkAck " + receipt.vehicle + "/" + receipt.run;
  Sample<dynid_wire_ChunkAck> sample;
  put_id(sample.data.vehicle, receipt.vehicle, where + " vehicle");
  put_id(sample.data.run, receipt.run, where + " run");
  sample.data.highest_contiguous = receipt.highest_contiguous;
  // The car needs the recent rejections; older ones were reported in earlier receipts.
  const std::size_t count = std::min<std::size_t>(receipt.rejections.size(), dynid_wire_kMaxRejections);
  const std::size_t first = receipt.rejections.size() - count;
  auto* rejections = allocate(sample.data.rejections, count, dynid_wire_kMaxRejections, where);
  for (std::size_t k = 0; k < count; ++k) {
    rejections[k].sequence_number = receipt.rejections[first + k].sequence;
    put_text(rejections[k].reason, receipt.rejections[first + k].reason);
  }
  return sample;
}

ChunkReceipt from_wire(const dynid_wire_ChunkAck& sample) {
  ChunkReceipt receipt;
  receipt.vehicle = get(sample.vehicle, "ChunkAck vehicle");
  receipt.run = get(sample.run, "ChunkAck " + receipt.vehicle + " run");
  const std::string where = "ChunkAck " + receipt.vehicle + "/" + receipt.run;
  if (sample.highest_contiguous < -1)
    throw InputError(where + ": highest contiguous sequence " +
                     std::to_string(sample.highest_contiguous) + " (-1 is 'none')");
  receipt.highest_contiguous = sample.highest_contiguous;
  for (const auto& rejection :
       elements(sample.rejections, dynid_wire_kMaxRejections, where + " rejections"))
    receipt.rejections.push_back(
        {rejection.sequence_number, get(rejection.reason, where + " rejection reason")});
  return receipt;
}

Sample<dynid_wire_Estimate> to_wire(const EstimateTable& table) {
  const std::string where = "Estimate " + table.vehicle + "/" + table.model;
  Sample<dynid_wire_Estimate> sample;
  auto& out = sample.data;
  put_id(out.vehicle, table.vehicle, where + " vehicle");
  put_id(out.model, table.model, where + " model");
  put_id(out.source, table.source, where + " source");
  out.revision = table.revision;
  auto* parameters = allocate(out.parameters, table.parameters.size(), dynid_wire_kMaxParameters,
                              where + " parameters");
  for (std::size_t k = 0; k < table.parameters.size(); ++k)
    put_parameter(parameters[k], table.parameters[k], where);
  out.rows = table.rows;
  out.effective_rows = table.effective_rows;
  out.sigma = table.sigma;
  out.condition_number = table.condition_number;
  out.residual_rms = table.residual_rms;
  out.relative_residual_norm = table.relative_residual_norm;
  auto* groups = allocate(out.groups, table.groups.size(), dynid_wire_kMaxGroups, where + " groups");
  for (std::size_t k = 0; k < table.groups.size(); ++k) {
    put_id(groups[k].group, table.groups[k].group, where + " group name");
    groups[k].rows = table.groups[k].rows;
    groups[k].residual_rms = table.groups[k].residual_rms;
  }
  put_text(out.not_excited, table.not_excited);
  put_id(out.residual_verdict, table.residual_verdict, where + " residual_verdict");
  put_text(out.residual_statement, table.residual_statement);
  out.residual_through = table.residual_through;
  put_id(out.estimator, table.estimator, where + " estimator");
  put_text(out.bias_test, table.bias_test);
  out.bias_through = table.bias_through;
  return sample;
}

EstimateTable from_wire(const dynid_wire_Estimate& sample) {
  EstimateTable table;
  table.vehicle = get(sample.vehicle, "Estimate vehicle");
  table.model = get(sample.model, "Estimate " + table.vehicle + " model");
  const std::string where = "Estimate " + table.vehicle + "/" + table.model;
  table.source = get(sample.source, where + " source");
  table.revision = sample.revision;
  for (const auto& row : elements(sample.parameters, dynid_wire_kMaxParameters, where + " parameters"))
    table.parameters.push_back(get_parameter(row, where));
  table.rows = sample.rows;
  table.effective_rows = sample.effective_rows;
  table.sigma = sample.sigma;
  table.condition_number = sample.condition_number;
  table.residual_rms = sample.residual_rms;
  table.relative_residual_norm = sample.relative_residual_norm;
  for (const auto& group : elements(sample.groups, dynid_wire_kMaxGroups, where + " groups"))
    table.groups.push_back({get(group.group, where + " group name"), group.rows, group.residual_rms});
  table.not_excited = get(sample.not_excited, where + " not_excited");
  table.residual_verdict = get(sample.residual_verdict, where + " residual_verdict");
  table.residual_statement = get(sample.residual_statement, where + " residual_statement");
  table.residual_through = sample.residual_through;
  table.estimator = get(sample.estimator, where + " estimator");
  if (table.estimator.empty()) table.estimator = kLeastSquares;  // an older server's
  if (table.estimator == kLeastSquares)  // an older server sends zeros there
    for (ParameterEntry& p : table.parameters) p.least_squares_value = p.least_squares_std = std::nan("");
  table.bias_test = get(sample.bias_test, where + " bias_test");
  table.bias_through = sample.bias_through;
  return table;
}

Sample<dynid_wire_Request> to_wire(const Request& request) {
  const std::string where = "Request " + request.client + "#" + std::to_string(request.correlation_id);
  Sample<dynid_wire_Request> sample;
  put_id(sample.data.client, request.client, where + " client");
  sample.data.correlation_id = request.correlation_id;
  put_id(sample.data.kind, request.kind, where + " kind");
  auto* arguments = allocate(sample.data.arguments, request.arguments.size(),
                             dynid_wire_kMaxArguments, where + " arguments");
  for (std::size_t k = 0; k < request.arguments.size(); ++k) {
    put_id(arguments[k].name, request.arguments[k].name, where + " argument name");
    put_id(arguments[k].value, request.arguments[k].value, where + " argument value");
  }
  return sample;
}

Request from_wire(const dynid_wire_Request& sample) {
  Request request;
  request.client = get(sample.client, "Request client");
  request.correlation_id = sample.correlation_id;
  const std::string where = "Request " + request.client + "#" + std::to_string(request.correlation_id);
  request.kind = get(sample.kind, where + " kind");
  for (const auto& argument : elements(sample.arguments, dynid_wire_kMaxArguments, where + " arguments"))
    request.arguments.push_back(
        {get(argument.name, where + " argument name"), get(argument.value, where + " argument value")});
  return request;
}

Sample<dynid_wire_Reply> to_wire(const Reply& reply) {
  const std::string where = "Reply " + reply.client + "#" + std::to_string(reply.correlation_id);
  Sample<dynid_wire_Reply> sample;
  put_id(sample.data.client, reply.client, where + " client");
  sample.data.correlation_id = reply.correlation_id;
  sample.data.status = to_wire_status(reply.status);
  put_text(sample.data.error, reply.error);
  put_id(sample.data.payload_format, reply.payload_format, where + " payload format");
  auto* payload = allocate(sample.data.payload, reply.payload.size(), dynid_wire_kMaxPayload,
                           where + " payload bytes");
  if (payload != nullptr) std::copy(reply.payload.begin(), reply.payload.end(), payload);
  check_reply_shard(reply.shard, reply.shard_count, where);
  sample.data.shard = reply.shard;
  sample.data.shard_count = reply.shard_count;
  return sample;
}

Reply from_wire(const dynid_wire_Reply& sample) {
  Reply reply;
  reply.client = get(sample.client, "Reply client");
  reply.correlation_id = sample.correlation_id;
  const std::string where = "Reply " + reply.client + "#" + std::to_string(reply.correlation_id);
  reply.status = reply_status_from_wire(wire_enum_value(sample.status), where);
  reply.error = get(sample.error, where + " error");
  reply.payload_format = get(sample.payload_format, where + " payload format");
  const auto payload = elements(sample.payload, dynid_wire_kMaxPayload, where + " payload");
  reply.payload.assign(payload.begin(), payload.end());
  check_reply_shard(sample.shard, sample.shard_count, where);
  reply.shard = sample.shard;
  reply.shard_count = sample.shard_count;
  return reply;
}

}  // namespace dynid::dds
