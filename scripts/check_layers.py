#!/usr/bin/env python3
"""The walls of issue 24: fails (exit 1) on an include cycle between units, or on an include that
goes against the declared component dependencies. Run by CTest as layout/layers:
  python3 scripts/check_layers.py SOURCE_DIR
  python3 scripts/check_layers.py --self-test   # CTest layout/layers_self_test: it finds faults
A unit is x.h + x.cc + a private x_steps.h in one folder. A component is a folder below; a file
may include its own component and any component reachable through its declared dependencies:
the same graph that target_link_libraries declares in CMakeLists.txt and pipeline/CMakeLists.txt
(keep the two in step). Tests, benchmarks and the Python module are clients: they may include
any component, but take part in the cycle check.
"""
import collections, os, re, sys

# component: folder, direct dependencies (lowest first in the file; must stay a DAG).
COMPONENTS = collections.OrderedDict([
    ("base", ("base", [])),
    ("pendulum", ("pendulum", ["base"])),
    ("fit", ("fit", ["pendulum", "base"])),
    ("figures", ("pipeline/figures", ["fit", "base"])),
    ("logs", ("pipeline/logs", ["pendulum", "base"])),
    ("live", ("pipeline/live", ["base"])),
    ("config", ("pipeline/config", ["logs", "fit", "pendulum", "base"])),
    ("records", ("pipeline/records", ["config", "fit", "base"])),
    ("trace", ("pipeline/trace", ["records", "config", "logs", "figures", "fit", "base"])),
    ("store", ("pipeline/store", ["records", "config", "base"])),
    ("report", ("pipeline/report", ["store", "records", "figures", "base"])),
    ("campaign", ("pipeline/campaign", ["report", "store", "trace", "records", "config",
                                        "figures", "fit", "base"])),
    ("watch", ("pipeline/watch", ["trace", "records", "config", "live", "logs", "pendulum",
                                  "base"])),
    ("commands", ("pipeline/commands", ["watch", "campaign", "trace", "records", "config", "logs",
                                        "figures", "fit", "pendulum", "base"])),
    ("cli", ("pipeline/cli", ["commands", "watch", "campaign", "report", "trace", "records", "config",
                              "logs", "fit", "base"])),
])
# Clients: may include any component, but take part in the cycle check.
CLIENT_DIRS = ["tests", "bench", "python", "."]
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def component_of(path):
    best = None
    for name, (folder, _) in COMPONENTS.items():
        if path.startswith(folder + "/") and "/" not in path[len(folder) + 1:]:
            best = name
    return best


def unit_of(path):
    d, f = os.path.split(path)
    stem = os.path.splitext(f)[0]
    if stem.endswith("_steps"):
        stem = stem[:-len("_steps")]
    return os.path.join(d, stem)


def closure():
    reach = {}
    for name in COMPONENTS:  # lowest first: dependencies are done before their users
        r = set()
        for dep in COMPONENTS[name][1]:
            if dep not in reach:
                sys.exit("component %s: dependency %s is not declared before it" % (name, dep))
            r |= {dep} | reach[dep]
        reach[name] = r
    return reach


def sccs(nodes, adj):
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):  # iterative Tarjan
        work = [(v, iter(sorted(adj[v])))]
        index[v] = low[v] = counter[0]; counter[0] += 1; stack.append(v); on.add(v)
        while work:
            node, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]; counter[0] += 1; stack.append(w); on.add(w)
                    work.append((w, iter(sorted(adj[w]))))
                    break
                if w in on:
                    low[node] = min(low[node], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    s = []
                    while True:
                        w = stack.pop(); on.discard(w); s.append(w)
                        if w == node:
                            break
                    out.append(sorted(s))

    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return [s for s in out if len(s) > 1]


def cmake_links():
    """component -> the bifilar::X it links (CMakeLists.txt, pipeline/CMakeLists.txt)."""
    text = ""
    for path in ("CMakeLists.txt", "pipeline/CMakeLists.txt"):
        if os.path.exists(path):
            text += re.sub(r"#[^\n]*", "", open(path, encoding="utf-8").read()) + "\n"
    folders = dict(re.findall(r"bifilar_component\(\s*(\w+)\s+([\w/]+)(?:\s+\w+)*\s*\)", text))
    links = {}
    for target, body in re.findall(r"target_link_libraries\(\s*bifilar_(\w+)\s([^)]*)\)", text):
        if target in folders:
            links.setdefault(target, set()).update(re.findall(r"bifilar::(\w+)", body))
    return folders, links


def check_cmake():
    """The CMake components and their links must be this file's COMPONENTS table."""
    folders, links = cmake_links()
    errors = []
    for name, (folder, deps) in COMPONENTS.items():
        if name not in folders:
            errors.append("CMake: no bifilar_component(%s %s)" % (name, folder))
            continue
        if folders[name] != folder:
            errors.append("CMake: component %s is folder %s, here %s" % (name, folders[name], folder))
        if links.get(name, set()) != set(deps):
            errors.append("CMake: bifilar_%s links %s, declared here %s"
                          % (name, sorted(links.get(name, set())), sorted(deps)))
    for name in folders:
        if name not in COMPONENTS:
            errors.append("CMake: component %s is not in scripts/check_layers.py" % name)
    return errors


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else ".")
    os.chdir(root)
    reach = closure()
    files = []
    for folder in [c[0] for c in COMPONENTS.values()] + CLIENT_DIRS:
        if not os.path.isdir(folder):
            continue
        walk = [(folder, None, os.listdir(folder))] if folder == "." else os.walk(folder)
        for dirpath, _, names in walk:
            for n in names:
                if n.endswith((".h", ".cc", ".hpp")):
                    files.append(os.path.normpath(os.path.join(dirpath, n)))
    files = sorted(set(files))
    errors = check_cmake()
    # Every source below pipeline/ belongs to a component folder.
    for dirpath, _, names in os.walk("pipeline"):
        for n in names:
            path = os.path.normpath(os.path.join(dirpath, n))
            if n.endswith((".h", ".cc", ".hpp")) and component_of(path) is None:
                errors.append("%s: not in a component folder" % path)
    edges = collections.defaultdict(list)
    for path in files:
        src = component_of(path)
        for lineno, line in enumerate(open(path, encoding="utf-8", errors="replace"), 1):
            m = INCLUDE.match(line)
            if not m or not os.path.exists(m.group(1)):
                continue
            target = m.group(1)
            dst = component_of(target)
            if src and dst and dst != src and dst not in reach[src]:
                errors.append("%s:%d: %s (%s) may not include %s (%s): not a declared dependency"
                              % (path, lineno, path, src, target, dst))
            a, b = unit_of(path), unit_of(target)
            if a != b:
                edges[(a, b)].append("%s:%d" % (path, lineno))
    adj = collections.defaultdict(set)
    nodes = {unit_of(f) for f in files}
    for a, b in edges:
        adj[a].add(b)
    for cycle in sccs(nodes, adj):
        members = set(cycle)
        lines = ["  %s -> %s (%s)" % (a, b, ", ".join(w)) for (a, b), w in sorted(edges.items())
                 if a in members and b in members]
        errors.append("include cycle between units %s:\n%s" % (" ".join(cycle), "\n".join(lines)))
    for e in errors:
        print(e)
    print("%d files, %d unit edges, %d problems" % (len(files), len(edges), len(errors)))
    return 1 if errors else 0


def self_test():
    """The check finds what it must: run on a small tree with one fault of each kind."""
    import shutil, subprocess, tempfile
    tmp = tempfile.mkdtemp()
    try:
        def write(path, text):
            os.makedirs(os.path.join(tmp, os.path.dirname(path)), exist_ok=True)
            open(os.path.join(tmp, path), "w").write(text)
        links = "".join("bifilar_component(%s %s)\ntarget_link_libraries(bifilar_%s %s)\n"
                        % (n, f, n, " ".join("bifilar::" + d for d in deps))
                        for n, (f, deps) in COMPONENTS.items())
        write("CMakeLists.txt", links)
        write("fit/a.h", '#include "fit/b.h"\n')
        write("fit/b.h", "")
        write("fit/b.cc", '#include "fit/a.h"\n')            # cycle a <-> b (b.h + b.cc)
        write("pipeline/config/c.h", "")
        write("pipeline/logs/d.cc", '#include "pipeline/config/c.h"\n')  # logs below config
        write("pipeline/stray.h", "")                          # no component
        out = subprocess.run([sys.executable, os.path.abspath(__file__), tmp],
                             capture_output=True, text=True).stdout
        want = ["include cycle between units fit/a fit/b",
                "pipeline/logs/d.cc:1: pipeline/logs/d.cc (logs) may not include",
                "pipeline/stray.h: not in a component folder", "3 problems"]
        missing = [w for w in want if w not in out]
        write("CMakeLists.txt", links.replace("bifilar_component(cli pipeline/cli)", ""))
        for f in ("fit/a.h", "fit/b.h", "fit/b.cc", "pipeline/logs/d.cc", "pipeline/stray.h"):
            os.remove(os.path.join(tmp, f))
        out2 = subprocess.run([sys.executable, os.path.abspath(__file__), tmp],
                              capture_output=True, text=True).stdout
        if "CMake: no bifilar_component(cli pipeline/cli)" not in out2:
            missing.append("a component missing from CMake")
        print(out + out2)
        print("self-test: " + ("missed " + "; ".join(missing) if missing else "ok"))
        return 1 if missing else 0
    finally:
        shutil.rmtree(tmp)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--self-test"]:
        sys.exit(self_test())
    sys.exit(main())
