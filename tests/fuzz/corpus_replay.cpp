// Corpus replay: runs a fuzz target's LLVMFuzzerTestOneInput on every file of the directories
// (or files) given, without libFuzzer, so the g++ and ASan builds check the committed corpus in
// every CI pass. A target that crashes, reports to a sanitizer or throws an exception it should
// not fails the test; an empty corpus fails too (a replay of nothing proves nothing).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

std::vector<std::filesystem::path> inputs_of(const std::filesystem::path& where) {
  std::vector<std::filesystem::path> files;
  if (std::filesystem::is_directory(where)) {
    for (const auto& entry : std::filesystem::directory_iterator(where))
      if (entry.is_regular_file()) files.push_back(entry.path());
  } else if (std::filesystem::is_regular_file(where)) {
    files.push_back(where);
  }
  std::sort(files.begin(), files.end());  // a stable order, so a failure reproduces
  return files;
}

std::string bytes_of(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t replayed = 0;
  for (int a = 1; a < argc; ++a) {
    for (const auto& file : inputs_of(argv[a])) {
      const std::string bytes = bytes_of(file);
      std::cerr << "replay " << file.filename().string() << " (" << bytes.size() << " bytes)\n";
      // libFuzzer never passes a null pointer, even for an empty input.
      LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data() ? bytes.data() : ""),
                             bytes.size());
      ++replayed;
    }
  }
  std::cerr << replayed << " inputs replayed\n";
  return replayed == 0 ? 1 : 0;
}
