"""The allow-lists of the layout checks (check_function_length.py, check_unit_facts.py): one
`path:item  # reason` a line, blank lines and comments ignored. Standard library only."""
import os


def read_allow_list(path, label, item):
    """Entries of the list at `path` as (entry, path part, item part) and the problems found:
    a line without `:` or without a reason is named by `label` (the list's name in messages)
    and line, as `want path:<item>  # reason`. A missing file is an empty list."""
    entries, problems = [], []
    if not os.path.exists(path):
        return entries, problems
    for k, line in enumerate(open(path, encoding="utf-8"), 1):
        entry, _, reason = line.partition("#")
        entry = entry.strip()
        if not entry:
            continue
        rel, _, rest = entry.partition(":")
        if not rest or not reason.strip():
            problems.append("%s:%d: want `path:%s  # reason`, got %r"
                            % (label, k, item, line.strip()))
            continue
        entries.append((entry, rel, rest))
    return entries, problems
