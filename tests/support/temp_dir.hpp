#pragma once
// TempDir: a fresh directory under the system's temporary directory for one test, removed with
// everything in it when the object goes. The one scratch-directory helper of every test area.
//
// Contract: the constructor creates the directory (mkdtemp: unique, mode 0700) named
// `<prefix>-XXXXXX`, or throws std::runtime_error; the destructor never throws.
#include <filesystem>
#include <string>

namespace dynid::test {

class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "dynid-test");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  /// The path of `name` inside the directory.
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace dynid::test
