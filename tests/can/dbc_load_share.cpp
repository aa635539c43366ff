// Which DBC files load unchanged. For every .dbc file given, or found in a folder given (sorted),
// one line: "loads", "loads (N warnings, K messages not decoded)" or "refused: <error>"; then
// the share that loads. With -v, each warning follows its file. dbc_load_share.sh builds it against
// the parser of any revision, so it uses only the API that every revision has.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include <dynid/can/dbc.hpp>

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  std::vector<fs::path> files;
  bool verbose = false;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "-v") {
      verbose = true;
      continue;
    }
    const fs::path arg(argv[i]);
    if (!fs::is_directory(arg)) {
      files.push_back(arg);
      continue;
    }
    std::vector<fs::path> found;
    for (const auto& e : fs::directory_iterator(arg))
      if (e.path().extension() == ".dbc") found.push_back(e.path());
    std::sort(found.begin(), found.end());
    files.insert(files.end(), found.begin(), found.end());
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: dbc_load_share [-v] FILE.dbc|FOLDER...\n");
    return 2;
  }
  std::size_t loaded = 0;
  for (const fs::path& f : files) {
    try {
      const dynid::can::Database db = dynid::can::parse_dbc_file(f);
      std::size_t not_decoded = 0;  // messages that id lookups do not find
      for (const auto& m : db.messages)
        if (!m.is_pseudo && db.find_message(m.id, m.extended) != &m) ++not_decoded;
      ++loaded;
      if (db.warnings.empty() && not_decoded == 0)
        std::printf("%s: loads\n", f.string().c_str());
      else
        std::printf("%s: loads (%zu warnings, %zu messages not decoded)\n", f.string().c_str(),
                    db.warnings.size(), not_decoded);
      if (verbose)
        for (const std::string& w : db.warnings) std::printf("  warning: %s\n", w.c_str());
    } catch (const std::exception& e) {
      std::printf("%s: refused: %s\n", f.string().c_str(), e.what());
    }
  }
  std::printf("loaded unchanged: %zu of %zu (%.1f %%)\n", loaded, files.size(),
              100.0 * static_cast<double>(loaded) / static_cast<double>(files.size()));
  return 0;
}
