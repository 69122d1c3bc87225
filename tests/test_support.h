// What several tests share: files, a temporary folder, the `bifilar fit` config of the
// quadrotor rig (the real Crazyflie logs and the simulator's preset), and that preset
// simulated with its glitches changed, and where the real logs are (BIFILAR_REAL_DATA).
// Header-only; include from tests only.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "base/user_error.h"
#include "pipeline/config/config.h"

namespace bifilar {
namespace test_support {

// True when `text` holds `part` (messages, pages and files checked for a phrase).
inline bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

inline std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Writes `text` to `path` (creating its folder) and returns the path.
inline std::string WriteFile(const std::string& path, const std::string& text) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A fresh folder /tmp/<prefix>_XXXXXX, removed with everything in it at the end of the scope.
struct TempDir {
  std::string path;
  explicit TempDir(const std::string& prefix = "bifilar_test") {
    std::string tmpl = "/tmp/" + prefix + "_XXXXXX";
    path = mkdtemp(tmpl.data());
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

// One run of the `bifilar` binary: its exit code (-1 when it did not exit), stdout and stderr.
struct CliRun {
  int exit_code = -1;
  std::string out, err;
};

// Runs `bifilar ARGS` with its output in `dir` (stdout.txt, stderr.txt).
inline CliRun Bifilar(const TempDir& dir, const std::string& args) {
  const std::string out = dir.path + "/stdout.txt", err = dir.path + "/stderr.txt";
  const int status =
      std::system((std::string(BIFILAR_BINARY) + " " + args + " >" + out + " 2>" + err).c_str());
  CliRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = ReadFile(out);
  r.err = ReadFile(err);
  return r;
}

// The config `bifilar fit` reads: geometry, mass, IMU format (no runs).
inline CampaignConfig LoadFitConfig(const std::string& path) {
  ConfigLoadOptions options;
  options.require_runs = false;
  return LoadCampaignConfig(path, options);
}

// The quadrotor rig with only geometry, mass and format configured: l 0.594 m, D 0.030 m,
// g 9.8066, time t (s), gyro wx, wy, wz (rad/s), no accelerometer. Mass 34.3 g: the BaseModel
// logs and the simulator's preset; 38.1 g: the NarrowMedium logs.
inline std::string QuadrotorFitConfig(double mass_kg = 0.0343) {
  char text[512];
  std::snprintf(text, sizeof(text),
                "gravity_mps2: 9.8066\n"
                "rig: {filar_length_m: 0.594, filar_separation_m: 0.030, mass_kg: %.4f}\n"
                "imu:\n  time: {column: t, unit: s}\n"
                "  gyro: {columns: [wx, wy, wz], unit: rad/s}\n  accel: null\n",
                mass_kg);
  return text;
}

// The quadrotor preset (30 Hz radio timestamps of 8-160 ms, coloured noise, a footer) simulated
// into `dir` with its one glitch replaced by `spike_count` glitches of `rate` rad/s (same seed,
// so the logs differ only in the glitch samples). Returns the output folder.
inline std::string SimulateQuadrotor(const TempDir& dir, int spike_count, double rate) {
  std::string preset =
      ReadFile(std::string(BIFILAR_SOURCE_DIR) + "/configs/simulate_quadrotor.yaml");
  const size_t count_at = preset.find("spike_count: 1");
  const size_t rate_at = preset.find("spike_rate_rad_per_s: 5");
  EXPECT_NE(count_at, std::string::npos);
  EXPECT_NE(rate_at, std::string::npos);
  char rate_text[64];
  std::snprintf(rate_text, sizeof(rate_text), "spike_rate_rad_per_s: %g", rate);
  preset.replace(rate_at, std::strlen("spike_rate_rad_per_s: 5"), rate_text);
  preset.replace(count_at, std::strlen("spike_count: 1"),
                 "spike_count: " + std::to_string(spike_count));
  const std::string name =
      "q_" + std::to_string(spike_count) + "_" + std::to_string(static_cast<int>(rate));
  WriteFile(dir.path + "/" + name + ".yaml", preset);
  const std::string command = std::string(BIFILAR_BINARY) + " simulate " + dir.path + "/" + name +
                              ".yaml --out " + dir.path + "/" + name + " > /dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0);
  return dir.path + "/" + name;
}

// The real logs (Crazyflie CSV in crazyflie/, PX4 ULog in px4/; their README says where they come
// from) live outside the repository, in a folder named by the environment variable
// BIFILAR_DATA_DIR. CTest sets it from the CMake cache variable of the same name for the tests
// labelled `realdata` (the list in tests/CMakeLists.txt); scripts/test.sh names ../shared/data
// when that folder is beside the checkout. What a real-data test does:
//   - no folder named: skipped, saying so (a newcomer without the data gets a green suite, and
//     scripts/test.sh prints how many real-data tests did not run);
//   - a folder named, but it or the file asked for is missing: FAILS (data that CI has cannot
//     vanish without a red suite);
//   - run by CTest without the `realdata` label (a new real-data test not yet in the list):
//     FAILS, naming the list.
enum class RealData { kFound, kNotNamed, kMissing, kUnlabelled };

// Finds `relative` ("crazyflie", "px4/sample_log_small.ulg") in the data folder: sets `*path`
// (always, so a message can name it) and, unless found, `*why`.
inline RealData FindRealData(const std::string& relative, std::string* path, std::string* why) {
  const char* label = std::getenv("BIFILAR_REALDATA_LABEL");  // "0": CTest, not labelled
  const char* dir = std::getenv("BIFILAR_DATA_DIR");
  *path = std::string(dir != nullptr ? dir : "") + "/" + relative;
  if (label != nullptr && std::string(label) == "0") {
    *why = "this test reads real data (" + relative +
           ") but CTest runs it without the label realdata: add its name to realdata_tests in "
           "tests/CMakeLists.txt";
    return RealData::kUnlabelled;
  }
  if (dir == nullptr || *dir == '\0') {
    *why =
        "real data not run: no data folder named (BIFILAR_DATA_DIR; cmake "
        "-DBIFILAR_DATA_DIR=DIR, or scripts/test.sh with ../shared/data beside the checkout)";
    return RealData::kNotNamed;
  }
  std::error_code ec;
  if (!std::filesystem::exists(*path, ec)) {
    *why = "the data folder named by BIFILAR_DATA_DIR has no " + *path;
    return RealData::kMissing;
  }
  return RealData::kFound;
}

// In a TEST body: declares std::string `var`, the path of `relative` in the data folder, or
// ends the test as FindRealData says (skip when no folder is named, failure otherwise).
#define BIFILAR_REAL_DATA(var, relative)                                               \
  std::string var;                                                                     \
  do {                                                                                 \
    std::string bifilar_real_data_why;                                                 \
    const ::bifilar::test_support::RealData bifilar_real_data_found =                  \
        ::bifilar::test_support::FindRealData(relative, &var, &bifilar_real_data_why); \
    if (bifilar_real_data_found == ::bifilar::test_support::RealData::kNotNamed)       \
      GTEST_SKIP() << bifilar_real_data_why;                                           \
    if (bifilar_real_data_found != ::bifilar::test_support::RealData::kFound)          \
      FAIL() << bifilar_real_data_why;                                                 \
  } while (false)

// The message of the UserError `f` throws ("" when it throws none).
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

}  // namespace test_support
}  // namespace bifilar
