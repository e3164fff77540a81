"""The package's shape (docs/ARCHITECTURE.md): its import graph has no circles, nothing imports
another module's underscore names, the generator loads without numba, a cold simulate of a
generated module without sympy, and only the jit layer imports numba. The graph is read from
the source (every import statement, at any level of a file: a function-level import is a
dependency too), not from a running process."""

import ast
import subprocess
import sys
from pathlib import Path

import lagrange_gen

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = Path(lagrange_gen.__file__).resolve().parent

#: Circles that stay until the module named in the reason is split. The test fails when one of
#: them goes (so that the entry is removed) or when another appears.
KNOWN_CIRCLES = {}


def _modules():
    """{dotted name relative to lagrange_gen ("" for the package): (path, is a package)}."""
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        if is_package:
            parts.pop()
        found[".".join(parts)] = (path, is_package)
    return found


MODULES = _modules()


def _absolute(name, is_package, node):
    """The dotted name (relative to lagrange_gen) an ImportFrom refers to; None outside it."""
    if node.level:
        parts = name.split(".") if name else []
        base = parts if is_package else parts[:-1]
        base = base[:len(base) - (node.level - 1)] if node.level > 1 else base
        return ".".join(base + (node.module.split(".") if node.module else []))
    head, _, rest = (node.module or "").partition(".")
    return rest if head == "lagrange_gen" else None


def _module_of(dotted):
    """The package module ``dotted`` names, or the closest package module above it."""
    while dotted not in MODULES and "." in dotted:
        dotted = dotted.rsplit(".", 1)[0]
    return dotted if dotted in MODULES else ""


def _imports(name):
    """[(lineno, imported module, imported name or None)] of one package module."""
    path, is_package = MODULES[name]
    out = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom):
            base = _absolute(name, is_package, node)
            if base is None:
                continue
            for alias in node.names:
                sub = f"{base}.{alias.name}" if base else alias.name
                if sub in MODULES:
                    out.append((node.lineno, sub, None))
                else:
                    out.append((node.lineno, _module_of(base), alias.name))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                head, _, rest = alias.name.partition(".")
                if head == "lagrange_gen":
                    out.append((node.lineno, _module_of(rest), None))
    return out


def _graph():
    return {name: {target for _, target, _ in _imports(name) if target != name} for name in MODULES}


def _circles(graph):
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index, low, on_stack, stack, found, counter = {}, {}, set(), [], [], 0
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.add(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(frozenset(component))
    return found


def test_the_graph_sees_the_imports():
    """The graph resolves relative, absolute and function-level imports (what the tests below
    rely on)."""
    graph = _graph()
    assert "run.loader" in graph["run.simulate"]                  # from .loader import
    assert "steppers.core.registry" in graph["codegen.generate"]  # in a function
    assert "codegen.keys" in graph["run.loader"]                  # from ..codegen.keys import
    assert _circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [frozenset("abc")]


def test_no_import_circles():
    circles = set(_circles(_graph()))
    unexpected = sorted(sorted(c) for c in circles - set(KNOWN_CIRCLES))
    assert not unexpected, f"import circles: {unexpected}"
    gone = sorted(sorted(c) for c in set(KNOWN_CIRCLES) - circles)
    assert not gone, f"no longer circles, remove them from KNOWN_CIRCLES: {gone}"


def _layers():
    """[[module names of a layer]] from docs/ARCHITECTURE.md's numbered list ("Which folder may
    import which"), lowest first: the backticked names before the first colon of each item."""
    import re
    text = (ROOT / "docs" / "ARCHITECTURE.md").read_text()
    section = text.split("## Which folder may import which", 1)[1].split("\n## ", 1)[0]
    layers = []
    for line in section.splitlines():
        item = re.match(r"\d+\. (.*?):", line)
        if item:
            layers.append(re.findall(r"`([\w.]+)`", item.group(1)))
    return layers


def _layer_of(name, layers):
    """Index in ``layers`` of the most specific name covering the module ``name`` (None: none)."""
    best, index = -1, None
    for k, names in enumerate(layers):
        for covering in names:
            if (name == covering or name.startswith(covering + ".")) and len(covering) > best:
                best, index = len(covering), k
    return index


def test_the_layers_are_read_from_the_page():
    layers = _layers()
    assert layers[0] == ["errors"] and layers[-1] == ["cli"] and len(layers) >= 10
    assert _layer_of("jit.portable", layers) > _layer_of("steppers.methods.rk4", layers) \
        > _layer_of("jit.cache", layers)


def test_every_import_points_down_the_layers_of_the_architecture_page():
    """A module imports only from its own layer and those listed before it: the package order
    that docs/ARCHITECTURE.md states holds, with no circle between folders."""
    layers = _layers()
    unplaced = sorted(name for name in MODULES if name and _layer_of(name, layers) is None)
    assert not unplaced, f"modules in no layer of docs/ARCHITECTURE.md: {unplaced}"
    offenders = [f"{name} -> {target}" for name, targets in _graph().items() if name
                 for target in sorted(targets) if target
                 and _layer_of(target, layers) > _layer_of(name, layers)]
    assert not offenders, "imports against the layers of docs/ARCHITECTURE.md: " + "; ".join(offenders)


def test_no_module_imports_another_modules_underscore_names():
    offenders = [f"{name}:{line}: {target}.{imported}"
                 for name in MODULES for line, target, imported in _imports(name)
                 if imported and imported.startswith("_") and not imported.startswith("__")
                 and target != name]
    assert not offenders, "private names imported across modules: " + "; ".join(offenders)


def _private_reads(name):
    """[(lineno, "module.attribute")] where a package module reads an underscore attribute of
    another package module it imported (``from . import precision; precision._ours``)."""
    path, _ = MODULES[name]
    tree = ast.parse(path.read_text(), str(path))
    modules = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith("lagrange_gen")):
            modules |= {a.asname or a.name for a in node.names}
        elif isinstance(node, ast.Import):
            modules |= {(a.asname or a.name).split(".")[0] for a in node.names if a.name.startswith("lagrange_gen")}
    return [(node.lineno, f"{node.value.id}.{node.attr}") for node in ast.walk(tree)
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
            and node.value.id in modules and node.attr.startswith("_") and not node.attr.startswith("__")]


def test_no_module_reads_another_modules_underscore_attributes():
    offenders = [f"{name}:{line}: {what}" for name in MODULES for line, what in _private_reads(name)]
    assert not offenders, "private attributes read across modules: " + "; ".join(offenders)


def _numba_imports(name):
    """[(lineno, what)] of the numba imports of one package module."""
    path, _ = MODULES[name]
    out = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom) and not node.level and (node.module or "").split(".")[0] == "numba":
            out.append((node.lineno, node.module))
        elif isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names if a.name.split(".")[0] == "numba"]
    return out


def test_only_the_jit_layer_imports_numba():
    """Every contact with numba goes through jit/ (docs/ARCHITECTURE.md), so a numba release is
    answered there; gpu/ is the same layer for the CUDA target (numba-cuda), and bench/ is
    outside the rule because it times numba's own import and compiles."""
    offenders = [f"{name}:{line}: {what}" for name in MODULES
                 if name.split(".")[0] not in ("jit", "gpu", "bench")
                 for line, what in _numba_imports(name)]
    assert not offenders, "numba imported outside jit/: " + "; ".join(offenders)
    assert _numba_imports("jit.api"), "the check sees imports"


def _run(code):
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT,
                          timeout=600)


def test_the_generator_loads_without_numba():
    out = _run("import lagrange_gen.codegen, lagrange_gen.derive; import sys; "
               "assert 'numba' not in sys.modules, 'numba imported'")
    assert out.returncode == 0, out.stderr


def test_a_cold_simulate_of_a_generated_module_does_not_import_sympy():
    out = _run("import sys\n"
               "import lagrange_gen as lg\n"
               "module = lg.import_generated('generated/cart_pendulum.py')\n"
               "traj = lg.simulate(module, 'rk4', [0.1, 0.5], [0.0, 0.0], t_end=0.005, h=1e-3)\n"
               "assert traj.q.shape == (6, 2), traj.q.shape\n"
               "assert 'sympy' not in sys.modules, 'sympy imported'\n")
    assert out.returncode == 0, out.stderr


def test_lagrange_gen_on_an_unchanged_model_imports_neither_numpy_nor_sympy():
    """The freshness check of a generated module (codegen.keys, jit.sources) is light: the
    command on a model whose module is current imports neither numpy, sympy nor numba (the
    first run may derive it once, when the generator changed since it was last decided)."""
    first = _run("from lagrange_gen.cli.main import main\n"
                 "assert main(['models/cart_pendulum.py', '-o', 'generated']) == 0\n")
    assert first.returncode == 0, first.stderr
    out = _run("import sys\n"
               "from lagrange_gen.cli.main import main\n"
               "assert main(['models/cart_pendulum.py', '-o', 'generated']) == 0\n"
               "heavy = sorted(m for m in ('numpy', 'sympy', 'numba') if m in sys.modules)\n"
               "assert not heavy, heavy\n")
    assert out.returncode == 0, out.stderr
    assert "is current" in out.stdout + out.stderr, out.stdout + out.stderr


def test_gpu_sits_below_run():
    """gpu/ (ensemble(device="cuda")) imports neither run/ nor cli/: run calls it."""
    above = ("run", "cli", "linear", "viz", "analysis", "bench", "identify")
    offenders = [f"{name} -> {target}" for name, targets in _graph().items()
                 if name.split(".")[0] == "gpu"
                 for target in targets if target.split(".")[0] in above]
    assert not offenders, "gpu/ imports a stage above it: " + "; ".join(offenders)


def test_a_cpu_ensemble_does_not_import_numba_cuda():
    out = _run("import sys\n"
               "import lagrange_gen as lg\n"
               "ens = lg.ensemble('generated/cart_pendulum.py', 'rk4', q0=[[0.1, 0.5]], "
               "t_end=0.003, h=1e-3)\n"
               "assert ens.ok.all() and ens.device == 'cpu'\n"
               "loaded = [m for m in ('numba.cuda', 'lagrange_gen.gpu') if m in sys.modules]\n"
               "assert not loaded, loaded\n")
    assert out.returncode == 0, out.stderr
