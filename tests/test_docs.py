"""Every script in examples/ has a page in the docs site's nav and is linked from a hand-written
page (as ../../examples/NAME.py, which docs/repository_links.py points at the example's page), so
none is left out of the site (docs/gen_pages.py runs each one when the site builds)."""
import pytest

from lg_test_support import ROOT

EXAMPLES = sorted((ROOT / "examples").glob("*.py"))
HAND_WRITTEN = [p for p in (ROOT / "docs").rglob("*.md")]


def test_there_are_examples_and_pages():
    assert EXAMPLES and HAND_WRITTEN


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_is_in_the_nav_and_linked_from_a_page(script):
    page = f"examples/{script.stem}.md"
    assert page in (ROOT / "mkdocs.yml").read_text(), f"{page} is not in mkdocs.yml's nav"
    linked = [p for p in HAND_WRITTEN if f"examples/{script.name})" in p.read_text()]
    assert linked, f"no page under docs/ links to examples/{script.name}"
