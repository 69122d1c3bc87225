#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite.
# Beyond the build's packages (scripts/setup.sh), the tests need Chromium (the report is loaded
# in headless Chromium and checked for console errors), so it is installed here when missing.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
if ! dpkg-query -W -f='${Status}' chromium 2>/dev/null | grep -q "install ok installed"; then
  echo "test: installing chromium (for the report test)"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends chromium >/dev/null
fi
"$here/scripts/setup.sh" "$here/build"
cd "$here/build" && ctest --output-on-failure -j"$(nproc)"
