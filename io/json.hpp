#pragma once
// Writing a JSON summary (`--json FILE`, "-" = standard output).

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace voussoir {

// A file that could not be written (names the path and the reason). Derives from
// std::runtime_error, so the program reports it as a failure (exit status 1).
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Writes `j` (indented by 2, trailing newline) to `path`, or to stdout when path is "-".
// The file is written to `path + ".tmp"` and renamed, so a reader never sees half a file.
// Throws OutputError naming the path when it cannot be written.
void write_json(const nlohmann::json& j, const std::string& path);

}  // namespace voussoir
