"""The package's shape: one-way layers, no import cycle (not even a lazy one), a light import,
and every module saying what it is for and what it exports."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

from conftest import run_python

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "turntable_pin"

# A module may import from its own layer and from layers of lower rank, never upward.
LAYER_RANK = {
    "core": 0,
    "stats": 1,
    "model": 2,
    "calibration": 3,
    "measurement": 4,
    "allocation": 4,
    "design": 5,
    "instrument": 5,
    "report": 6,
    "viewer": 5,
    "cli": 7,
    "api": 8,  # the flat API (api.py) over every layer
}


def _modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _imports(name: str, path: Path, known: set[str]) -> set[str]:
    """Every package module ``name`` imports, at the top or inside functions (lazy)."""
    tree = ast.parse(path.read_text())
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            candidates = [target] + [f"{target}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            candidates = [a.name for a in node.names]
        else:
            continue
        for c in candidates:
            if c in known and c != name:
                found.add(c)
    # string-named lazy exports (core.lazy) are imports too
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == "_EXPORTS" for t in node.targets
        ):
            for value in ast.literal_eval(node.value).values():
                target = f"{name}.{value}"
                if target in known:
                    found.add(target)
    return found


def _graph() -> dict[str, set[str]]:
    modules = _modules()
    known = set(modules)
    return {name: _imports(name, path, known) for name, path in modules.items()}


def _layer(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


def test_layers_import_only_downwards():
    wrong = []
    for module, targets in _graph().items():
        layer = _layer(module)
        if layer is None or layer == "__main__":
            continue
        for target in targets:
            other = _layer(target)
            if other is None or other == layer:
                continue
            if LAYER_RANK[other] > LAYER_RANK[layer] or (LAYER_RANK[other] == LAYER_RANK[layer]):
                wrong.append(f"{module} -> {target}")
    assert not wrong, "upward or sideways imports: " + ", ".join(sorted(wrong))


def test_no_import_cycle_even_lazy():
    graph = _graph()
    # package __init__ files only re-export their own modules: leave them out of the cycle check
    graph = {m: {t for t in ts if not (m.startswith(t + "."))} for m, ts in graph.items()}
    state: dict[str, int] = {}
    cycle: list[str] = []

    def visit(node: str, stack: list[str]) -> bool:
        state[node] = 1
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                cycle.extend([*stack, node, nxt])
                return True
            if state.get(nxt) is None and visit(nxt, stack + [node]):
                return True
        state[node] = 2
        return False

    for node in sorted(graph):
        if state.get(node) is None and visit(node, []):
            break
    assert not cycle, "import cycle: " + " -> ".join(cycle)


def test_the_statistics_layer_knows_no_turntable():
    words = ("arcsec", "dpsi", "dtheta", "dgamma", "phi1", "phi2", "turntable", "gyrowheel")
    hits = []
    for path in (PACKAGE / "stats").glob("*.py"):
        text = path.read_text().lower()
        hits += [f"{path.name}: {w}" for w in words if w in text]
    assert not hits, hits


@pytest.mark.parametrize("name", sorted(_modules()))
def test_every_module_has_a_docstring_and_all(name):
    if name.endswith("__main__"):  # runs the command line when imported
        assert '"""' in _modules()[name].read_text().split("\n", 1)[0]
        return
    module = importlib.import_module(name)
    assert (module.__doc__ or "").strip(), f"{name} has no docstring"
    assert hasattr(module, "__all__"), f"{name} declares no __all__"
    missing = []
    for public in module.__all__:
        value = getattr(module, public)
        if not callable(value) or getattr(value, "__module__", name) != name:
            continue  # constants, and names re-exported from their defining module
        if not (value.__doc__ or "").strip():
            missing.append(public)
        if isinstance(value, type):
            for attr, member in vars(value).items():
                if attr.startswith("_") or not (callable(member) or isinstance(member, property)):
                    continue
                if isinstance(member, (staticmethod, classmethod)):
                    member = member.__func__
                if not (getattr(member, "__doc__", None) or "").strip():
                    missing.append(f"{public}.{attr}")
    assert not missing, f"{name}: public definitions without a docstring: {missing}"


def _heavy_modules_loaded_by(argv: list[str], heavy: tuple[str, ...]) -> list[str]:
    """Which of ``heavy`` a fresh interpreter has imported after ``turntable-pin ARGV``."""
    code = (
        "import sys, io, contextlib, turntable_pin\nfrom turntable_pin.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    try:\n        main({argv!r})\n    except SystemExit:\n        pass\n"
        f"print(','.join(m for m in {heavy!r} if m in sys.modules))\n"
    )
    proc = run_python(code)
    return [m for m in proc.strip().split(",") if m]


def test_import_and_help_pay_for_no_heavy_library():
    heavy = ("numpy", "scipy", "pinocchio", "matplotlib", "yourdfpy", "meshcat")
    assert _heavy_modules_loaded_by(["--help"], heavy) == []


def test_orientation_does_not_load_scipy_or_matplotlib():
    heavy = ("scipy", "matplotlib", "yourdfpy", "meshcat")
    assert _heavy_modules_loaded_by(["orientation", "--phi1-deg", "30"], heavy) == []


def test_no_text_of_the_package_says_the_models_install_outside_it():
    """The bundled models are package data, ``turntable_pin/models`` (setup.py); no docstring,
    message or help text under src/ says they install under ``<prefix>/share`` (issue 30)."""
    import turntable_pin.core.resources as resources

    setup = (PACKAGE.parents[1] / "setup.py").read_text()
    texts = [p.read_text() for p in sorted(PACKAGE.rglob("*.py"))] + [setup]
    assert not [t for t in texts if "share/turntable-pin" in t or "share/turntable_pin" in t]
    assert "turntable_pin/models" in resources.__doc__
    assert '"turntable_pin.models": "models"' in setup
