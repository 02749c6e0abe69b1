#include "tests/app/run_dgmm.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace dgmm::test {
namespace {

std::string Slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// stderr without the lines xvfb-run writes itself (e.g. "xvfb-run: error: problem while
// cleaning up temporary directory", seen under load): the tests judge dgmm's own output.
std::string WithoutXvfbRunLines(const std::string& err) {
  std::istringstream in(err);
  std::string line, kept;
  while (std::getline(in, line)) {
    if (line.rfind("xvfb-run: ", 0) == 0) continue;
    kept += line + "\n";
  }
  return kept;
}

}  // namespace

// The process's folder of temporary files, removed when the test process exits (set
// DGMM_KEEP_TEST_DIRS to keep it for a look after a failure).
struct TestDirs {
  std::filesystem::path base =
      std::filesystem::temp_directory_path() / ("dgmm-test-" + std::to_string(::getpid()));
  ~TestDirs() {
    std::error_code ec;
    if (!std::getenv("DGMM_KEEP_TEST_DIRS")) std::filesystem::remove_all(base, ec);
  }
};

std::filesystem::path MakeTempDir(const std::string& name) {
  namespace fs = std::filesystem;
  static const TestDirs dirs;
  const fs::path& base = dirs.base;
  fs::path dir = base / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::filesystem::path SourcePath(const std::string& relative) {
  return std::filesystem::path(DGMM_SOURCE_DIR) / relative;
}

int CountLines(const std::string& s) {
  std::istringstream in(s);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) n += !line.empty();
  return n;
}

RunResult RunDgmm(const std::vector<std::string>& args, const std::vector<std::string>& env) {
  const char* exe = std::getenv("DGMM_EXE");
  std::string binary = exe ? exe : std::string(DGMM_BINARY_DIR) + "/app/dgmm";
  static int counter = 0;
  auto dir = MakeTempDir("run-" + std::to_string(counter++));
  auto out_path = dir / "stdout", err_path = dir / "stderr";
  pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int in = ::open("/dev/null", O_RDONLY);
    ::dup2(in, 0);
    ::dup2(out, 1);
    ::dup2(err, 2);
    for (const auto& kv : env) ::putenv(const_cast<char*>(kv.c_str()));
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(binary.c_str()));
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  RunResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = Slurp(out_path);
  r.err = Slurp(err_path);
  std::filesystem::remove_all(dir);
  return r;
}

RunResult RunUnderXvfb(const std::vector<std::string>& args, const std::filesystem::path& dir) {
  const char* exe = std::getenv("DGMM_EXE");
  std::string binary = exe ? exe : std::string(DGMM_BINARY_DIR) + "/app/dgmm";
  // scripts/with-display.sh: $DISPLAY when set (scripts/test.sh starts one), else xvfb-run -a.
  std::string command = std::string(DGMM_SOURCE_DIR) + "/scripts/with-display.sh " + binary;
  for (const auto& a : args) command += " '" + a + "'";
  command += " >" + (dir / "out").string() + " 2>" + (dir / "err").string();
  RunResult r;
  // Concurrent `xvfb-run -a` calls (parallel ctest) can race for a display number: retry then.
  for (int attempt = 0; attempt < 3; ++attempt) {
    int status = std::system(command.c_str());
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = Slurp(dir / "out");
    r.err = WithoutXvfbRunLines(Slurp(dir / "err"));
    if (r.err.find("cannot open an X display") == std::string::npos) break;
  }
  return r;
}

}  // namespace dgmm::test
