"""A griffe extension (mkdocs.yml, mkdocstrings' python handler) that shows the package's
plain-text docstrings as Markdown without changing them.

The docstrings are written for `help()`: ``code`` spans, "name: description" lines with indented
continuations, underlined section titles, and symbols such as <name>, a*b, x_i or [a, b](u)
that Markdown would read as HTML, emphasis or a link. Here: those characters are escaped outside
code spans; a run of "name: description" lines becomes a list; an underlined title becomes a
bold line (not a heading in the page's table of contents); ":class:`X`" becomes `X`; a
trailing "::" before an indented block becomes ":".
"""
import re

import griffe

DEFINITION = re.compile(r"^(?P<names>[A-Za-z_]\w*(?:\s*,\s*[A-Za-z_]\w*)*)\s*:\s+(?P<rest>\S.*)$")
NOT_NAMES = {"Note", "Notes", "Example", "Examples", "Returns", "Raises", "See", "Warning",
             "Explanation", "Usage"}
ROLE = re.compile(r":(?:class|func|meth|mod|attr|data|obj|exc):`~?([^`]+)`")
CODE_SPAN = re.compile(r"(``.+?``|`[^`]+`)")
UNDERLINE = re.compile(r"^\s*(-{3,}|={3,})\s*$")
ESCAPES = {"<": "&lt;", ">": "&gt;", "*": r"\*", "_": r"\_", "[": r"\[", "]": r"\]"}


def escape(text):
    """``text`` with Markdown's special characters escaped outside code spans."""
    parts = CODE_SPAN.split(text)
    for i in range(0, len(parts), 2):
        parts[i] = "".join(ESCAPES.get(c, c) for c in parts[i])
    return "".join(parts)


def to_markdown(doc):
    lines = ROLE.sub(r"`\1`", doc).split("\n")
    out = []
    in_list = False
    in_code = False
    for i, line in enumerate(lines):
        following = lines[i + 1] if i + 1 < len(lines) else ""
        if in_code:
            if line.strip() and not line.startswith("    "):
                in_code = False
            else:
                out.append(line)
                continue
        if UNDERLINE.match(line):
            continue
        if line.strip() and UNDERLINE.match(following):
            out += ["", f"**{escape(line.strip())}**", ""]
            in_list = False
            continue
        if line.startswith("    ") and not in_list and (not out or not out[-1].strip()):
            in_code = True                       # an indented block after a blank line: code
            out.append(line)
            continue
        match = DEFINITION.match(line)
        if match and match["names"] not in NOT_NAMES:
            if not in_list and out and out[-1].strip():
                out.append("")
            out.append(f"- `{match['names']}`: {escape(match['rest'])}")
            in_list = True
            continue
        if not line.strip():
            in_list = False
        elif in_list and not line.startswith(" "):
            line = "  " + line                   # a continuation written at column 0
        if line.rstrip().endswith("::"):
            line = line.rstrip()[:-1]
        out.append(escape(line))
    return "\n".join(out)


class PlainTextDocstrings(griffe.Extension):
    def on_instance(self, *, obj, **kwargs):
        if obj.docstring is not None:
            obj.docstring.value = to_markdown(obj.docstring.value)
