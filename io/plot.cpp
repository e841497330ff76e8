// Pictures through the scripts of scripts/ (plot.hpp).

#include "io/plot.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "io/json.hpp"

namespace voussoir {

namespace {

constexpr const char* kPython = "/usr/bin/python3";

// Single-quoted for the shell ('\'' for a quote inside).
std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

bool draw_with_script(const std::string& script, const std::vector<std::string>& args,
                      const std::string& output) {
  if (access(kPython, X_OK) != 0) {
    std::fprintf(stderr,
                 "voussoir: warning: %s could not be drawn: no %s (install python3 and "
                 "python3-matplotlib)\n",
                 output.c_str(), kPython);
    return false;
  }
  std::string cmd =
      std::string(kPython) + " " + quoted(std::string(VOUSSOIR_SOURCE_DIR) + "/scripts/" + script);
  for (const std::string& a : args) cmd += " " + quoted(a);
  std::fflush(stdout);  // our summary before the script's lines
  const int status = std::system(cmd.c_str());
  if (status == 0) return true;
  const int code = status > 0 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::fprintf(
      stderr, "voussoir: warning: %s could not be drawn: scripts/%s %s\n", output.c_str(),
      script.c_str(),
      code >= 0 ? ("exited with status " + std::to_string(code)).c_str() : "could not be run");
  return false;
}

bool draw_geometry(const nlohmann::json& geometry, const std::string& picture,
                   const std::vector<std::string>& args) {
  const std::string tmp = picture + ".geometry.json";
  write_json(geometry, tmp);
  std::vector<std::string> all = {tmp, "-o", picture};
  all.insert(all.end(), args.begin(), args.end());
  const bool ok = draw_with_script("draw", all, picture);
  std::remove(tmp.c_str());
  return ok;
}

}  // namespace voussoir
