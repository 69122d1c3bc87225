"""C++ source as text for the layout checks (check_function_length.py, check_unit_facts.py):
comments blanked, and optionally string/char literals and preprocessor lines, newlines kept so
that line numbers stay those of the file. Standard library only."""
import re


def _blank(text):
    return re.sub(r"[^\n]", " ", text)


def blank_cxx(text, literals=True, preprocessor=True):
    """// and /* */ comments blanked; with `literals`, string (raw ones too) and char literals
    blanked between their quotes, else kept as they are; with `preprocessor`, # lines (and their
    continuations) blanked. A digit separator (1'000) is not a char literal."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i)); i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(_blank(text[i:j])); i = j
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum()
                                                          or text[i - 1] == "_")):
            k = text.find("(", i)
            delim = ")" + text[i + 2:k] + '"'
            j = text.find(delim, k)
            j = n if j < 0 else j + len(delim)
            out.append(_blank(text[i:j]) if literals else text[i:j]); i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum() and text[i + 1:i + 2].isalnum():
                out.append(c); i += 1; continue  # digit separator 1'000
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            if literals and j - i >= 2:
                out.append(c + " " * (j - i - 2) + c)
            else:
                out.append(text[i:j])
            i = j
        elif preprocessor and c == "#" and (i == 0 or text[i - 1] == "\n"):
            j = i
            while True:  # preprocessor line, with continuations
                j = text.find("\n", j)
                if j < 0:
                    j = n; break
                if text[j - 1] != "\\":
                    break
                j += 1
            out.append(_blank(text[i:j])); i = j
        else:
            out.append(c); i += 1
    return "".join(out)
