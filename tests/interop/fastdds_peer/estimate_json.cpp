#include "estimate_json.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace peer {

namespace wire = dynid::wire;

namespace {

nlohmann::json number(double value) {
  if (!std::isfinite(value)) return nullptr;
  return value;
}

std::string status_name(wire::ParameterStatus status, wire::ParameterVerdict verdict) {
  switch (verdict) {
    case wire::NO_VERDICT:
      break;
    case wire::POORLY_IDENTIFIED:
      return "poorly identified";
    case wire::NOT_EXCITED:
      return "not excited";
    case wire::IMPLAUSIBLE:
      return "implausible";
  }
  switch (status) {
    case wire::IDENTIFIED:
      return "identified";
    case wire::REGROUPED:
      return "regrouped";
    case wire::DEPENDENT:
      return "dependent";
    case wire::ELIMINATED:
      return "eliminated";
  }
  throw std::runtime_error("unknown parameter status " + std::to_string(status));
}

nlohmann::json parameter_json(const wire::ParameterRow& p) {
  return {{"name", p.name().to_string()},
          {"unit", p.unit().to_string()},
          {"value", number(p.value())},
          {"std", number(p.standard_deviation())},
          {"relative_std_percent", number(p.relative_std_percent())},
          {"status", status_name(p.status(), p.verdict())},
          {"relation", p.relation().to_string()},
          {"reason", p.reason().to_string()},
          {"least_squares_value", number(p.least_squares_value())},
          {"least_squares_std", number(p.least_squares_std())}};
}

}  // namespace

nlohmann::json estimate_json(const wire::Estimate& e) {
  nlohmann::json parameters = nlohmann::json::array();
  for (const auto& p : e.parameters()) parameters.push_back(parameter_json(p));
  nlohmann::json groups = nlohmann::json::array();
  for (const auto& g : e.groups())
    groups.push_back({{"group", g.group().to_string()},
                      {"rows", g.rows()},
                      {"residual_rms", number(g.residual_rms())}});
  return {{"vehicle", e.vehicle().to_string()},
          {"model", e.model().to_string()},
          {"source", e.source().to_string()},
          {"revision", e.revision()},
          {"parameters", parameters},
          {"rows", e.rows()},
          {"effective_rows", number(e.effective_rows())},
          {"sigma", number(e.sigma())},
          {"condition_number", number(e.condition_number())},
          {"residual_rms", number(e.residual_rms())},
          {"relative_residual_norm", number(e.relative_residual_norm())},
          {"groups", groups},
          {"not_excited", e.not_excited().to_string()},
          // Not on the wire: the server's replies alone say why a model's channel cannot be judged.
          {"not_identified", ""},
          {"residual_verdict", e.residual_verdict().to_string()},
          {"residual_statement", e.residual_statement().to_string()},
          {"residual_through", e.residual_through()},
          {"estimator", e.estimator().to_string()},
          {"bias_test", e.bias_test().to_string()},
          {"bias_through", e.bias_through()}};
}

}  // namespace peer
