#!/usr/bin/env python3
"""No wall of code (issue 24): fails (exit 1) listing every function longer than 120 lines.
Run by CTest as layout/function_length:
  python3 scripts/check_function_length.py SOURCE_DIR
  python3 scripts/check_function_length.py --self-test   # CTest layout/function_length_self_test
Scans the .cc and .h files of base/ pendulum/ fit/ pipeline/ (all sub-folders), python/*.cc and
bifilar_main.cc; tests/ and bench/ are not scanned, nor pendulum/dop853.h (a port of Hairer's code).
A function is a brace block whose header ends like a definition, `name(...) [const] {`, and that is
not inside another function (lambdas count toward the function that holds them). Its length is the
line of the closing brace minus the line of the name, plus one (the ctags measure of issue 24).
scripts/function_length_allow.txt lists `path:function` pairs that may still be long, one a line,
each with a `# reason`; an entry that is no longer needed is reported too, so the list only shrinks.
"""
import os, re, sys

from allow_list import read_allow_list
from cxx_text import blank_cxx

LIMIT = 120
ROOTS = ["base", "pendulum", "fit", "pipeline"]
EXCLUDED = {"pendulum/dop853.h"}
ALLOW_FILE = "scripts/function_length_allow.txt"
NOT_FUNCTIONS = {"if", "for", "while", "switch", "catch", "return", "sizeof", "decltype",
                 "alignof", "static_assert", "defined", "operator"}
HEADER_TAIL = re.compile(
    r"([A-Za-z_~][\w:~]*(?:<[^;{}()]*>)?)\s*\([^;{}]*\)\s*"  # name(args)
    r"(?:const|noexcept|override|final|mutable|&|&&|\s|->\s*[^;{}()]+)*$")
CTOR_INIT = re.compile(r"([A-Za-z_~][\w:~]*)\s*\([^;{}]*\)\s*(?:noexcept\s*)?:[^:]")


def strip_code(text):
    """Comments, string and char literals blanked (newlines kept): braces in them do not count."""
    return blank_cxx(text)


def functions(text):
    """(name, first line, last line) of every outermost function definition in C++ source text."""
    code = strip_code(text)
    found, stack, header_start = [], [], 0
    for i, c in enumerate(code):
        if c == "{":
            header = code[header_start:i]
            kind = "block"
            if not any(k == "function" for k, _, _ in stack):
                name, pos = function_name(header)
                if name:
                    kind = "function"
                    stack.append((kind, name, header_start + pos))
                    header_start = i + 1
                    continue
            stack.append((kind, None, i))
            header_start = i + 1
        elif c == "}":
            if stack:
                kind, name, pos = stack.pop()
                if kind == "function":
                    found.append((name, code.count("\n", 0, pos) + 1, code.count("\n", 0, i) + 1))
            header_start = i + 1
        elif c == ";":
            header_start = i + 1
    return found


def function_name(header):
    """The function's name and its offset in header, if header ends a function definition."""
    h = header.rstrip()
    m = CTOR_INIT.search(h)  # Foo::Foo(args) : member_(x), other_{y}
    if m and m.group(1).split("::")[-1] not in NOT_FUNCTIONS and "=" not in h[:m.start()]:
        return m.group(1), m.start(1)
    m = HEADER_TAIL.search(h)
    if not m:
        return None, 0
    name = m.group(1)
    base = name.split("<")[0].split("::")[-1]
    if base in NOT_FUNCTIONS or h[:m.start(1)].rstrip().endswith(("=", "]", "return", ",", "(")):
        return None, 0
    return name, m.start(1)


def source_files(src):
    for root in ROOTS:
        for d, _, files in os.walk(os.path.join(src, root)):
            for f in sorted(files):
                if f.endswith((".cc", ".h")):
                    rel = os.path.relpath(os.path.join(d, f), src)
                    if rel not in EXCLUDED:
                        yield rel
    pydir = os.path.join(src, "python")
    if os.path.isdir(pydir):
        for f in sorted(os.listdir(pydir)):
            if f.endswith(".cc"):
                yield os.path.join("python", f)
    if os.path.exists(os.path.join(src, "bifilar_main.cc")):
        yield "bifilar_main.cc"


def read_allow(path):
    entries, problems = read_allow_list(path, ALLOW_FILE, "function")
    return {entry for entry, _, _ in entries}, problems


def long_functions(src):
    long = []
    for rel in source_files(src):
        text = open(os.path.join(src, rel), encoding="utf-8", errors="replace").read()
        for name, first, last in functions(text):
            if last - first + 1 > LIMIT:
                long.append((rel, name, first, last - first + 1))
    return long


def main(src):
    allow, problems = read_allow(os.path.join(src, ALLOW_FILE))
    used = set()
    for rel, name, first, length in long_functions(src):
        key = "%s:%s" % (rel, name.split("::")[-1])
        if key in allow or "%s:%s" % (rel, name) in allow:
            used.add(key if key in allow else "%s:%s" % (rel, name))
            print("allowed: %s:%d %s is %d lines" % (rel, first, name, length))
            continue
        problems.append("%s:%d: %s is %d lines (limit %d): split it into named steps"
                        % (rel, first, name, length, LIMIT))
    for entry in sorted(allow - used):
        problems.append("%s: %s is no longer over %d lines (or gone): remove it from the list"
                        % (ALLOW_FILE, entry, LIMIT))
    for p in problems:
        print(p)
    print("function length: %d problem(s)" % len(problems))
    return 1 if problems else 0


SELF_TEST_SOURCE = r'''
namespace {
// A comment with a brace { that must not count.
int Short(int x) { return x + 1; }
}  // namespace
struct Box {
  int Get() const { return v; }
  int v = 0;
};
Widget::Widget(int a) : a_(a), b_{a} {
  Use("}");
}
std::vector<int> Long(const std::vector<int>& v) {
  auto f = [&](int i) {
    if (i > 0) {
      return i;
    }
    return -i;
  };
%s
  return v;
}
template <typename T>
T Twice(T x) noexcept {
  return x + x;
}
'''


def self_test():
    body = "\n".join("  Use(%d);" % k for k in range(LIMIT))
    found = {name: (first, last) for name, first, last in functions(SELF_TEST_SOURCE % body)}
    want = {"Short", "Box", "Widget::Widget", "Long", "Twice"}
    missing = []
    if "Get" in found:
        del found["Get"]  # a member function inside a class body: found is fine too
    if set(found) - {"Box"} != want - {"Box"}:
        missing.append("functions %s, want %s" % (sorted(found), sorted(want - {"Box"})))
    if "Long" in found:
        first, last = found["Long"]
        if last - first + 1 != LIMIT + 9:
            missing.append("Long is %d lines, want %d" % (last - first + 1, LIMIT + 9))
    if found.get("Short", (0, 0))[1] - found.get("Short", (0, 0))[0] != 0:
        missing.append("Short should be one line")
    long = [n for n, f, l in functions(SELF_TEST_SOURCE % body) if l - f + 1 > LIMIT]
    if long != ["Long"]:
        missing.append("over the limit: %s, want ['Long']" % long)
    missing += allow_list_self_test(body)
    print("self-test: " + ("missed " + "; ".join(missing) if missing else "ok"))
    return 1 if missing else 0


def allow_list_self_test(body):
    """A tree with one long function: fails without an entry, passes with it, fails on a stale
    entry or one without a reason."""
    import contextlib, io, tempfile
    missing = []
    with tempfile.TemporaryDirectory() as src:
        os.makedirs(os.path.join(src, "fit"))
        os.makedirs(os.path.join(src, "scripts"))
        with open(os.path.join(src, "fit", "long.cc"), "w") as f:
            f.write(SELF_TEST_SOURCE % body)

        def run(allow_text):
            with open(os.path.join(src, ALLOW_FILE), "w") as f:
                f.write(allow_text)
            with contextlib.redirect_stdout(io.StringIO()):
                return main(src)
        cases = [("no entry", "", 1),
                 ("an entry with a reason", "fit/long.cc:Long  # split later\n", 0),
                 ("an entry without a reason", "fit/long.cc:Long\n", 1),
                 ("a stale entry", "fit/long.cc:Long  # x\nfit/long.cc:Short  # y\n", 1)]
        for what, text, want in cases:
            if run(text) != want:
                missing.append("allow list with %s: exit %d, want %d" % (what, 1 - want, want))
    return missing


if __name__ == "__main__":
    if sys.argv[1:2] == ["--self-test"]:
        sys.exit(self_test())
    if len(sys.argv) != 2:
        sys.exit("usage: check_function_length.py SOURCE_DIR | --self-test")
    sys.exit(main(sys.argv[1]))
