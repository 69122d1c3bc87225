#!/usr/bin/env python3
"""One name per unit fact (issue 24): fails (exit 1) listing every second spelling of pi, of a
degree/radian factor, of standard gravity g0 or of the slug ft^2 factor outside base/units.h. Run by CTest as
layout/unit_facts:
  python3 scripts/check_unit_facts.py SOURCE_DIR
  python3 scripts/check_unit_facts.py --self-test   # CTest layout/unit_facts_self_test
Scans the .cc and .h files of base/ pendulum/ fit/ pipeline/ python/src/ tests/ and bench/ (all
sub-folders), comments left out (code and string literals are read: a help text that writes
"9.80665" by hand is a second spelling; one formatted from kStandardGravityMps2 is not).
Flagged: `kPi =` and the other constants of units.h defined again, M_PI, 3.14159..., pi over 180
(`kPi / 180`, `x * kPi / 180.0`), 180 over pi (`180.0 / kPi`, `x * 180 / kPi`), 57.29... and
0.01745..., 9.80665, and 1.3558.../0.73756... (slug ft^2). Use kPi, kRadPerDeg, kDegPerRad,
kStandardGravityMps2, kKgM2PerSlugFt2 and kSlugFt2PerKgM2.
Not scanned: base/units.h (the definitions) and tests/base_units_test.cc (which pins each constant
to its literal value). scripts/unit_facts_allow.txt lists `path:spelling  # reason` pairs that may
stay for now, one a line; an entry that matches nothing is reported too, so the list only shrinks.
"""
import os, re, sys

from allow_list import read_allow_list
from cxx_text import blank_cxx

ROOTS = ["base", "pendulum", "fit", "pipeline", os.path.join("python", "src"), "tests", "bench"]
EXEMPT = {"base/units.h", "tests/base_units_test.cc"}
ALLOW_FILE = "scripts/unit_facts_allow.txt"
# (pattern, the fact it spells, the one name to use)
SPELLINGS = [
    (r"\bkPi\s*=(?!=)", "pi defined again", "kPi"),
    (r"\bk(?:RadPerDeg|DegPerRad|StandardGravityMps2|KgM2PerSlugFt2)\s*=(?!=)",
     "a constant of base/units.h defined again", "the one in base/units.h"),
    (r"\bM_PI\w*", "pi", "kPi"),
    (r"\b3\.14159", "pi", "kPi"),
    (r"\b(?:kPi|M_PI)\b[^;\n]*?/\s*180(?:\.0*)?(?![\w.])", "radians per degree", "kRadPerDeg"),
    (r"(?<![\w.])180(?:\.0*)?(?![\w.])[^;\n]*?/\s*(?:kPi|M_PI)\b", "degrees per radian",
     "kDegPerRad"),
    (r"\b57\.29", "degrees per radian", "kDegPerRad"),
    (r"\b0\.01745", "radians per degree", "kRadPerDeg"),
    (r"\b9\.80665", "standard gravity g0", "kStandardGravityMps2"),
    (r"\b1\.3558\d*", "kg m^2 per slug ft^2", "kKgM2PerSlugFt2"),
    (r"\b0\.73756\d*", "slug ft^2 per kg m^2", "kSlugFt2PerKgM2"),
]


def without_comments(text):
    """// and /* */ comments blanked (newlines kept); string and char literals kept as they are."""
    return blank_cxx(text, literals=False, preprocessor=False)


def source_files(src):
    for root in ROOTS:
        for d, _, files in os.walk(os.path.join(src, root)):
            for f in sorted(files):
                if f.endswith((".cc", ".h")):
                    rel = os.path.relpath(os.path.join(d, f), src).replace(os.sep, "/")
                    if rel not in EXEMPT:
                        yield rel


def findings(src):
    """(path, line, spelling, fact, name) of every second spelling under src."""
    found = []
    for rel in sorted(source_files(src)):
        text = without_comments(open(os.path.join(src, rel), encoding="utf-8",
                                     errors="replace").read())
        for k, line in enumerate(text.split("\n"), 1):
            for pattern, fact, name in SPELLINGS:
                m = re.search(pattern, line)
                if m:
                    found.append((rel, k, m.group(0).strip(), fact, name))
                    break
    return found


def read_allow(path):
    entries, problems = read_allow_list(path, ALLOW_FILE, "spelling")
    return {(rel, spelling): entry for entry, rel, spelling in entries}, problems


def main(src):
    allow, problems = read_allow(os.path.join(src, ALLOW_FILE))
    used = set()
    for rel, line, spelling, fact, name in findings(src):
        key = next((k for k in allow if k[0] == rel and k[1] in spelling), None)
        if key:
            used.add(key)
            print("allowed: %s:%d '%s' (%s)" % (rel, line, spelling, fact))
            continue
        problems.append("%s:%d: '%s' spells %s a second time: use %s (base/units.h)"
                        % (rel, line, spelling, fact, name))
    for key in sorted(set(allow) - used):
        problems.append("%s: %s matches nothing any more: remove it from the list"
                        % (ALLOW_FILE, allow[key]))
    for p in problems:
        print(p)
    print("unit facts: %d problem(s)" % len(problems))
    return 1 if problems else 0


# Each planted line must be flagged; each clean line must not.
PLANTED = [
    "constexpr double kPi = 3.14159265358979323846;",
    "const double t = pitch * M_PI / 180.0;",
    "const double w = 2.0 * M_PI * f;",
    "const double a = 0.5 * 3.14159265358979 / 180;",
    "constexpr double kDeg = kPi / 180.0;",
    "const double th = pitch_deg * kPi / 180;",
    "const double deg = rad * 180.0 / kPi;",
    "double tau = 0.5 * std::atan2(b, a) * 180 / kPi;",
    "const double deg = rad * 57.29577951308232;",
    "const double rad = deg * 0.0174532925;",
    "o.geometry = {2.0, 1.8, 6.75, 9.80665};",
    'app.add_option("--gravity", g, "local g, m/s^2 (9.80665)");',
    "constexpr double kRadPerDeg = 0.017453292519943295;",
    "constexpr double kStandardGravityMps2 = 9.81;",
    "const double imperial = si / 1.35581795;",
    "const double imperial = si * 0.737562;",
]
CLEAN = [
    "const double t = pitch * kRadPerDeg;",
    "const double w = 2.0 * kPi * f;",
    "const double deg = rad * kDegPerRad;",
    "o.geometry = {2.0, 1.8, 6.75, kStandardGravityMps2};",
    'Fmt("local g, m/s^2 (%g)", kStandardGravityMps2);',
    "// 9.80665 is standard gravity, pi = 3.14159: a comment is no definition",
    "/* M_PI * 180 / kPi */ int x = 1;",
    "if (kPi == other) return;",
    "plwind(-180.0, 180.0, 0.0, 1.0);",
    "const double x = y / 1800.0 * kPi;",
    "const double imperial = si * kSlugFt2PerKgM2;  // 1 slug ft^2 = 1.35581795 kg m^2",
]


def self_test():
    import contextlib, io, tempfile
    missing = []
    with tempfile.TemporaryDirectory() as src:
        for d in ("base", "fit", "tests", "scripts", os.path.join("python", "src")):
            os.makedirs(os.path.join(src, d))

        def write(rel, lines):
            with open(os.path.join(src, rel), "w") as f:
                f.write("\n".join(lines) + "\n")

        def run(allow_text=""):
            with open(os.path.join(src, ALLOW_FILE), "w") as f:
                f.write(allow_text)
            with contextlib.redirect_stdout(io.StringIO()):
                return main(src)
        write("base/units.h", ["constexpr double kPi = 3.14159265358979323846;",
                               "constexpr double kStandardGravityMps2 = 9.80665;"])
        write("tests/base_units_test.cc", ["EXPECT_EQ(kPi, M_PI);"])
        write("fit/clean.cc", CLEAN)
        if run() != 0:
            missing.append("a clean tree fails: %s" % findings(src))
        for k, line in enumerate(PLANTED):
            rel = ("fit/planted.cc", "tests/planted_test.cc", "python/src/planted.cc")[k % 3]
            write(rel, CLEAN + [line])
            flagged = [f for f in findings(src) if f[0] == rel]
            if run() != 1 or len(flagged) != 1 or flagged[0][1] != len(CLEAN) + 1:
                missing.append("planted %r in %s: flagged %s" % (line, rel, flagged))
            os.remove(os.path.join(src, rel))
        write("fit/planted.cc", ['Use("default 9.80665");'])
        cases = [("an entry with a reason", "fit/planted.cc:9.80665  # later\n", 0),
                 ("an entry without a reason", "fit/planted.cc:9.80665\n", 1),
                 ("a stale entry", "fit/planted.cc:9.80665  # x\nfit/clean.cc:M_PI  # y\n", 1)]
        for what, text, want in cases:
            if run(text) != want:
                missing.append("allow list with %s: exit %d, want %d" % (what, 1 - want, want))
    print("self-test: " + ("missed " + "; ".join(missing) if missing else "ok"))
    return 1 if missing else 0


if __name__ == "__main__":
    if sys.argv[1:2] == ["--self-test"]:
        sys.exit(self_test())
    if len(sys.argv) != 2:
        sys.exit("usage: check_unit_facts.py SOURCE_DIR | --self-test")
    sys.exit(main(sys.argv[1]))
