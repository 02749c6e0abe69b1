// Untrusted files and careless paths (issue #13): mutated version-2 files give one line and a
// non-zero exit, never a signal; an output that is an input is refused and the input untouched;
// a refused sim2real leaves an older result as it was; a full disk is an error, not a crash.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "tests/app/run_dgmm.h"

namespace dgmm::test {
namespace {

namespace fs = std::filesystem;

std::string Slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void Spit(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

class Untrusted : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = MakeTempDir(std::string("untrusted-") +
                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string P(const std::string& name) const { return (dir_ / name).string(); }
  // A small set and its model, both version 2.
  void MakeSetAndModel() {
    std::string csv = "c,x,y,z\n";
    for (int i = 0; i < 200; ++i) {
      csv += std::to_string(i % 2) + "," + std::to_string(0.1 * (i % 13)) + "," +
             std::to_string(0.2 * (i % 7)) + "," + std::to_string(0.05 * (i % 11)) + "\n";
    }
    Spit(P("set.csv"), csv);
    ASSERT_EQ(RunDgmm({"import", P("set.csv"), "-o", P("set.h5"), "--command-cols", "c",
                       "--pose-cols", "x,y", "--terrain-cols", "z"})
                  .exit_code,
              0);
    RunResult r = RunDgmm({"fit", P("set.h5"), "-o", P("m.h5")});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  // Runs args: never a signal; a failure is one line on stderr.
  void ExpectNoCrash(const std::vector<std::string>& args, const std::string& what) {
    RunResult r = RunDgmm(args);
    ASSERT_NE(r.exit_code, -1) << what << ": killed by a signal\n" << r.err;
    if (r.exit_code != 0) EXPECT_EQ(CountLines(r.err), 1) << what << "\n" << r.err;
  }
  fs::path dir_;
};

TEST_F(Untrusted, MutatedFilesNeverCrash) {
  MakeSetAndModel();
  std::mt19937_64 rng(13);
  for (const std::string name : {"set.h5", "m.h5"}) {
    const std::string bytes = Slurp(P(name));
    const bool model = name == "m.h5";
    auto run = [&](const std::string& file, const std::string& what) {
      if (model) {
        ExpectNoCrash({"export", file, "-o", P("out.json")}, what);
      } else {
        ExpectNoCrash({"info", file}, what);
        ExpectNoCrash({"fit", file, "-o", P("out.h5")}, what);
      }
    };
    // Truncations, including inside the superblock and the metadata at the end.
    for (size_t cut : {size_t{0}, size_t{8}, size_t{47}, bytes.size() / 3, bytes.size() / 2,
                       bytes.size() - 100, bytes.size() - 1}) {
      Spit(P("cut.h5"), bytes.substr(0, cut));
      run(P("cut.h5"), name + " cut at " + std::to_string(cut));
    }
    // Byte flips: in the first 4 KiB (superblock, root object header) and anywhere.
    for (int trial = 0; trial < 12; ++trial) {
      std::string mutated = bytes;
      const size_t span = trial % 2 ? mutated.size() : std::min<size_t>(4096, mutated.size());
      for (int k = 0; k < 1 + trial % 3; ++k) {
        mutated[rng() % span] ^= static_cast<char>(1 + rng() % 255);
      }
      Spit(P("flip.h5"), mutated);
      run(P("flip.h5"), name + " flip trial " + std::to_string(trial));
    }
  }
}

TEST_F(Untrusted, OutputThatIsAnInputIsRefusedAndTheInputUntouched) {
  MakeSetAndModel();
  const std::string set = Slurp(P("set.h5")), model = Slurp(P("m.h5")), csv = Slurp(P("set.csv"));
  fs::create_symlink(P("set.h5"), P("alias.h5"));
  const std::vector<std::vector<std::string>> cases = {
      {"fit", P("set.h5"), "-o", P("set.h5")},
      {"fit", P("set.h5"), "-o", (dir_ / "." / "set.h5").string()},
      {"fit", P("set.h5"), "-o", P("alias.h5")},
      {"em", P("set.h5"), "-o", P("set.h5")},
      {"export", P("m.h5"), "-o", P("m.h5")},
      {"import", P("set.csv"), "-o", P("set.csv"), "--pose-cols", "x,y"},
      {"upgrade", P("set.h5"), "-o", P("set.h5")},
      // Found by scripts/bad_input_battery.py: these overwrote their input.
      {"import-log", "--commands", P("set.csv"), "--pose", P("set.csv"), "--pose-cols", "x,y",
       "-o", P("set.csv")},
      {"tune", P("set.h5"), "--curve-csv", P("set.h5")},
      {"tune", P("set.h5"), "--plot", P("set.h5")},
      {"render", P("m.h5"), "--data", P("set.h5"), "-o", P("set.h5")},
  };
  for (const auto& args : cases) {
    RunResult r = RunDgmm(args);
    EXPECT_GE(r.exit_code, 1) << args[0];
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("is the same file as the input"), std::string::npos) << r.err;
  }
  EXPECT_EQ(Slurp(P("set.h5")), set);
  EXPECT_EQ(Slurp(P("m.h5")), model);
  EXPECT_EQ(Slurp(P("set.csv")), csv);
  Spit(P("c.json"), "{}\n");
  RunResult r = RunDgmm({"simulate", "--config", P("c.json"), "-o", P("c.json")});
  EXPECT_NE(r.err.find("is the same file as the input"), std::string::npos) << r.err;
  EXPECT_EQ(Slurp(P("c.json")), "{}\n");
}

TEST_F(Untrusted, RefusedSim2RealLeavesTheOlderResultAndCreatesNothing) {
  const std::string sim = SourcePath("datasets/sim2real/sim.h5").string();
  const std::string real = SourcePath("datasets/sim2real/slip/real.h5").string();
  fs::create_directory(P("report"));
  Spit(P("report/report.json"), "{\"old\": true}\n");
  Spit(P("report/figure.png"), "old png");
  fs::copy_file(sim, P("sim_copy.h5"));
  Spit(P("bad.json"), "{ not json");
  const std::vector<std::vector<std::string>> refused = {
      {"sim2real", "--sim", sim, "--real", sim, "-o", P("report")},
      {"sim2real", "--sim", sim, "--real", P("sim_copy.h5"), "-o", P("report")},
      {"sim2real", "--sim", sim, "--real", real, "--sim-config", P("bad.json"), "-o", P("report")},
      {"sim2real", "--sim", sim, "--real", real, "--sim-config", dir_.string(), "-o", P("report")},
      {"sim2real", "--sim", sim, "--real", sim, "-o", P("new_report")},
  };
  for (const auto& args : refused) {
    RunResult r = RunDgmm(args);
    EXPECT_GE(r.exit_code, 1) << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
  }
  EXPECT_EQ(Slurp(P("report/report.json")), "{\"old\": true}\n");
  EXPECT_EQ(Slurp(P("report/figure.png")), "old png");
  EXPECT_FALSE(fs::exists(P("new_report"))) << "a refused run creates no folder";
  for (const auto& e : fs::directory_iterator(dir_)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  }
  // A folder that is not an earlier report is never replaced.
  fs::create_directory(P("notes"));
  Spit(P("notes/thesis.tex"), "precious");
  RunResult r = RunDgmm({"sim2real", "--sim", sim, "--real", real, "-o", P("notes")});
  EXPECT_GE(r.exit_code, 1);
  EXPECT_NE(r.err.find("report.json"), std::string::npos) << r.err;
  EXPECT_EQ(Slurp(P("notes/thesis.tex")), "precious");
}

// Exit status of `bash -c script` (-1 when a signal ended dgmm, as a shell reports 128 + n).
int Shell(const std::string& script) {
  const int status = std::system(("bash -c '" + script + "'").c_str());
  if (!WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

TEST_F(Untrusted, FullDiskIsAnErrorNotACrash) {
  std::string csv = "x,y\n";
  for (int i = 0; i < 40000; ++i) csv += std::to_string(i * 0.37) + "," + std::to_string(i % 97) + "\n";
  Spit(P("big.csv"), csv);
  const char* exe = std::getenv("DGMM_EXE");
  ASSERT_NE(exe, nullptr);
  // ulimit -f 16: at most 16 KiB per file, so the sample set cannot be written.
  const int code = Shell(std::string("ulimit -f 16; ") + exe + " import " + P("big.csv") +
                         " -o " + P("out.h5") + " --pose-cols x,y 2> " + P("err.txt"));
  EXPECT_GE(code, 1);
  EXPECT_LT(code, 128) << "a signal (128 + n) ended dgmm: " << Slurp(P("err.txt"));
  EXPECT_EQ(CountLines(Slurp(P("err.txt"))), 1) << Slurp(P("err.txt"));
  EXPECT_FALSE(fs::exists(P("out.h5")));
  for (const auto& e : fs::directory_iterator(dir_)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  }
}

}  // namespace
}  // namespace dgmm::test
