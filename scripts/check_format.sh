#!/usr/bin/env bash
# Checks that every tracked C++ file (*.cc, *.h) is formatted as .clang-format says, with
# clang-format --dry-run -Werror: exit 0 when all are, else 1 with the files that are not and the
# command that formats them. scripts/test.sh runs it (a file not formatted fails the tests).
# Usage: scripts/check_format.sh          check
#        scripts/check_format.sh --fix    format them in place (clang-format -i)
# CLANG_FORMAT names the program (default clang-format: Debian's package clang-format, which
# scripts/setup.sh installs; another major version may format some lines differently).
# Files under third_party/ or vendor/ (none today) are someone else's and are not checked.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
cd "$here"
clang_format="${CLANG_FORMAT:-clang-format}"
fix=0
case "${1:-}" in
  --fix) fix=1 ;;
  "") ;;
  *) echo "usage: scripts/check_format.sh [--fix]" >&2; exit 2 ;;
esac
if ! command -v "$clang_format" >/dev/null 2>&1; then
  echo "check_format: no $clang_format (Debian: clang-format; scripts/setup.sh installs it)" >&2
  exit 2
fi
if [ ! -f .clang-format ]; then
  echo "check_format: no .clang-format in $here" >&2
  exit 2
fi
# The tracked files (a copy without git: every *.cc and *.h but the build folders).
files=()
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  while IFS= read -r -d '' f; do files+=("$f"); done < <(git ls-files -z -- '*.cc' '*.h')
else
  while IFS= read -r -d '' f; do files+=("${f#./}"); done < <(
    find . \( -path './build*' -o -path './.git' \) -prune -o \
      \( -name '*.cc' -o -name '*.h' \) -type f -print0)
fi
kept=()
for f in "${files[@]}"; do
  case "$f" in
    third_party/* | */third_party/* | vendor/* | */vendor/*) ;;
    *) [ -f "$f" ] && kept+=("$f") ;;
  esac
done
if [ ${#kept[@]} -eq 0 ]; then
  echo "check_format: no C++ files found" >&2
  exit 2
fi
if [ "$fix" -eq 1 ]; then
  printf '%s\0' "${kept[@]}" | xargs -0 -n 50 "$clang_format" -i --style=file
  echo "check_format: formatted ${#kept[@]} files"
  exit 0
fi
# --dry-run -Werror: a warning per place that would change (file:line:column), exit non-zero.
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
status=0
printf '%s\0' "${kept[@]}" |
  xargs -0 -n 50 "$clang_format" --dry-run -Werror --style=file >"$log" 2>&1 || status=$?
if [ "$status" -eq 0 ]; then
  echo "check_format: all ${#kept[@]} C++ files are formatted as .clang-format says"
  exit 0
fi
bad=$(grep -oE '^[^:]+\.(cc|h):[0-9]+:[0-9]+: (error|warning)' "$log" | cut -d: -f1 | sort -u || true)
if [ -z "$bad" ]; then  # clang-format failed otherwise (a bad .clang-format, say)
  cat "$log" >&2
  echo "check_format: $clang_format failed (exit $status)" >&2
  exit 2
fi
count=$(printf '%s\n' "$bad" | grep -c .)
places=$(grep -cE '^[^:]+\.(cc|h):[0-9]+:[0-9]+: (error|warning)' "$log" || true)
echo "check_format: $count of ${#kept[@]} C++ files are not formatted as .clang-format says" \
     "($places places):"
printf '  %s\n' $bad
echo "check_format: the first places:"
grep -E -A2 '^[^:]+\.(cc|h):[0-9]+:[0-9]+: (error|warning)' "$log" | head -n 30 || true
echo "check_format: format them with: scripts/check_format.sh --fix"
exit 1
