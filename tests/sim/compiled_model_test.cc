// The compiled-model bytes behind simulation cache keys (lib/sim/compiled_model.h): they follow
// every file the model is built from (included MJCF, meshes) and not where the files are.
#include "sim/compiled_model.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace dgmm::sim {
namespace {

namespace fs = std::filesystem;

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// A binary STL tetrahedron whose apex is at height `apex_z`.
void WriteTetrahedron(const fs::path& path, float apex_z) {
  const float v[4][3] = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}, {0.03f, 0.03f, apex_z}};
  const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  std::ofstream out(path, std::ios::binary);
  const std::string header(80, ' ');
  out.write(header.data(), 80);
  const std::uint32_t n = 4;
  out.write(reinterpret_cast<const char*>(&n), 4);
  for (const auto& f : faces) {
    const float normal[3] = {0, 0, 0};
    out.write(reinterpret_cast<const char*>(normal), 12);
    for (int k : f) out.write(reinterpret_cast<const char*>(v[k]), 12);
    const std::uint16_t attribute = 0;
    out.write(reinterpret_cast<const char*>(&attribute), 2);
  }
}

// robot.xml includes legs.xml and uses foot.stl.
fs::path WriteRobot(const fs::path& dir, const std::string& leg_mass, float apex_z) {
  fs::create_directories(dir);
  WriteText(dir / "robot.xml", R"(<mujoco model="fingerprint">
  <asset><mesh name="foot" file="foot.stl"/></asset>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 0.1"/>
    <body name="torso" pos="0 0 0.3">
      <freejoint/>
      <geom type="box" size="0.1 0.05 0.02" mass="1"/>
      <include file="legs.xml"/>
    </body>
  </worldbody>
</mujoco>)");
  WriteText(dir / "legs.xml", "<mujoco><body name=\"leg\" pos=\"0.1 0 0\"><joint type=\"hinge\"/>"
                              "<geom type=\"capsule\" fromto=\"0 0 0 0 0 -0.2\" size=\"0.01\" mass=\"" +
                                  leg_mass + "\"/><geom type=\"mesh\" mesh=\"foot\" pos=\"0 0 -0.2\"/></body></mujoco>");
  WriteTetrahedron(dir / "foot.stl", apex_z);
  return dir / "robot.xml";
}

class CompiledModelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("dgmm_compiled_model_" + std::to_string(::getpid()));
    fs::remove_all(root_);
  }
  void TearDown() override { fs::remove_all(root_); }
  std::string Bytes(const fs::path& mjcf) {
    SimConfig c;
    c.mjcf_path = mjcf.string();
    return CompiledModelBytes(c);
  }
  fs::path root_;
};

TEST_F(CompiledModelTest, FollowsIncludedFilesAndMeshesNotTheFolder) {
  const std::string base = Bytes(WriteRobot(root_ / "a", "0.2", 0.05f));
  ASSERT_FALSE(base.empty());
  EXPECT_EQ(Bytes(WriteRobot(root_ / "a", "0.2", 0.05f)), base) << "same files, same bytes";
  EXPECT_EQ(Bytes(WriteRobot(root_ / "moved" / "elsewhere", "0.2", 0.05f)), base) << "the folder moved";
  EXPECT_NE(Bytes(WriteRobot(root_ / "b", "0.25", 0.05f)), base) << "an included file changed";
  EXPECT_NE(Bytes(WriteRobot(root_ / "c", "0.2", 0.08f)), base) << "a mesh changed";
}

TEST_F(CompiledModelTest, TheBuiltInRobotCompiles) {
  EXPECT_EQ(CompiledModelBytes(SimConfig{}), CompiledModelBytes(SimConfig{}));
}

TEST_F(CompiledModelTest, AMissingIncludedFileIsAnErrorNamingTheModel) {
  const fs::path mjcf = WriteRobot(root_ / "d", "0.2", 0.05f);
  fs::remove(root_ / "d" / "legs.xml");
  try {
    Bytes(mjcf);
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("robot.xml"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace dgmm::sim
