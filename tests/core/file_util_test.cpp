#include "ademono/core/file_util.h"

#include <unistd.h>
#include <string>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "ademono/core/error.h"

namespace ademono {
namespace {

namespace fs = std::filesystem;

TEST(FileUtil, ParseDoubleRejectsGarbageAndNaN) {
  EXPECT_DOUBLE_EQ(ParseDouble("1.5e3", "f.txt", 3, 0), 1500.0);
  EXPECT_DOUBLE_EQ(ParseDouble("+2", "f.txt", 3, 0), 2.0);
  EXPECT_THROW(ParseDouble("nan", "f.txt", 3, 0), InputError);
  EXPECT_THROW(ParseDouble("1.0x", "f.txt", 3, 0), InputError);
  try {
    ParseDouble("abc", "f.txt", 7, 2);
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "f.txt:7: field 3 'abc' is not a finite number");
  }
}

TEST(FileUtil, SplitFields) {
  auto f = SplitFields("  1 2\t3\r");
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[2], "3");
  auto g = SplitFields("a,b, c", true);
  ASSERT_EQ(g.size(), 3u);
  EXPECT_EQ(g[2], "c");
}

TEST(FileUtil, AtomicWriteLeavesNothingOnFailure) {
  const fs::path dir =
      fs::temp_directory_path() / ("ademono_atomic_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path target = dir / "out.txt";
  EXPECT_THROW(WriteFileAtomic(target,
                               [](std::ostream& out) {
                                 out << "partial";
                                 throw std::runtime_error("boom");
                               }),
               std::runtime_error);
  EXPECT_FALSE(fs::exists(target));
  EXPECT_TRUE(fs::is_empty(dir));
  WriteTextFileAtomic(target, "done\n");
  EXPECT_EQ(ReadTextFile(target), "done\n");
}

TEST(FileUtil, ReadImageNamesTheFile) {
  const fs::path dir =
      fs::temp_directory_path() / ("ademono_image_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path bad = dir / "broken.png";
  std::ofstream(bad) << "not a png";
  try {
    ReadImage(bad, 1);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.png: image does not decode"), std::string::npos);
  }
}

}  // namespace
}  // namespace ademono
