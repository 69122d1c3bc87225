#include "base/interrupt.h"

#include <csignal>

namespace bifilar {
namespace {

static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler stores to it");

std::atomic<bool> g_interrupt{false};

extern "C" void OnInterrupt(int) {
  g_interrupt.store(true);
  std::signal(SIGINT, SIG_DFL);  // a second Ctrl-C kills at once
}

}  // namespace

void InstallInterruptHandler() {
  struct sigaction action = {};
  action.sa_handler = OnInterrupt;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
}

std::atomic<bool>& ProcessInterruptFlag() { return g_interrupt; }

CampaignInterrupted::CampaignInterrupted(int done, int total, const std::string& cache_dir)
    : std::runtime_error("interrupted: " + std::to_string(done) + " of " + std::to_string(total) +
                         " fits finished and kept in " + cache_dir +
                         "; no result file was written; run the same command again to go on "
                         "from the cache"),
      done_(done),
      total_(total) {}

}  // namespace bifilar
