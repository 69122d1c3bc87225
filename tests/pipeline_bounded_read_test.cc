// Bounded reads (issue 15, items 5 and 6): every input is a regular file within a size cap
// (base/bounded_read.h), gzip logs are read member after member up to a decompressed cap, and
// YAML aliases are refused. Known truth: files written here with known bytes; a FIFO, /dev/zero
// and a symlink to /dev/urandom must be refused without being read (a read would block or never
// end, and CTest's timeout would fail the test).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <string>

#include "base/bounded_read.h"
#include "base/gzip.h"
#include "base/user_error.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/store/output_set.h"
#include "test_support.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;
using test_support::Contains;
using test_support::TempDir;
using test_support::WriteFile;

using test_support::ErrorOf;

const InputCap kTenBytes{10, "test file", "raise the test's cap"};

TEST(ReadRegularFile, ReadsARegularFileAndASymlinkToOne) {
  TempDir dir;
  const std::string path = WriteFile(dir.path + "/a.txt", std::string("ten bytes\0", 10));
  fs::create_symlink(path, dir.path + "/link.txt");
  std::string bytes, why;
  ASSERT_TRUE(ReadRegularFile(path, kTenBytes, &bytes, &why)) << why;
  EXPECT_EQ(bytes, std::string("ten bytes\0", 10));  // exactly at the cap is accepted
  ASSERT_TRUE(ReadRegularFile(dir.path + "/link.txt", kTenBytes, &bytes, &why)) << why;
  EXPECT_EQ(bytes.size(), 10u);
}

TEST(ReadRegularFile, RefusesWhatIsNotARegularFileWithoutReadingIt) {
  TempDir dir;
  const std::string fifo = dir.path + "/fifo.csv";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  fs::create_symlink("/dev/urandom", dir.path + "/random.csv");
  const struct {
    std::string path, expected;
  } cases[] = {
      {fifo, fifo + ": is a FIFO (named pipe), not a regular file"},
      {"/dev/zero", "/dev/zero: is a character device, not a regular file"},
      {dir.path + "/random.csv", dir.path + "/random.csv: is a character device"},
      {dir.path, dir.path + ": is a folder, not a regular file"},
      {dir.path + "/missing.csv", dir.path + "/missing.csv: cannot open the test file"},
  };
  for (const auto& c : cases) {
    std::string bytes = "left over", why;
    EXPECT_FALSE(ReadRegularFile(c.path, kTenBytes, &bytes, &why)) << c.path;
    EXPECT_EQ(why.rfind(c.expected, 0), 0u) << why;
    EXPECT_TRUE(bytes.empty());
  }
}

TEST(ReadRegularFile, RefusesAFileAboveTheCapNamingSizeCapAndHowToRaiseIt) {
  TempDir dir;
  const std::string path = WriteFile(dir.path + "/big.txt", "eleven byte");
  std::string bytes, why;
  EXPECT_FALSE(ReadRegularFile(path, kTenBytes, &bytes, &why));
  EXPECT_EQ(why,
            path + ": too large for a test file: 11 bytes > cap 10 bytes; raise the test's cap");
  EXPECT_TRUE(bytes.empty());
  // A fixed cap says so instead of naming a key.
  EXPECT_FALSE(ReadRegularFile(path, InputCap{10, "config", ""}, &bytes, &why));
  EXPECT_TRUE(Contains(why, "11 bytes > cap 10 bytes; is this the right file?")) << why;
  EXPECT_EQ(ErrorOf([&] { ReadRegularFileOrThrow(path, kTenBytes); }),
            path + ": too large for a test file: 11 bytes > cap 10 bytes; raise the test's cap");
}

// ---- gzip ----

const InputCap kBigCap{1'000'000'000, "log once decompressed", "raise it"};

TEST(Gzip, ReadsEveryMemberAsZcatDoes) {
  const std::string a = "t,gx\n0,1\n1,2\n", b = "2,3\n3,4\n", c = "4,5\n";
  std::string text, why;
  ASSERT_TRUE(
      GzipDecompress(GzipCompress(a) + GzipCompress(b) + GzipCompress(c), &text, &why, kBigCap))
      << why;
  EXPECT_EQ(text, a + b + c);
  // Zero padding after the last member (a tape or dd block) is ignored, as zcat does.
  ASSERT_TRUE(GzipDecompress(GzipCompress(a) + std::string(512, '\0'), &text, &why, kBigCap));
  EXPECT_EQ(text, a);
}

TEST(Gzip, RefusesOtherBytesAfterAMemberAndATruncatedMember) {
  const std::string one = GzipCompress("t,gx\n0,1\n");
  std::string text, why;
  EXPECT_FALSE(GzipDecompress(one + "trailing", &text, &why, kBigCap));
  EXPECT_EQ(why, "not a valid gzip file (8 bytes after the end of gzip member 1 at byte " +
                     std::to_string(one.size()) + " are not another gzip member)");
  const std::string two = GzipCompress("1,2\n2,3\n");
  EXPECT_FALSE(GzipDecompress(one + two.substr(0, two.size() - 5), &text, &why, kBigCap));
  EXPECT_EQ(why, "not a valid gzip file (truncated in member 2)");
  EXPECT_TRUE(text.empty());
}

TEST(Gzip, StopsABombAtTheCap) {
  // 64 MB of zeros compress to ~64 kB (ratio ~1000); the cap of 1 MB stops inflation there.
  const std::string bomb = GzipCompress(std::string(64'000'000, '0'));
  ASSERT_LT(bomb.size(), 200'000u);
  std::string text, why;
  EXPECT_FALSE(GzipDecompress(bomb, &text, &why, {1'000'000, "log once decompressed", "raise it"}));
  EXPECT_EQ(why,
            "too large for a log once decompressed: more than the cap of 1000000 bytes; raise it");
  EXPECT_TRUE(text.empty());
}

// ---- logs ----

const char kLog[] =
    "t,gx,gy,gz\n0,0,0,0.1\n0.01,0,0,0.2\n0.02,0,0,0.3\n0.03,0,0,0.2\n0.04,0,0,0.1\n";

TEST(ReadImuLog, AMultiMemberGzipLogIsTheWholeLog) {
  TempDir dir;
  const std::string text = kLog;
  const size_t half = text.find("0.02");
  const std::string path = WriteFile(dir.path + "/log.csv.gz", GzipCompress(text.substr(0, half)) +
                                                                   GzipCompress(text.substr(half)));
  ImuFormat format;
  format.accel_columns = {"", "", ""};
  const ImuData data = ReadImuLog(path, format);
  ASSERT_EQ(data.t_s.size(), 5u);
  EXPECT_DOUBLE_EQ(data.t_s.back(), 0.04);  // not 0.01: the second member is read
  EXPECT_DOUBLE_EQ(data.gyro_in_imu.back().z(), 0.1);
}

TEST(ReadImuLog, CapsNameTheirConfigKeys) {
  TempDir dir;
  ImuFormat format;
  format.accel_columns = {"", "", ""};
  const std::string plain = WriteFile(dir.path + "/log.csv", kLog);
  const std::string gz = WriteFile(dir.path + "/log.csv.gz", GzipCompress(kLog));
  ImuLogOptions options;
  options.max_file_bytes = 20;
  EXPECT_TRUE(Contains(ErrorOf([&] { ReadImuLog(plain, format, options); }),
                       plain + ": too large for a log: " + std::to_string(sizeof(kLog) - 1) +
                           " bytes > cap 20 bytes; raise limits.max_log_mb (MB) in the config"));
  options = ImuLogOptions();
  options.max_decompressed_bytes = 20;
  EXPECT_TRUE(Contains(ErrorOf([&] { ReadImuLog(gz, format, options); }),
                       gz + ": too large for a log once decompressed: more than the cap of 20 "
                            "bytes; raise limits.max_decompressed_log_mb (MB) in the config"));
  fs::create_symlink("/dev/urandom", dir.path + "/random.csv");
  EXPECT_TRUE(Contains(ErrorOf([&] { ReadImuLog(dir.path + "/random.csv", format); }),
                       "random.csv: is a character device, not a regular file"));
}

// ---- configs ----

const char kFitConfig[] =
    "rig: {filar_length_m: 2.0, filar_separation_m: 0.9, mass_kg: 1.0}\n"
    "imu:\n  time: {column: t, unit: s}\n  gyro: {columns: [gx, gy, gz], unit: rad/s}\n"
    "  swing_axis: [0, 0, 1]\n";

TEST(Config, LimitsAreReadCheckedAndReachTheLogReader) {
  TempDir dir;
  const std::string path = WriteFile(
      dir.path + "/c.yaml",
      std::string(kFitConfig) + "limits: {max_log_mb: 5, max_decompressed_log_mb: 7.5}\n");
  const CampaignConfig config = test_support::LoadFitConfig(path);
  EXPECT_EQ(config.limits.LogOptions().max_file_bytes, 5'000'000u);
  EXPECT_EQ(config.limits.LogOptions().max_decompressed_bytes, 7'500'000u);
  const CampaignConfig defaults =
      test_support::LoadFitConfig(WriteFile(dir.path + "/d.yaml", kFitConfig));
  EXPECT_EQ(defaults.limits.LogOptions().max_file_bytes, 1'000'000'000u);
  EXPECT_EQ(defaults.limits.LogOptions().max_decompressed_bytes, 1'000'000'000u);
  const struct {
    const char* bad;
    const char* expect;  // the key, its value and the bound; or the key when it is no number
  } cases[] = {
      {"limits: {max_log_mb: 0.5}\n", "limits.max_log_mb = 0.5; must be in [1, 1000000] (MB)"},
      {"limits: {max_decompressed_log_mb: nan}\n",
       "'limits.max_decompressed_log_mb' must be a finite number"},  // refused as it is read
      {"limits: {max_log_mb: 2e6}\n", "limits.max_log_mb = 2000000; must be in [1, 1000000] (MB)"},
      {"limits: {max_log_mb: }\n", "'limits.max_log_mb'"},
  };
  for (const auto& c : cases) {
    const std::string p = WriteFile(dir.path + "/bad.yaml", std::string(kFitConfig) + c.bad);
    const std::string error = ErrorOf([&] { test_support::LoadFitConfig(p); });
    EXPECT_TRUE(Contains(error, p + ":6:")) << error;
    EXPECT_TRUE(Contains(error, c.expect)) << error << " lacks " << c.expect;
  }
  const std::string typo =
      WriteFile(dir.path + "/typo.yaml", std::string(kFitConfig) + "limits: {max_log_gb: 5}\n");
  EXPECT_TRUE(Contains(ErrorOf([&] { test_support::LoadFitConfig(typo); }),
                       "unknown key 'limits.max_log_gb'"));
}

TEST(Config, AFifoOrADeviceIsRefusedAtOnce) {
  TempDir dir;
  const std::string fifo = dir.path + "/c.yaml";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  EXPECT_EQ(ErrorOf([&] { test_support::LoadFitConfig(fifo); }),
            fifo +
                ": is a FIFO (named pipe), not a regular file; a config is read from a "
                "regular file only");
  EXPECT_TRUE(Contains(ErrorOf([&] { test_support::LoadFitConfig("/dev/zero"); }),
                       "/dev/zero: is a character device"));
}

TEST(Config, AliasesAreRefusedNamingLineAndAlias) {
  TempDir dir;
  const std::string plain =
      std::string(kFitConfig) + "fit: {max_amplitude_deg: &a 20, min_amplitude_deg: *a}\n";
  const std::string path = WriteFile(dir.path + "/alias.yaml", plain);
  EXPECT_EQ(ErrorOf([&] { test_support::LoadFitConfig(path); }),
            path +
                ":6:52: YAML alias '*a'; bifilar reads no aliases or merge keys ('<<') in its "
                "YAML files: write the values out where they are used");
  // "Billion laughs": 10 levels of 9 aliases (9^10 nodes to a walker) in ~0.5 kB, refused at
  // its first alias before any tree is built.
  std::string bomb = "a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n";
  for (int level = 1; level <= 10; ++level) {
    bomb += "a" + std::to_string(level) + ": &a" + std::to_string(level) + " [";
    for (int k = 0; k < 9; ++k) bomb += (k ? ", *a" : "*a") + std::to_string(level - 1);
    bomb += "]\n";
  }
  const std::string bomb_path = WriteFile(dir.path + "/bomb.yaml", bomb);
  EXPECT_TRUE(Contains(ErrorOf([&] { test_support::LoadFitConfig(bomb_path); }),
                       bomb_path + ":2:10: YAML alias '*a0'"));
  // A merge key is an alias too; and a simulation spec is read by the same reader.
  EXPECT_TRUE(Contains(
      ErrorOf([&] { ParseSimulateSpec("base: &b {seed: 3}\nother:\n  <<: *b\n", "spec.yaml"); }),
      "spec.yaml:3:7: YAML alias '*b'"));
}

// ---- the output folder ----

TEST(OutputFolder, AFifoInPlaceOfAResultOrACacheEntryIsRefused) {
  TempDir dir;
  const std::string out = dir.path + "/out";
  fs::create_directories(out + "/cache");
  WriteFile(out + "/cache/0123456789abcdef.json", "{}");
  EXPECT_NO_THROW(RefuseNonRegularOutputs(out));
  const std::string entry = out + "/cache/fedcba9876543210.json";
  ASSERT_EQ(mkfifo(entry.c_str(), 0644), 0);
  EXPECT_EQ(ErrorOf([&] { RefuseNonRegularOutputs(out); }),
            entry +
                ": is a FIFO (named pipe), not a regular file; bifilar reads and writes only "
                "regular files in its output folder: move it away or choose another --out");
  fs::remove(entry);
  fs::create_symlink("/dev/zero", out + "/results.json");
  EXPECT_TRUE(Contains(ErrorOf([&] { RefuseNonRegularOutputs(out); }),
                       out + "/results.json: is a device, not a regular file"));
}

}  // namespace
}  // namespace bifilar
