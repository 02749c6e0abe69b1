// Temporary outputs: removed when SIGTERM/SIGINT ends the process, stale ones of dead processes
// removed; output paths that are an input refused; whole folders swapped in at once.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "util/atomic_dir.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/output_guard.h"
#include "util/temp_registry.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("dgmm_temps_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

int CountTemps(const fs::path& dir) {
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    n += e.path().filename().string().find(".tmp-") != std::string::npos;
  }
  return n;
}

std::string Read(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), {}};
}

// A child writes a temporary file and a temporary folder, tells the parent, and waits to be
// killed: after `sig` nothing named *.tmp-* may remain.
void ExpectCleanupOn(int sig) {
  const fs::path dir = FreshDir("signal" + std::to_string(sig));
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    AtomicFile file(dir / "out.h5");
    std::ofstream(file.temp_path()) << std::string(1 << 20, 'x');
    AtomicDir folder(dir / "report", "report.json");
    std::ofstream(folder.temp_path() / "a.png") << "png";
    fs::create_directory(folder.temp_path() / "sub");
    std::ofstream(folder.temp_path() / "sub" / "b.txt") << "b";
    (void)!write(ready[1], "x", 1);
    for (;;) pause();
  }
  char c;
  ASSERT_EQ(read(ready[0], &c, 1), 1);
  EXPECT_EQ(CountTemps(dir), 2 + 0);  // the file and the folder (its contents are inside it)
  kill(child, sig);
  int status = 0;
  waitpid(child, &status, 0);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "the signal is re-raised";
  EXPECT_EQ(CountTemps(dir), 0);
  EXPECT_FALSE(fs::exists(dir / "out.h5"));
  EXPECT_FALSE(fs::exists(dir / "report"));
  close(ready[0]);
  close(ready[1]);
  fs::remove_all(dir);
}

TEST(TempCleanup, SigtermRemovesTemporaryFilesAndFolders) { ExpectCleanupOn(SIGTERM); }
TEST(TempCleanup, SigintRemovesTemporaryFilesAndFolders) { ExpectCleanupOn(SIGINT); }

TEST(TempCleanup, StaleTempsOfDeadProcessesAreRemoved) {
  const fs::path dir = FreshDir("stale");
  // pid_max is at most 4194304: this process cannot exist.
  std::ofstream(dir / "m.h5.tmp-99999999-0") << "stale";
  std::ofstream(dir / ("m.h5.tmp-" + std::to_string(::getpid()) + "-77")) << "live";
  std::ofstream(dir / "m.h5.tmp-notapid") << "not ours";
  long pid = 0;
  EXPECT_TRUE(IsTempName("m.h5.tmp-123-4", "m.h5", &pid));
  EXPECT_EQ(pid, 123);
  EXPECT_FALSE(IsTempName("m.h5.tmp-12a-4", "m.h5", &pid));
  { AtomicFile file(dir / "m.h5"); }
  EXPECT_FALSE(fs::exists(dir / "m.h5.tmp-99999999-0"));
  EXPECT_TRUE(fs::exists(dir / ("m.h5.tmp-" + std::to_string(::getpid()) + "-77")));
  EXPECT_TRUE(fs::exists(dir / "m.h5.tmp-notapid"));
  fs::remove_all(dir);
}

TEST(OutputGuard, SameInodeIsRefusedWhateverTheSpelling) {
  const fs::path dir = FreshDir("guard");
  std::ofstream(dir / "in.h5") << "data";
  fs::create_hard_link(dir / "in.h5", dir / "link.h5");
  fs::create_symlink(dir / "in.h5", dir / "sym.h5");
  for (const fs::path& out : {dir / "in.h5", dir / "." / "in.h5", dir / "link.h5", dir / "sym.h5"}) {
    EXPECT_THROW(RefuseOutputThatIsAnInput(out.string(), {(dir / "in.h5").string()}), InputError)
        << out;
  }
  EXPECT_NO_THROW(RefuseOutputThatIsAnInput((dir / "new.h5").string(), {(dir / "in.h5").string()}));
  std::ofstream(dir / "copy.h5") << "data";
  EXPECT_FALSE(SameFile((dir / "copy.h5").string(), (dir / "in.h5").string()));
  EXPECT_TRUE(SameContent((dir / "copy.h5").string(), (dir / "in.h5").string()));
  EXPECT_EQ(Read(dir / "in.h5"), "data");
  fs::remove_all(dir);
}

TEST(AtomicDirTest, CommitReplacesTheWholeFolderAndAbandonLeavesTheOldOne) {
  const fs::path dir = FreshDir("atomicdir");
  fs::create_directory(dir / "report");
  std::ofstream(dir / "report" / "report.json") << "old";
  std::ofstream(dir / "report" / "old_figure.png") << "old";
  {
    AtomicDir out(dir / "report", "report.json");
    std::ofstream(out.temp_path() / "report.json") << "abandoned";
  }  // no Commit: the old result stays as it was
  EXPECT_EQ(Read(dir / "report" / "report.json"), "old");
  EXPECT_EQ(CountTemps(dir), 0);
  {
    AtomicDir out(dir / "report", "report.json");
    std::ofstream(out.temp_path() / "report.json") << "new";
    out.Commit();
  }
  EXPECT_EQ(Read(dir / "report" / "report.json"), "new");
  EXPECT_FALSE(fs::exists(dir / "report" / "old_figure.png")) << "nothing of the old run is kept";
  EXPECT_EQ(CountTemps(dir), 0);
  // A folder that is not an earlier result is refused, not replaced.
  fs::create_directory(dir / "home");
  std::ofstream(dir / "home" / "thesis.tex") << "precious";
  EXPECT_THROW(AtomicDir(dir / "home", "report.json"), InputError);
  EXPECT_EQ(Read(dir / "home" / "thesis.tex"), "precious");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dgmm
