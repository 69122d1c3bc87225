// `bifilar watch --serve` (issue 34, "A page for the rig"): the page loads in headless Chromium
// without console errors, loads nothing from outside, and its numbers change as a feeder writes
// a simulated swing into the followed log. Skipped where /usr/bin/chromium is not installed.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <regex>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "pipeline/commands/simulate_spec.h"
#include "pipeline/commands/watch_command.h"
#include "pipeline/watch/watch_server.h"
#include "tests/test_support.h"
#include "tests/watch_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

TEST(WatchPage, SelfContained) {
  const std::string html = WatchPageHtml();
  for (const char* outside : {"http://", "https://", "src=", "@import", "url("}) {
    EXPECT_EQ(html.find(outside), std::string::npos) << outside;
  }
  EXPECT_NE(html.find("EventSource(\"/events\")"), std::string::npos);
}

TEST(WatchPage, NumbersChangeInHeadlessChromiumAsTheFeederPlays) {
  if (!std::filesystem::exists("/usr/bin/chromium")) GTEST_SKIP() << "no /usr/bin/chromium";
  TempDir dir("watch_page");
  watch_support::SimulateSwing(dir.path + "/sw.csv", {21, 20.0, {}, {}});
  const std::string config = watch_support::WriteSwingConfig(dir.path + "/c.yaml");
  const std::string text = ReadFile(dir.path + "/sw.csv");
  const std::string live = dir.path + "/live.csv";
  WriteFile(live, "");
  // The feeder: the log written in pieces over about 6 s.
  std::thread feeder([&] {
    std::ofstream out(live, std::ios::binary | std::ios::app);
    for (size_t at = 0; at < text.size(); at += 4000) {
      out << text.substr(at, 4000) << std::flush;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  std::string url;
  std::mutex mutex;
  WatchCommandOptions o;
  o.config_path = config;
  o.source = live;
  o.save_path = dir.path + "/saved.csv";
  o.serve_port = 0;
  o.idle_end_s = 2.0;
  o.on_event = [&](const std::string& e) {
    std::lock_guard<std::mutex> lock(mutex);
    const size_t at = e.find("http://127.0.0.1:");
    if (at != std::string::npos) url = e.substr(at);
  };
  std::thread watch([&] { RunWatch(o); });
  for (int i = 0; i < 100; ++i) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (!url.empty()) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::string page;
  {
    std::lock_guard<std::mutex> lock(mutex);
    page = url;
  }
  ASSERT_FALSE(page.empty());
  const std::string profile = dir.path + "/profile", dom = dir.path + "/dom.html",
                    log = dir.path + "/chromium.log";
  // Chromium's virtual time runs until the event stream closes (the watch ends when the feeder
  // has stopped for 2 s), so the DOM is dumped with every update received.
  const std::string command =
      "timeout 120 /usr/bin/chromium --headless --no-sandbox --disable-gpu --no-first-run "
      "--disable-background-networking --disable-component-update --disable-sync "
      "--user-data-dir=" +
      profile +
      " --enable-logging=stderr --v=0 --virtual-time-budget=60000 "
      "--dump-dom " +
      page + " > " + dom + " 2> " + log;
  const int status = std::system(command.c_str());
  feeder.join();
  watch.join();
  ASSERT_EQ(status, 0) << ReadFile(log);
  const std::string messages = ReadFile(log);
  for (const char* bad : {"CONSOLE", "Uncaught", "Failed to load", "ERR_"}) {
    EXPECT_EQ(messages.find(bad), std::string::npos) << bad << " in:\n" << messages;
  }
  const std::string html = ReadFile(dom);
  std::smatch m;
  ASSERT_TRUE(
      std::regex_search(html, m, std::regex("id=\"updates\" data-first-t=\"([^\"]*)\">([0-9]+)<")))
      << html.substr(0, 3000);
  const std::string first_t = m[1];
  const int updates = std::stoi(m[2]);
  EXPECT_GE(updates, 5);
  ASSERT_TRUE(std::regex_search(html, m, std::regex("id=\"t\">([0-9.]+) s<")));
  EXPECT_GT(std::stod(m[1].str()), std::stod(first_t) + 5.0);
  ASSERT_TRUE(std::regex_search(html, m, std::regex("id=\"inertia\">([0-9.e-]+) kg m\\^2<")));
  EXPECT_NEAR(std::stod(m[1].str()), 0.05, 0.001);
}

}  // namespace
}  // namespace bifilar
