"""An mkdocs hook (mkdocs.yml, hooks:): links from a docs page to files of the repository
outside docs/.

The pages link to the repository's files by their relative path (``../../models/x.py`` from
docs/guides/), so that the links work where the Markdown is read as files. The site holds no
source files, so here each such link is checked and rewritten: a report (reports/) points to
its copy on the site (docs/gen_pages.py puts the reports there), an example script
(examples/*.py) to its page, and any other file becomes its path in code type. A link to a file
that does not exist is a warning, which fails the strict build.
"""
import logging
import os
import posixpath
import re
from pathlib import Path

log = logging.getLogger("mkdocs.hooks.repository_links")
LINK = re.compile(r"(!?)\[([^\]\n]*)\]\(([^)\s]+)\)")
FENCE = re.compile(r"^\s*(```|~~~)")


def rewrite(target, page_dir, docs_dir, root, src_uri):
    """The new Markdown for a link to ``target`` from a page in ``page_dir`` (relative to
    docs_dir): None to leave the link as it is, else (kind, value)."""
    if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith(("#", "/")):
        return None
    path, _, anchor = target.partition("#")
    resolved = (docs_dir / page_dir / path).resolve()
    if resolved == docs_dir or docs_dir in resolved.parents:
        return None                                  # a page of the site: mkdocs checks it
    if not (resolved == root or root in resolved.parents) or not resolved.exists():
        log.warning("Doc file '%s' links to '%s', which is not a file of the repository",
                    src_uri, target)
        return None
    in_repo = resolved.relative_to(root).as_posix()
    fragment = f"#{anchor}" if anchor else ""
    if in_repo.startswith("reports/") and resolved.suffix in (".md", ".png"):
        return "link", posixpath.relpath(in_repo, page_dir or ".") + fragment
    if in_repo.startswith("examples/") and resolved.suffix == ".py":
        page = f"examples/{resolved.stem}.md"
        return "link", posixpath.relpath(page, page_dir or ".") + fragment
    return "code", in_repo


def on_page_markdown(markdown, page, config, files):
    docs_dir = Path(config["docs_dir"]).resolve()
    root = docs_dir.parent
    page_dir = posixpath.dirname(page.file.src_uri)

    def replace(match):
        bang, text, target = match.groups()
        new = rewrite(target, page_dir, docs_dir, root, page.file.src_uri)
        if new is None:
            return match.group(0)
        kind, value = new
        if kind == "link":
            return f"{bang}[{text}]({value})"
        shown = text.strip("`")
        return f"`{value}`" if shown in (value, os.path.basename(value)) else f"{text} (`{value}`)"

    out, in_fence = [], False
    for line in markdown.split("\n"):
        if FENCE.match(line):
            in_fence = not in_fence
        out.append(line if in_fence else LINK.sub(replace, line))
    return "\n".join(out)
