// Ctrl-C (base/interrupt.h): SIGINT sent to `bifilar process` mid-campaign stops it with exit
// code 130, a message saying what was finished, the finished fits in the cache and no result
// file; the next run goes on from the cache.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include <gtest/gtest.h>

#include "test_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;
using test_support::TempDir;

// Starts `bifilar process` on the sample campaign with one worker, stderr to `err`.
pid_t StartProcess(const std::string& out, const std::string& err) {
  const pid_t pid = fork();
  if (pid == 0) {
    FILE* f = std::freopen(err.c_str(), "w", stderr);
    if (f == nullptr || std::freopen("/dev/null", "w", stdout) == nullptr) _exit(99);
    const std::string config = std::string(BIFILAR_SOURCE_DIR) + "/configs/prandtl_d.yaml";
    execl(BIFILAR_BINARY, BIFILAR_BINARY, "process", config.c_str(), "--out", out.c_str(), "--jobs",
          "1", static_cast<char*>(nullptr));
    _exit(98);
  }
  return pid;
}

// Waits for the child; -1 if it is still running after `bound` (then it is killed).
int WaitBounded(pid_t pid, std::chrono::seconds bound) {
  const auto end = std::chrono::steady_clock::now() + bound;
  int status = 0;
  while (std::chrono::steady_clock::now() < end) {
    if (waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -2;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  return -1;
}

TEST(CtrlC, ProcessStopsKeepsTheCacheAndWritesNoResult) {
  TempDir dir;
  const std::string out = dir.path + "/out", err = dir.path + "/err.txt";
  const pid_t pid = StartProcess(out, err);
  ASSERT_GT(pid, 0);
  // Wait for the third finished fit (one line per fit: stderr is not a terminal).
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (ReadFile(err).find("fit 3/") == std::string::npos &&
         std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_NE(ReadFile(err).find("fit 3/"), std::string::npos) << ReadFile(err);
  kill(pid, SIGINT);
  // The bound only guards against a hang; a fit of the sample takes ~50 ms.
  EXPECT_EQ(WaitBounded(pid, std::chrono::seconds(60)), 130) << ReadFile(err);
  const std::string message = ReadFile(err);
  EXPECT_NE(message.find("bifilar: interrupted: "), std::string::npos) << message;
  EXPECT_NE(message.find("kept in"), std::string::npos) << message;
  EXPECT_FALSE(std::filesystem::exists(out + "/results.json"));
  EXPECT_FALSE(std::filesystem::exists(out + "/traces.csv"));
  int cached = 0;
  for (const auto& entry : std::filesystem::directory_iterator(out + "/cache")) {
    cached += entry.path().extension() == ".json";
  }
  EXPECT_GE(cached, 3);
  EXPECT_LT(cached, 57);  // the sample has 57 logs: it stopped early
  // The next run finishes, reusing what was fitted (exit 0: every log fits).
  const pid_t again = StartProcess(out, err);
  EXPECT_EQ(WaitBounded(again, std::chrono::seconds(300)), 0) << ReadFile(err);
  EXPECT_TRUE(std::filesystem::exists(out + "/results.json"));
}

}  // namespace
}  // namespace bifilar
