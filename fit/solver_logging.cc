#include "fit/solver_logging.h"

#include <mutex>

#include <glog/logging.h>

namespace bifilar {

void QuietSolverLogging() {
  static std::once_flag once;
  std::call_once(once, [] {
    FLAGS_logtostderr = true;  // never files under /tmp
    FLAGS_minloglevel = google::GLOG_ERROR;
    if (!google::IsGoogleLoggingInitialized()) google::InitGoogleLogging("bifilar");
  });
}

}  // namespace bifilar
