#pragma once
// Shared helpers of the car tests: paths of the project's profiles and of the reference data,
// a scratch folder that removes itself.
#include <filesystem>
#include <string>

namespace dynid::car::test {

std::filesystem::path source_dir();
std::filesystem::path profile_path(const std::string& file);
/// ../shared/data/rav4-comma2k19, or empty when the reference data is absent.
std::filesystem::path rav4_data_dir();
std::filesystem::path rav4_log();
std::string rav4_missing_message();

class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace dynid::car::test

// Skips the current test when the RAV4 reference data is absent.
#define DYNID_REQUIRE_RAV4_DATA()                                                   \
  do {                                                                              \
    if (::dynid::car::test::rav4_data_dir().empty())                                \
      GTEST_SKIP() << ::dynid::car::test::rav4_missing_message();                   \
  } while (false)
