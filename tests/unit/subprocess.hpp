#pragma once
// Running the voussoir program from a test: fork/exec with a wall-clock limit, a CPU-time
// limit and an address-space limit set in the child, standard output and error captured to
// files. No sleeps: the child's own alarm() ends it (SIGALRM survives exec), and the parent
// blocks in waitpid(). Used by test_stability (guards), test_fuzz and test_restart.

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace voussoir::testing {

// Sanitizer builds reserve terabytes of shadow memory: an address-space limit would kill them
// at start-up, so it is left off there (the sanitizers bound memory errors themselves).
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
#else
inline constexpr bool kSanitized = false;
#endif

struct Limits {
  unsigned wall_s = 60;                    // SIGALRM after this many seconds
  unsigned cpu_s = 120;                    // SIGXCPU after this much CPU time (all threads)
  unsigned long long memory = 2ull << 30;  // RLIMIT_AS [bytes]; 0 = none
};

struct ProcessResult {
  bool exited = false;   // normal exit (else killed by a signal)
  int status = -1;       // exit status when exited
  int signal = 0;        // signal number when killed
  std::string out, err;  // captured standard output and error

  bool timed_out() const { return !exited && (signal == SIGALRM || signal == SIGXCPU); }
  std::string describe() const {
    std::ostringstream s;
    if (exited)
      s << "exit status " << status;
    else
      s << "killed by signal " << signal << (timed_out() ? " (time limit)" : "");
    return s.str();
  }
};

inline std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs `args` (args[0] the program path) with the limits; `scratch` is a path prefix for the
// captured output files (removed afterwards).
inline ProcessResult run_process(const std::vector<std::string>& args, const Limits& limits,
                                 const std::string& scratch) {
  const std::string out_path = scratch + ".stdout", err_path = scratch + ".stderr";
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = ::open("/dev/null", O_RDONLY);
    if (out < 0 || err < 0 || null < 0) _exit(126);
    dup2(null, 0);
    dup2(out, 1);
    dup2(err, 2);
    if (limits.memory > 0 && !kSanitized) {
      const rlimit as{limits.memory, limits.memory};
      setrlimit(RLIMIT_AS, &as);
    }
    const rlimit cpu{limits.cpu_s, limits.cpu_s + 5};
    setrlimit(RLIMIT_CPU, &cpu);
    const rlimit core{0, 0};  // no core dumps from deliberate crashes
    setrlimit(RLIMIT_CORE, &core);
    alarm(limits.wall_s);
    execv(argv[0], argv.data());
    _exit(127);
  }
  ProcessResult r;
  int status = 0;
  if (pid > 0) {
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    r.exited = WIFEXITED(status);
    r.status = r.exited ? WEXITSTATUS(status) : -1;
    r.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  }
  r.out = read_text_file(out_path);
  r.err = read_text_file(err_path);
  std::remove(out_path.c_str());
  std::remove(err_path.c_str());
  return r;
}

}  // namespace voussoir::testing
