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


def test_every_public_name_is_in_the_api_reference():
    import lagrange_gen
    from lagrange_gen import errors
    page = (ROOT / "docs" / "reference" / "api.md").read_text()
    targets = [line.split()[1] for line in page.splitlines() if line.startswith("::: ")]
    documented = {target.rsplit(".", 1)[-1] for target in targets}
    if "lagrange_gen.errors" in targets:
        documented |= {name for name in vars(errors) if not name.startswith("_")}
    if "`lagrange_gen.t`" in page:
        documented.add("t")
    missing = sorted(set(lagrange_gen.__all__) - documented)
    assert not missing, f"docs/reference/api.md does not document {missing}"


def test_every_name_in_the_api_reference_is_importable_from_the_package():
    """The page says everything on it is ``lg.<name>``: each documented object is reachable as
    an attribute of the package, and is the object documented."""
    import importlib

    import lagrange_gen
    page = (ROOT / "docs" / "reference" / "api.md").read_text()
    targets = [line.split()[1] for line in page.splitlines() if line.startswith("::: ")]
    unreachable = []
    for target in targets:
        if target == "lagrange_gen.errors":
            continue
        where, name = target.rsplit(".", 1)
        defined = getattr(importlib.import_module(where), name)
        if getattr(lagrange_gen, name, None) is not defined:
            unreachable.append(name)
    assert not unreachable, f"documented but not lagrange_gen.<name>: {unreachable}"
