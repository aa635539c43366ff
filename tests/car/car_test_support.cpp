#include "car_test_support.hpp"

#include <atomic>
#include <unistd.h>

namespace dynid::car::test {

std::filesystem::path source_dir() { return DYNID_SOURCE_DIR; }

std::filesystem::path profile_path(const std::string& file) {
  return source_dir() / "deploy" / "profiles" / file;
}

std::filesystem::path rav4_data_dir() {
  const std::filesystem::path dir = std::filesystem::path(DYNID_SHARED_DATA) / "rav4-comma2k19";
  return std::filesystem::exists(dir / "rav4_2018-08-02_seg40.candump.log") ? dir : std::filesystem::path();
}

std::filesystem::path rav4_log() { return rav4_data_dir() / "rav4_2018-08-02_seg40.candump.log"; }

std::string rav4_missing_message() {
  return std::string("reference data absent: ") + DYNID_SHARED_DATA +
         "/rav4-comma2k19 (the real RAV4 CAN log) is not beside this clone; see README";
}

ScratchDir::ScratchDir(const std::string& tag) {
  static std::atomic<int> counter{0};
  path_ = std::filesystem::temp_directory_path() /
          ("dynid-car-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

}  // namespace dynid::car::test
