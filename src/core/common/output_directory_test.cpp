#include "hrg_gyro/core/common/output_directory.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace hrg_gyro {
namespace core {
namespace {

namespace fs = std::filesystem;

class OutputDirectoryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("hrg_gyro_outdir_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    fs::remove_all(root_);
    fs::create_directories(root_ / "out" / "sub");
    fs::create_directories(root_ / "outside");
    fs::create_directories(root_ / "outer");
    fs::create_directory_symlink(root_ / "outside", root_ / "out" / "link");
  }
  void TearDown() override { fs::remove_all(root_); }
  std::string at(const std::string& relative) const { return (root_ / relative).string(); }
  fs::path root_;
};

TEST_F(OutputDirectoryTest, AcceptsFilesInsideAndInSubdirectories) {
  EXPECT_TRUE(isInsideDirectory(at("out/params.yaml"), at("out")));
  EXPECT_TRUE(isInsideDirectory(at("out/sub/params.report.yaml"), at("out")));
  EXPECT_TRUE(isInsideDirectory(at("out/./params.yaml"), at("out/")));
}

TEST_F(OutputDirectoryTest, RefusesEscapesByDotDotLinksAndPrefixes) {
  EXPECT_FALSE(isInsideDirectory(at("out/../outside/params.yaml"), at("out")));
  EXPECT_FALSE(isInsideDirectory(at("out/link/params.yaml"), at("out")));  // a link leading out
  EXPECT_FALSE(isInsideDirectory(at("outer/params.yaml"), at("out")));     // a name prefix is not a parent
  EXPECT_FALSE(isInsideDirectory("/etc/passwd", at("out")));
}

TEST_F(OutputDirectoryTest, FollowsALinkAtTheFileItself) {
  // The writer replaces the file a link points to: a link inside the directory is judged by its
  // destination, relative or absolute, dangling (the file a write would create) or not.
  fs::create_symlink(root_ / "outside" / "params.yaml", root_ / "out" / "absolute.yaml");
  fs::create_symlink("../outside/report.yaml", root_ / "out" / "relative.yaml");
  std::ofstream(root_ / "outside" / "params.yaml") << "k: 1\n";
  EXPECT_FALSE(isInsideDirectory(at("out/absolute.yaml"), at("out")));
  EXPECT_FALSE(isInsideDirectory(at("out/relative.yaml"), at("out")));  // dangling, leads out
  fs::create_symlink("sub/params.yaml", root_ / "out" / "inside.yaml");
  EXPECT_TRUE(isInsideDirectory(at("out/inside.yaml"), at("out")));
  fs::create_symlink("loop_b.yaml", root_ / "out" / "loop_a.yaml");
  fs::create_symlink("loop_a.yaml", root_ / "out" / "loop_b.yaml");
  EXPECT_FALSE(isInsideDirectory(at("out/loop_a.yaml"), at("out")));
}

TEST_F(OutputDirectoryTest, RefusesWhatDoesNotExist) {
  EXPECT_FALSE(isInsideDirectory(at("out/missing/params.yaml"), at("out")));
  EXPECT_FALSE(isInsideDirectory(at("out/params.yaml"), at("nowhere")));
}

TEST(DirectoryOfTest, SplitsAtTheLastSlash) {
  EXPECT_EQ(directoryOf("/a/b/c.yaml"), "/a/b");
  EXPECT_EQ(directoryOf("/c.yaml"), "/");
  EXPECT_EQ(directoryOf("c.yaml"), ".");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
