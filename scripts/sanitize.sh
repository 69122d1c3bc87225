#!/usr/bin/env bash
# The test suite in a second build, build-sanitize/, with AddressSanitizer and
# UndefinedBehaviorSanitizer (cmake -DBIFILAR_SANITIZE=ON: -O1 -g, any undefined behaviour ends
# the program). scripts/test.sh runs it last, so CI does. Every report, from a test program or
# from a `bifilar` process that a test starts (whose stderr a test may swallow, or whose exit
# code a test may take for an ordinary error), is written to build-sanitize/sanitizer-reports/;
# any report there fails this script, and the reports are printed.
# Left out, and why:
#   - the Python module (BIFILAR_PYTHON=OFF): an instrumented extension needs libasan preloaded
#     into the Python interpreter; the Python tests run in the normal build;
#   - pipeline/messages.Messages.OutOfMemoryNamesTheInput: it caps the address space with
#     `ulimit -v` at 120 MB, and ASan reserves terabytes of address space for its shadow memory,
#     so the program cannot start there;
#   - the stress test runs BIFILAR_STRESS_CASES=100 cases instead of 500 (each case starts
#     several instrumented `bifilar` processes: 500 would take most of CI's hour on 2 cores).
# Leaks of the one-time fontconfig/pango/cairo caches are suppressed: tests/sanitizers/lsan.supp.
# Usage: scripts/sanitize.sh [BUILD_DIR]   (default: build-sanitize; the real-data folder as in
# scripts/test.sh)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build-sanitize}"
# No -Werror here: at -O1 with the sanitizers GCC 12 warns falsely inside std::regex and
# std::function (-Wmaybe-uninitialized); the warning check is the normal build's (test.sh).
cmake_args="-DBIFILAR_SANITIZE=ON -DBIFILAR_PYTHON=OFF -DBIFILAR_WERROR=OFF -DBIFILAR_STRESS_CASES=100"
data="${BIFILAR_DATA_DIR:-}"
if [ -z "$data" ] && [ -d "$here/../shared/data" ]; then data="$(cd "$here/../shared/data" && pwd)"; fi
if [ -n "$data" ]; then cmake_args="$cmake_args -DBIFILAR_DATA_DIR=$data"; fi
echo "sanitize: building $build (AddressSanitizer, UndefinedBehaviorSanitizer)"
BIFILAR_CMAKE_ARGS="$cmake_args" "$here/scripts/setup.sh" "$build" bifilar bifilar_tests

reports="$build/sanitizer-reports"
rm -rf "$reports" && mkdir -p "$reports"
supp="$here/tests/sanitizers"
# exitcode 86: a report is never mistaken for bifilar's own exit codes (0, 1, 2).
# allocator_may_return_null: a failed huge allocation throws std::bad_alloc as it does without
# ASan, and the code's handling of it is what the tests check.
export ASAN_OPTIONS="log_path=$reports/asan:exitcode=86:allocator_may_return_null=1:detect_leaks=1"
export UBSAN_OPTIONS="log_path=$reports/ubsan:exitcode=86:print_stacktrace=1:suppressions=$supp/ubsan.supp"
export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0"
cd "$build"
status=0
ctest --output-on-failure -j"$(nproc)" -E '^pipeline/messages\.Messages\.OutOfMemoryNamesTheInput$' ||
  status=$?
found=$(find "$reports" -type f | sort)
if [ -n "$found" ]; then
  echo "sanitize: $(printf '%s\n' "$found" | wc -l) sanitizer report(s):"
  for f in $found; do echo "== $f"; cat "$f"; done
  exit 1
fi
[ "$status" -eq 0 ] || exit "$status"
echo "sanitize: no AddressSanitizer or UndefinedBehaviorSanitizer report"
