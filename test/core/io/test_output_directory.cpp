// OutputDirectory: the rules every file-writing service follows (issue 17: a service call could
// overwrite any file the node's user can write).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "downstream_perception/core/io/output_directory.h"

using namespace downstream_perception;  // NOLINT
namespace fs = std::filesystem;

namespace {

class OutputDirectoryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "dp_output_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    root_ = pattern;
    dir_ = root_ / "out";
    victim_ = root_ / "victim.txt";
    std::ofstream(victim_) << "precious";
  }
  void TearDown() override { fs::remove_all(root_); }

  static std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  /// Everything in the output directory (a failed or refused write must leave nothing behind).
  std::size_t entries() const {
    if (!fs::exists(dir_)) return 0;
    return static_cast<std::size_t>(
        std::distance(fs::recursive_directory_iterator(dir_), fs::recursive_directory_iterator()));
  }

  fs::path root_, dir_, victim_;
};

}  // namespace

TEST_F(OutputDirectoryTest, WritesANameInsideAndSaysWhere) {
  const OutputDirectory out(dir_.string());
  const OutputFileResult r = out.write("room.ply", ".ply", "ply bytes", false);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.path, (dir_ / "room.ply").string());
  EXPECT_EQ(read(r.path), "ply bytes");
  EXPECT_EQ(entries(), 1u);  // no temporary left
}

TEST_F(OutputDirectoryTest, CreatesSubdirectoriesInside) {
  const OutputDirectory out(dir_.string() + "/");
  const OutputFileResult r = out.write("runs/./a/room.bt", ".bt", "bt", false);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.path, (dir_ / "runs/a/room.bt").string());
  EXPECT_EQ(read(dir_ / "runs/a/room.bt"), "bt");
}

TEST_F(OutputDirectoryTest, RefusesANulByteThatHidesAnotherExtension) {
  const OutputDirectory out(dir_.string());
  const std::string name = std::string("victim.txt") + '\0' + ".ply";
  const OutputFileResult r = out.write(name, ".ply", "x", true);
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.error.find("NUL"), std::string::npos) << r.error;
  EXPECT_EQ(entries(), 0u);
}

TEST_F(OutputDirectoryTest, RefusesAbsolutePathsAndEscapes) {
  const OutputDirectory out(dir_.string());
  for (const std::string& name : {victim_.string() + ".ply", std::string("../victim.ply"),
                                  std::string("a/../../victim.ply"), std::string("a/../b.ply")}) {
    const OutputFileResult r = out.write(name, ".ply", "x", true);
    EXPECT_FALSE(r.ok()) << name;
  }
  EXPECT_FALSE(fs::exists(root_ / "victim.ply"));
  EXPECT_EQ(read(victim_), "precious");
}

TEST_F(OutputDirectoryTest, NeverFollowsASymlink) {
  fs::create_directories(dir_);
  fs::create_symlink(victim_, dir_ / "mesh.ply");
  fs::create_directory_symlink(root_, dir_ / "up");
  const OutputDirectory out(dir_.string());
  const OutputFileResult leaf = out.write("mesh.ply", ".ply", "x", true);
  EXPECT_FALSE(leaf.ok());
  EXPECT_NE(leaf.error.find("not a regular file"), std::string::npos) << leaf.error;
  const OutputFileResult sub = out.write("up/victim.ply", ".ply", "x", true);
  EXPECT_FALSE(sub.ok());
  EXPECT_EQ(read(victim_), "precious");
  EXPECT_FALSE(fs::exists(root_ / "victim.ply"));
  EXPECT_TRUE(fs::is_symlink(dir_ / "mesh.ply"));
}

TEST_F(OutputDirectoryTest, KeepsAnExistingFileUnlessAskedToOverwrite) {
  const OutputDirectory out(dir_.string());
  ASSERT_TRUE(out.write("m.ply", ".ply", "first", false).ok());
  const OutputFileResult kept = out.write("m.ply", ".ply", "second", false);
  EXPECT_FALSE(kept.ok());
  EXPECT_NE(kept.error.find("exists"), std::string::npos);
  EXPECT_EQ(read(dir_ / "m.ply"), "first");
  ASSERT_TRUE(out.write("m.ply", ".ply", "second", true).ok());
  EXPECT_EQ(read(dir_ / "m.ply"), "second");
  EXPECT_EQ(entries(), 1u);
}

TEST_F(OutputDirectoryTest, RefusesAHugeNameWithoutEchoingIt) {
  const OutputDirectory out(dir_.string());
  const std::string name(1 << 20, 'a');
  const OutputFileResult r = out.write(name + ".ply", ".ply", "x", false);
  EXPECT_FALSE(r.ok());
  EXPECT_LT(r.error.size(), 300u);
  const OutputFileResult component = out.write(std::string(300, 'b') + ".ply", ".ply", "x", false);
  EXPECT_FALSE(component.ok());
  EXPECT_EQ(entries(), 0u);
}

TEST_F(OutputDirectoryTest, RefusesOtherExtensionsEmptyNamesAndControlCharacters) {
  const OutputDirectory out(dir_.string());
  for (const std::string name : {"room.obj", ".ply", "", "dir/", "a\nb.ply", "./"}) {
    EXPECT_FALSE(out.write(name, ".ply", "x", true).ok()) << "'" << name << "'";
  }
  EXPECT_EQ(entries(), 0u);
}

TEST_F(OutputDirectoryTest, RefusesARelativeOutputDirectory) {
  const OutputDirectory out("relative/out");
  EXPECT_FALSE(out.write("m.ply", ".ply", "x", false).ok());
  EXPECT_FALSE(fs::exists("relative"));
}

TEST(ShortenForMessage, CutsAndMasks) {
  EXPECT_EQ(shortenForMessage("ab\ncd", 80), "ab?cd");
  EXPECT_EQ(shortenForMessage(std::string(100, 'x'), 4), "xxxx... (100 bytes)");
}
