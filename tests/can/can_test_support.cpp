#include "can_test_support.hpp"

#include <sys/wait.h>
#include <algorithm>
#include <array>
#include <cstdio>
#include <dynid/can/dbc.hpp>
#include <dynid/error.hpp>
#include <memory>

namespace dynid::can::test {

std::filesystem::path shared_data() { return DYNID_SHARED_DATA; }
std::filesystem::path opendbc_dir() { return shared_data() / "opendbc"; }
std::filesystem::path rav4_dir() { return shared_data() / "rav4-comma2k19"; }

std::vector<std::filesystem::path> opendbc_files() {
  std::vector<std::filesystem::path> out;
  if (!std::filesystem::is_directory(opendbc_dir())) return out;
  for (const auto& e : std::filesystem::directory_iterator(opendbc_dir()))
    if (e.path().extension() == ".dbc") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::string dbc_error(const std::string& text, const std::string& name) {
  try {
    parse_dbc_string(text, name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::vector<Frame> read_all(LogReader& reader) {
  std::vector<Frame> out;
  Frame f;
  while (reader.next(f)) out.push_back(f);
  return out;
}

std::vector<std::string> described(const LogReader& reader) {
  std::vector<std::string> out;
  for (const auto& e : reader.errors()) out.push_back(reader.describe(e));
  return out;
}

std::string run_command(const std::string& command, int& status) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) {
    status = -1;
    return out;
  }
  std::array<char, 65536> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) out.append(buf.data(), n);
  const int raw = pclose(pipe);
  status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return out;
}

}  // namespace dynid::can::test
