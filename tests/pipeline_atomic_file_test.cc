// WriteFileAtomically (base/atomic_file.h): the file appears whole or not at all, and a
// target that is not a regular file (folder, device, FIFO) is refused with its path named and
// left as it was.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "base/atomic_file.h"
#include "base/user_error.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;

namespace fs = std::filesystem;

struct TempDir {
  TempDir() {
    path = fs::temp_directory_path() / ("bifilar_atomic_" + std::to_string(::getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  fs::path path;
};

// The message of the UserError `fn` throws ("" when it throws none).
template <typename Fn>
std::string ErrorOf(Fn fn) {
  try {
    fn();
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

// Nothing but `expected` in `dir`: no temporary file left behind.
void ExpectOnly(const fs::path& dir, const std::vector<std::string>& expected) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, expected);
}

TEST(AtomicFile, WritesAndReplacesARegularFileAndCreatesFolders) {
  TempDir dir;
  const fs::path file = dir.path / "sub" / "a.txt";
  WriteFileAtomically(file.string(), "first");
  EXPECT_EQ(ReadFile(file), "first");
  WriteFileAtomically(file.string(), std::string("second\0with nul", 15));
  EXPECT_EQ(ReadFile(file), std::string("second\0with nul", 15));
  ExpectOnly(dir.path / "sub", {"a.txt"});
  EXPECT_EQ(AtomicTemporaryName("x/y.json"), "x/y.json.tmp." + std::to_string(::getpid()));
}

TEST(AtomicFile, RefusesAFolder) {
  TempDir dir;
  fs::create_directories(dir.path / "results.json");
  const std::string target = (dir.path / "results.json").string();
  const std::string message = ErrorOf([&] { WriteFileAtomically(target, "x"); });
  EXPECT_EQ(message, target + ": is a folder, expected a file name");
  EXPECT_TRUE(fs::is_directory(target));
  ExpectOnly(dir.path, {"results.json"});
}

TEST(AtomicFile, RefusesAFifoAndLeavesItAFifo) {
  TempDir dir;
  const fs::path fifo = dir.path / "traces.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string message = ErrorOf([&] { WriteFileAtomically(fifo.string(), "x"); });
  EXPECT_EQ(message.rfind(fifo.string() + ": exists and is not a regular file", 0), 0u) << message;
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  ExpectOnly(dir.path, {"traces.csv"});
  // A link to it is refused as a link.
  fs::create_symlink(fifo, dir.path / "link.csv");
  EXPECT_NE(ErrorOf([&] {
              WriteFileAtomically((dir.path / "link.csv").string(), "x");
            }).find("is a symbolic link"),
            std::string::npos);
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir.path / "link.csv")));
}

TEST(AtomicFile, RefusesADevice) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  // Through a link in our own folder: were the check ever lost, the rename would replace the
  // link, never /dev/full itself (the tests may run as root).
  TempDir dir;
  const fs::path link = dir.path / "report.html";
  fs::create_symlink("/dev/full", link);
  const std::string message = ErrorOf([&] { WriteFileAtomically(link.string(), "x"); });
  EXPECT_EQ(message.rfind(link.string() + ": is a symbolic link (to /dev/full)", 0), 0u) << message;
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
  ExpectOnly(dir.path, {"report.html"});
}

// Issue 23: a link is neither replaced nor written through, whatever it points to: a regular
// file, a dangling name, or /proc/self/fd/1 (what /dev/stdout is; the link lives in our folder,
// the real /dev/stdout is never touched).
TEST(AtomicFile, RefusesASymbolicLinkAndLeavesItAndItsTarget) {
  TempDir dir;
  std::ofstream(dir.path / "real.txt") << "real";
  fs::create_symlink(dir.path / "real.txt", dir.path / "link.txt");
  fs::create_symlink(dir.path / "nothing", dir.path / "dangling.txt");
  fs::create_symlink("/proc/self/fd/1", dir.path / "stdout");
  for (const char* name : {"link.txt", "dangling.txt", "stdout"}) {
    const std::string link = (dir.path / name).string();
    const std::string message = ErrorOf([&] { WriteFileAtomically(link, "new"); });
    EXPECT_EQ(message.rfind(link + ": is a symbolic link", 0), 0u) << message;
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link))) << name;
    EXPECT_NE(ErrorOf([&] { CheckFileTarget(link); }), "") << name;
  }
  EXPECT_EQ(ReadFile(dir.path / "real.txt"), "real");
  ExpectOnly(dir.path, {"dangling.txt", "link.txt", "real.txt", "stdout"});
}

// Issue 23: a 255-byte name (the most ext4 allows) is written through a short temporary name;
// a longer one is refused with the reason.
TEST(AtomicFile, WritesA255ByteNameAndRefusesALongerOneWithTheReason) {
  TempDir dir;
  const std::string longest(255, 'a');
  const std::string temp = AtomicTemporaryName((dir.path / longest).string());
  EXPECT_LE(fs::path(temp).filename().string().size(), 255u);
  EXPECT_EQ(fs::path(temp).parent_path(), dir.path);
  WriteFileAtomically((dir.path / longest).string(), "x");
  EXPECT_EQ(ReadFile(dir.path / longest), "x");
  ExpectOnly(dir.path, {longest});
  const std::string too_long = (dir.path / std::string(256, 'b')).string();
  const std::string message = ErrorOf([&] { WriteFileAtomically(too_long, "x"); });
  EXPECT_NE(
      message.find("the file name is 256 bytes long, more than this file system allows (255)"),
      std::string::npos)
      << message;
  ExpectOnly(dir.path, {longest});
}

TEST(AtomicFile, RefuseToReplaceNamesTheFileAndHonoursForce) {
  TempDir dir;
  const std::string file = (dir.path / "mine.csv").string();
  EXPECT_EQ(ErrorOf([&] { RefuseToReplace(file, "simulate --trace", false); }), "");
  std::ofstream(file) << "mine";
  EXPECT_EQ(
      ErrorOf([&] { RefuseToReplace(file, "simulate --trace", false); }),
      "simulate --trace: " + file + " exists; choose another name, or add --force to overwrite it");
  EXPECT_EQ(ErrorOf([&] { RefuseToReplace(file, "simulate --trace", true); }), "");
}

}  // namespace
}  // namespace bifilar
