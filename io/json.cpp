#include "io/json.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

namespace voussoir {

void write_json(const nlohmann::json& j, const std::string& path) {
  // NaN is not JSON: nlohmann writes it as null; the drivers should never hand us one, so a
  // null in a summary is a visible sign of a bug rather than a silently wrong number.
  const std::string text = j.dump(2) + "\n";
  if (path == "-") {
    std::cout << text << std::flush;
    if (!std::cout) throw OutputError("cannot write JSON to standard output");
    return;
  }
  if (path.empty()) throw OutputError("cannot write JSON: empty file name");
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw OutputError("cannot write JSON file '" + path + "': " + std::strerror(errno));
    out << text;
    out.close();
    if (!out) {
      std::remove(tmp.c_str());
      throw OutputError("cannot write JSON file '" + path + "': write failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw OutputError("cannot write JSON file '" + path + "': " + ec.message());
  }
}

}  // namespace voussoir
