#include "nist_dataset.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace dynid::test {
namespace {

std::vector<std::string> read_lines(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  return lines;
}

// "Certified Values  (lines 31 to 55)" -> {31, 55} (1-based, inclusive).
std::pair<std::size_t, std::size_t> line_range(const std::vector<std::string>& lines,
                                               const std::string& label, const std::string& path) {
  const std::regex re(label + R"(\s*\(lines\s+(\d+)\s+to\s+(\d+)\))");
  for (const auto& line : lines) {
    std::smatch m;
    if (std::regex_search(line, m, re)) return {std::stoul(m[1]), std::stoul(m[2])};
  }
  throw std::runtime_error(path + ": no '" + label + " (lines A to B)' in the header");
}

}  // namespace

NistDataset read_nist_dataset(const std::string& path) {
  const auto lines = read_lines(path);
  NistDataset d;
  d.name = path.substr(path.find_last_of('/') + 1);
  const auto [cert_first, cert_last] = line_range(lines, "Certified Values", path);
  const auto [data_first, data_last] = line_range(lines, "Data", path);

  std::vector<std::pair<int, std::pair<double, double>>> params;  // B index -> (value, sd)
  const std::regex param_re(R"(^\s*B(\d+)\s+(\S+)\s+(\S+)\s*$)");
  const std::regex resid_re(R"(^\s*Standard Deviation\s+(\S+)\s*$)");
  bool after_residual = false;
  for (std::size_t i = cert_first - 1; i < cert_last && i < lines.size(); ++i) {
    std::smatch m;
    if (std::regex_match(lines[i], m, param_re))
      params.push_back({std::stoi(m[1]), {std::stod(m[2]), std::stod(m[3])}});
    if (lines[i].find("Residual") != std::string::npos) after_residual = true;
    if (after_residual && std::regex_match(lines[i], m, resid_re)) {
      d.certified_residual_sd = std::stod(m[1]);
      after_residual = false;
    }
  }
  if (params.empty()) throw std::runtime_error(path + ": no certified parameters found");
  const bool intercept = params.front().first == 0;

  std::vector<std::vector<double>> rows;
  for (std::size_t i = data_first - 1; i < data_last && i < lines.size(); ++i) {
    std::istringstream s(lines[i]);
    std::vector<double> values;
    for (double v; s >> v;) values.push_back(v);
    if (values.size() < 2)
      throw std::runtime_error(path + ":" + std::to_string(i + 1) + ": expected y and predictors");
    rows.push_back(values);
  }
  const auto k = static_cast<Eigen::Index>(params.size());
  const std::size_t predictors = rows.front().size() - 1;
  const bool polynomial = predictors == 1 && k - (intercept ? 1 : 0) > 1;
  d.design.resize(static_cast<Eigen::Index>(rows.size()), k);
  d.y.resize(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const auto ri = static_cast<Eigen::Index>(r);
    d.y(ri) = rows[r][0];
    for (Eigen::Index c = 0; c < k; ++c) {
      const int power = params[static_cast<std::size_t>(c)].first;  // B_p multiplies x^p or x_p
      if (power == 0)
        d.design(ri, c) = 1.0;
      else if (polynomial)
        d.design(ri, c) = std::pow(rows[r][1], power);
      else
        d.design(ri, c) = rows[r].at(static_cast<std::size_t>(power));
    }
  }
  d.certified_value.resize(k);
  d.certified_std.resize(k);
  for (Eigen::Index c = 0; c < k; ++c) {
    d.certified_value(c) = params[static_cast<std::size_t>(c)].second.first;
    d.certified_std(c) = params[static_cast<std::size_t>(c)].second.second;
  }
  return d;
}

double log_relative_error(double computed, double certified) {
  const double err =
      certified == 0.0 ? std::abs(computed) : std::abs(computed - certified) / std::abs(certified);
  if (err == 0.0) return 15.0;
  return std::min(15.0, -std::log10(err));
}

}  // namespace dynid::test
