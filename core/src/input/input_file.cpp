#include "dynid/input/input_file.hpp"

#include <fstream>
#include <system_error>

#include "dynid/error.hpp"

namespace dynid::input {
namespace {

std::string kind_of(std::filesystem::file_type type) {
  using std::filesystem::file_type;
  switch (type) {
    case file_type::directory: return "a directory";
    case file_type::fifo: return "a FIFO (named pipe)";
    case file_type::character: return "a character device";
    case file_type::block: return "a block device";
    case file_type::socket: return "a socket";
    default: return "not a regular file";
  }
}

}  // namespace

void check_input_file(const std::filesystem::path& path, std::string_view what, std::uintmax_t max_bytes) {
  const std::string where = path.string() + ": " + std::string(what) + ": ";
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (status.type() == std::filesystem::file_type::not_found) throw InputError(where + "no such file");
  if (ec) throw InputError(where + "cannot examine it: " + ec.message());
  if (status.type() != std::filesystem::file_type::regular)
    throw InputError(where + "is " + kind_of(status.type()) + ", not a regular file");
  if (max_bytes == 0) return;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(where + "cannot examine it: " + ec.message());
  if (size > max_bytes)
    throw InputError(where + "is " + std::to_string(size) + " bytes, more than the " + std::to_string(max_bytes) +
                     " accepted");
}

std::string read_input_file(const std::filesystem::path& path, std::string_view what, std::uintmax_t max_bytes) {
  check_input_file(path, what, max_bytes);
  const std::string where = path.string() + ": " + std::string(what) + ": ";
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(where + "cannot open it");
  // One byte more than the size checked: a file that grew meanwhile is seen, not read on.
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  std::string text(static_cast<std::size_t>(ec ? 0 : size) + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw InputError(where + "read error");
  if (static_cast<std::uintmax_t>(in.gcount()) > size)
    throw InputError(where + "grew while being read (more than " + std::to_string(size) + " bytes)");
  text.resize(static_cast<std::size_t>(in.gcount()));
  return text;
}

void check_output_file(const std::filesystem::path& path, std::string_view what) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  const auto type = status.type();
  // A character device (/dev/null) takes what is written; a FIFO would block, a directory, a
  // socket or a block device cannot hold the output.
  if (type == std::filesystem::file_type::not_found || type == std::filesystem::file_type::regular ||
      type == std::filesystem::file_type::character)
    return;
  const std::string where = path.string() + ": " + std::string(what) + ": ";
  if (ec) throw InputError(where + "cannot examine it: " + ec.message());
  throw InputError(where + "is " + kind_of(type) + ", not a regular file");
}

}  // namespace dynid::input
