#include "base/parallel_runner.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <ostream>
#include <thread>
#include <vector>

namespace bifilar {

int ResolveJobs(int jobs) {
  return jobs > 0 ? jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

void ParallelFor(int n, int jobs, const std::function<void(int)>& fn) {
  std::atomic<int> next{0};
  std::mutex error_mutex;
  std::exception_ptr error;
  auto worker = [&] {
    try {
      for (int i = next++; i < n; i = next++) fn(i);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      next = n;
    }
  };
  const int threads = std::max(1, std::min(jobs, n));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& thread : pool) thread.join();
  if (error) std::rethrow_exception(error);
}

void ProgressReporter::TaskDone(const std::string& line) {
  // Counted under the lock, so the lines (and the bar) show 1, 2, ... n in order and the bar's
  // final newline comes last.
  const std::lock_guard<std::mutex> lock(mutex_);
  const int done = ++done_;
  if (callback_) callback_(done, total_, line);
  if (out_ == nullptr) return;
  std::ostream& out = *out_;
  if (bar_) {
    const int width = 30;
    const int filled = total_ > 0 ? done * width / total_ : width;
    out << "\r  fitting [" << std::string(filled, '#') << std::string(width - filled, ' ') << "] "
        << done << "/" << total_ << std::flush;
    if (done == total_) out << "\n";
  } else {
    out << "  fit " << done << "/" << total_ << " " << line << "\n" << std::flush;
  }
}

int ProgressReporter::Stop() {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (out_ != nullptr && bar_ && done_ < total_) *out_ << "\n" << std::flush;
  return done_;
}

}  // namespace bifilar
