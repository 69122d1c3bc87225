// Ctrl-C. The CLI's SIGINT handler and the Python module's signal check set a flag that a long
// run reads between pieces of work: `bifilar process` stops handing out fits, keeps the finished
// ones in the cache, writes no result file and reports CampaignInterrupted; `bifilar fit` stops
// between logs. A second Ctrl-C in the CLI kills at once (the default action is restored).
#pragma once

#include <atomic>
#include <stdexcept>
#include <string>

namespace bifilar {

// Installs the SIGINT handler that sets ProcessInterruptFlag() (CLI only; Python has its own).
void InstallInterruptHandler();

// The flag the handler sets. Lock-free, so a signal handler may store to it.
std::atomic<bool>& ProcessInterruptFlag();

// Exit code of a run stopped by Ctrl-C (128 + SIGINT, as shells report it).
constexpr int kInterruptedExitCode = 130;

// A run stopped on request: what was finished, for the message.
class CampaignInterrupted : public std::runtime_error {
 public:
  CampaignInterrupted(int done, int total, const std::string& cache_dir);
  int done() const { return done_; }
  int total() const { return total_; }

 private:
  int done_, total_;
};

}  // namespace bifilar
