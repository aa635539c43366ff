#include "scipy_reference.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace dynid::signal::test {
namespace {

constexpr const char* kPython = "/usr/bin/python3";

std::filesystem::path temp_signal_path() {
  static std::atomic<int> counter{0};
  return std::filesystem::temp_directory_path() /
         ("dynid_signal_" + std::to_string(getpid()) + "_" + std::to_string(counter++) + ".txt");
}

void write_matrix(const std::filesystem::path& path, const Eigen::MatrixXd& x) {
  std::ofstream out(path);
  out << std::setprecision(17);
  for (Eigen::Index r = 0; r < x.rows(); ++r) {
    for (Eigen::Index c = 0; c < x.cols(); ++c) out << (c ? " " : "") << x(r, c);
    out << '\n';
  }
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::string run(const std::string& command, int& status) {
  std::FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("popen failed: " + command);
  std::string text;
  char buffer[4096];
  std::size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) text.append(buffer, got);
  status = pclose(pipe);
  return text;
}

Eigen::MatrixXd read_rows(std::istream& in, Eigen::Index rows, Eigen::Index cols) {
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r)
    for (Eigen::Index c = 0; c < cols; ++c) in >> m(r, c);
  if (!in) throw std::runtime_error("scipy_reference.py: truncated answer");
  return m;
}

ScipyAnswer parse(const std::string& text) {
  std::istringstream in(text);
  ScipyAnswer answer;
  std::string tag;
  Eigen::Index sections = 0;
  in >> tag >> sections;
  if (tag != "sos") throw std::runtime_error("scipy_reference.py said: " + text);
  answer.sos = read_rows(in, sections, 6);
  if (in >> tag) {
    if (tag == "error") {
      std::getline(in, answer.error);
    } else {
      Eigen::Index rows = 0, cols = 0;
      in >> rows >> cols;
      answer.filtered = read_rows(in, rows, cols);
    }
  }
  return answer;
}

}  // namespace

std::optional<ScipyAnswer> run_scipy(int order, double cutoff_hz, double rate_hz,
                                     const Eigen::MatrixXd* x, std::string& why) {
  if (!std::filesystem::exists(kPython)) {
    why = std::string(kPython) + " is missing (Debian's python3 with python3-scipy)";
    return std::nullopt;
  }
  std::ostringstream command;
  command << std::setprecision(17) << kPython << " " << DYNID_SOURCE_DIR
          << "/tests/signal/scipy_reference.py " << order << " " << cutoff_hz << " " << rate_hz;
  std::filesystem::path path;
  if (x) {
    path = temp_signal_path();
    write_matrix(path, *x);
    command << " " << path.string();
  }
  int status = 0;
  const std::string text = run(command.str(), status);
  if (x) std::filesystem::remove(path);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 3) {
    why = "scipy is not importable by " + std::string(kPython) + ": " + text;
    return std::nullopt;
  }
  if (status != 0) throw std::runtime_error("scipy_reference.py failed: " + text);
  return parse(text);
}

}  // namespace dynid::signal::test
