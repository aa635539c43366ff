#include "process_stats.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "dynid/error.hpp"

namespace dynid::load {

namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot be read (is the process running?)");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// "VmRSS:   1234 kB" -> bytes.
std::uint64_t status_kb(const std::string& status, const std::string& field,
                        const std::string& path) {
  const auto at = status.find("\n" + field + ":");
  if (at == std::string::npos) throw InputError(path + ": no field " + field);
  std::istringstream line(status.substr(at + field.size() + 2));
  std::uint64_t kb = 0;
  if (!(line >> kb)) throw InputError(path + ": unreadable field " + field);
  return kb * 1024;
}

}  // namespace

ProcessStats read_process_stats(pid_t pid) {
  const std::string base = "/proc/" + std::to_string(pid);
  const std::string stat = read_file(base + "/stat");
  // The command name (field 2) may hold spaces and parentheses: fields are counted after the
  // last ')'. utime and stime are fields 14 and 15, i.e. the 12th and 13th after it.
  const auto close = stat.rfind(')');
  if (close == std::string::npos) throw InputError(base + "/stat: unreadable");
  std::istringstream fields(stat.substr(close + 1));
  std::string field;
  double ticks = 0.0;
  for (int k = 1; k <= 13 && fields >> field; ++k)
    if (k >= 12) ticks += std::stod(field);
  if (!fields) throw InputError(base + "/stat: too few fields");
  const std::string status = read_file(base + "/status");
  ProcessStats s;
  s.cpu_seconds = ticks / static_cast<double>(sysconf(_SC_CLK_TCK));
  s.rss_bytes = status_kb(status, "VmRSS", base + "/status");
  s.peak_rss_bytes = status_kb(status, "VmHWM", base + "/status");
  return s;
}

ProcessStats read_process_stats(const std::vector<pid_t>& pids) {
  ProcessStats total;
  for (const pid_t pid : pids) {
    const ProcessStats one = read_process_stats(pid);
    total.cpu_seconds += one.cpu_seconds;
    total.rss_bytes += one.rss_bytes;
    total.peak_rss_bytes += one.peak_rss_bytes;
  }
  return total;
}

double slope(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = std::min(x.size(), y.size());
  if (n < 2) return 0.0;
  double mx = 0.0, my = 0.0;
  for (std::size_t k = 0; k < n; ++k) mx += x[k], my += y[k];
  mx /= static_cast<double>(n);
  my /= static_cast<double>(n);
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    sxy += (x[k] - mx) * (y[k] - my);
    sxx += (x[k] - mx) * (x[k] - mx);
  }
  return sxx > 0.0 ? sxy / sxx : 0.0;
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto rank = static_cast<std::size_t>(
      std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size())));
  const std::size_t index = rank == 0 ? 0 : rank - 1;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(index),
                   values.end());
  return values[index];
}

}  // namespace dynid::load
