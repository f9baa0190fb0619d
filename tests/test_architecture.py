"""The package's shape: data flows one way (no import cycle), rooms of readable size.

The import graph holds every ``import`` of every module in ``src/heritage_bayes``,
including imports inside functions (a lazy import is still a dependency) and under
``if TYPE_CHECKING:`` (a type named in a signature is one too), and the implicit
dependency of a module on its parent package's ``__init__``.
"""

from __future__ import annotations

import ast
import functools
import re
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "heritage_bayes"
PKG = "heritage_bayes"


def _module_name(path: Path) -> str:
    rel = path.relative_to(SRC.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for p in SRC.rglob("*.py")}


def _resolve(name: str, modules: dict[str, Path]) -> str | None:
    """The module a dotted import name refers to (``a.b.func`` -> ``a.b``)."""
    while name and name not in modules:
        name = name.rpartition(".")[0]
    return name or None


def import_graph(modules: dict[str, Path] | None = None) -> dict[str, set[str]]:
    """module -> modules of this package it imports (anywhere in the file)."""
    modules = modules if modules is not None else _modules()
    graph: dict[str, set[str]] = {}
    for mod, path in modules.items():
        deps: set[str] = set()
        is_pkg = path.name == "__init__.py"
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names: list[str] = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = mod.split(".")
                    base = base if is_pkg else base[:-1]
                    base = base[: len(base) - (node.level - 1)]
                    prefix = ".".join(base + ([node.module] if node.module else []))
                else:
                    prefix = node.module or ""
                names = [prefix] + [f"{prefix}.{a.name}" for a in node.names]
            for n in names:
                if n == PKG or n.startswith(PKG + "."):
                    target = _resolve(n, modules)
                    if target and target != mod:
                        deps.add(target)
        graph[mod] = deps
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of the graph as a list of modules (first == last), or None."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(n: str) -> list[str] | None:
        state[n] = 1
        stack.append(n)
        for m in sorted(graph.get(n, ())):
            if state.get(m) == 1:
                return [*stack[stack.index(m) :], m]
            if m not in state:
                found = visit(m)
                if found:
                    return found
        stack.pop()
        state[n] = 2
        return None

    for n in sorted(graph):
        if n not in state:
            found = visit(n)
            if found:
                return found
    return None


def _without_package_inits(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """Edges into a package ``__init__`` that only re-exports its submodules are not
    layering: ``heritage_bayes/__init__`` gathers the public API from every layer. Keep
    edges between real modules and from packages to their children."""
    inits = {m for m, p in _modules().items() if p.name == "__init__.py"}
    return {m: {d for d in deps if d not in inits} for m, deps in graph.items()}


def test_the_cycle_finder_finds_cycles():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": set()}) is None


def test_import_graph_sees_lazy_and_relative_imports(tmp_path):
    pkg = tmp_path / PKG
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("from .x import f\n")
    (pkg / "sub" / "x.py").write_text("def f():\n    from heritage_bayes.y import g\n")
    (pkg / "y.py").write_text("from heritage_bayes.sub.x import f\n")
    (pkg / "z.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from heritage_bayes.y import T\n"
    )
    mods = {_module_name_in(p, tmp_path): p for p in pkg.rglob("*.py")}
    g = import_graph(mods)
    assert g["heritage_bayes.sub.x"] == {"heritage_bayes.y"}
    assert g["heritage_bayes.sub"] == {"heritage_bayes.sub.x"}
    assert g["heritage_bayes.z"] == {"heritage_bayes.y"}  # a typing-only import counts
    assert find_cycle(g) == ["heritage_bayes.sub.x", "heritage_bayes.y", "heritage_bayes.sub.x"]


def _module_name_in(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def test_no_import_cycle_in_the_package():
    cycle = find_cycle(_without_package_inits(import_graph()))
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_rc_network_is_a_description_the_model_compiles():
    """``rc.network`` imports nothing of the package (not even lazily or for typing);
    ``rc.model`` imports it and its numerics at module level: the cycle the two once
    hid behind a lazy import and a ``TYPE_CHECKING`` block is gone."""
    modules = _modules()
    net_tree = ast.parse(modules["heritage_bayes.rc.network"].read_text(encoding="utf-8"))
    assert not [
        n
        for n in ast.walk(net_tree)
        if isinstance(n, ast.Import | ast.ImportFrom)
        and PKG in (getattr(n, "module", None) or "") + "".join(a.name for a in n.names)
    ]
    model_tree = ast.parse(modules["heritage_bayes.rc.model"].read_text(encoding="utf-8"))
    top = set(map(id, model_tree.body))
    lazy = [
        n.module for n in ast.walk(model_tree) if isinstance(n, ast.ImportFrom) and id(n) not in top
    ]
    assert lazy == []
    assert "heritage_bayes.rc.network" in import_graph()["heritage_bayes.rc.model"]


def test_lower_layers_do_not_import_higher_ones():
    """Every module of the package has its layer (a new one is placed here), and no
    module imports one of a higher layer."""
    graph = import_graph()
    layers = {  # lower number = lower layer
        "rc": 1, "climate": 1, "io": 1, "rundir": 1, "errors": 0, "_version": 0, "_arviz": 0,
        "convert": 0, "format": 0, "names": 0, "_env": 0, "_memory": 0, "_progress": 0,
        "_terminal": 0, "questions": 0, "yaml_text": 0,
        "config": 1, "init_periods": 1,
        "inputs": 2, "models": 2, "sources": 2, "demo": 2, "inference": 2, "init_model": 2,
        "init_roof": 2, "init_sources": 2,
        "prepare": 3, "prepare_steps": 3, "run": 3, "init_checks": 3, "init_columns": 3,
        "init_regimes": 3,
        "report": 4, "init_steps": 4,
        "calibration": 5, "projection": 5,
        "portfolio": 6, "compare": 6, "init_config": 6,
        "cli": 7,
        "reference": 8,
    }  # fmt: skip
    unplaced = sorted({m.split(".")[1] for m in graph if "." in m} - set(layers))
    assert unplaced == [], f"modules without a layer: {unplaced}"
    bad = []
    for mod, deps in graph.items():
        top = mod.split(".")[1] if "." in mod else None
        if top not in layers:
            continue
        for d in deps:
            dtop = d.split(".")[1] if "." in d else None
            if dtop in layers and layers[dtop] > layers[top]:
                bad.append(f"{mod} -> {d}")
    assert bad == [], bad


def test_rc_and_inference_see_neither_the_settings_nor_the_readers():
    """Settings are parsed once, at the boundary: the RC and inference layers receive
    typed values and import nothing from ``config`` or ``io``."""
    bad = sorted(
        f"{mod} -> {d}"
        for mod, deps in import_graph().items()
        if mod.split(".")[1:2] in (["rc"], ["inference"])
        for d in deps
        if d.split(".")[1:2] in (["config"], ["io"])
    )
    assert bad == [], bad


def test_the_settings_modules_stay_small():
    """The settings package is split by topic: no module of it above ~400 lines."""
    sizes = {
        p.name: len(p.read_text(encoding="utf-8").splitlines())
        for p in (SRC / "config").glob("*.py")
    }
    assert len(sizes) >= 8 and max(sizes.values()) <= 400, sizes


MAX_LINES = 600


@pytest.mark.parametrize("path", sorted(SRC.rglob("*.py")), ids=lambda p: str(p.relative_to(SRC)))
def test_modules_are_of_readable_size(path):
    """No module above 600 lines: a longer one is split by topic."""
    n = len(path.read_text(encoding="utf-8").splitlines())
    assert n <= MAX_LINES, (
        f"{path.relative_to(SRC)} has {n} lines (> {MAX_LINES}): split it by topic"
    )


#: An issue or a commit cited in prose: "issue 28", "issues 47, 49", "#28" (not a
#: logger's ``[#1]`` section), "commit ab12cd3" or a bare hash of 7-40 hex digits
#: holding both a letter and a digit.
CITATION = re.compile(
    r"\b[Ii]ssues?\s+#?\d+|(?<![\w&\[])#\d+\b"
    r"|\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*\d)[0-9a-f]{7,40}\b"
)


def _prose(tree: ast.AST):
    """(line, text) of every docstring and every string ``description=`` (a setting's
    text in the configuration reference, a command's in the CLI reference)."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            doc = ast.get_docstring(node, clean=False)
            if doc:
                yield getattr(node, "lineno", 1), doc
        elif isinstance(node, ast.Call):
            for kw in node.keywords:
                if kw.arg == "description" and isinstance(kw.value, ast.Constant):
                    if isinstance(kw.value.value, str):
                        yield node.lineno, kw.value.value


@functools.cache
def _package_prose() -> tuple[tuple[Path, int, str, bool], ...]:
    """(path, line, text, is an attribute's ``#:`` block) of the package's prose, parsed
    once for the tests that read it."""
    out = []
    for path in sorted(SRC.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        out += [(path, line, doc, False) for line, doc in _prose(ast.parse(text))]
        out += [(path, line, doc, True) for line, doc in _attribute_docs(text)]
    return tuple(out)


def test_the_citation_finder_finds_citations():
    cited = [
        "the peak memory (issue 28)", "issues 47, 49", "see #46", "on 84701f4",
        "at commit 8a2d1f5, before",
    ]  # fmt: skip
    plain = [
        "sections ``[#I]``, ``[#1]``", "1 000 000 steps", "2019-2020", "deadbeef",
        "sha256 of the rows", "EN 15757", "&#39;",
    ]  # fmt: skip
    assert [bool(CITATION.search(s)) for s in cited] == [True] * len(cited)
    assert [CITATION.search(s) for s in plain] == [None] * len(plain)


def test_no_docstring_or_setting_description_cites_an_issue_or_a_commit():
    """Docstrings hold the science and the contract; an issue number or a commit ages
    with every commit. Measured notes and their commands live in ``docs/science/``."""
    bad = [
        f"{path.relative_to(SRC)}:{line}: {m.group()!r}"
        for path, line, text, attribute in _package_prose()
        if not attribute
        for m in CITATION.finditer(text)
    ]
    assert bad == [], bad


#: The usual shapes of a measured note (a figure from one run on particular data): a
#: "Measured:" that is not a pointer to docs/, "measured on the demo / TRH-1 / Ørholm /
#: by benchmarks/...", a FIT percentage, a percentage against another, seconds of CPU,
#: τ before and after, megabytes of a file, counts of days, rooms or seeds, a mean z, a
#: coverage that rose. Such notes live in docs/science/ with their commands.
MEASURED_NOTE = re.compile(
    r"\b[Mm]easured:(?!\s*docs/)"
    r"|\b[Mm]easured (?:on|by|in|with|over) (?:the |a |two |eight )?"
    r"(?:demo|TRH-1|Ørholm|Annisse|``benchmarks/|benchmarks/|\w+ rooms|stations)"
    r"|\b[Mm]easured \d"
    r"|\b[Tt]he demo (?:misses|gives|gave|took|takes) \d"
    r"|\bFIT\b(?: of \w+)?(?: was| were| is)? \d+(?:\.\d+)? ?%"
    r"|\d+(?:\.\d+)? ?% FIT\b"
    r"|\d+(?:\.\d+)? ?% (?:against|vs\.?) \d"
    r"|\d+(?:\.\d+)? ?s (?:of (?:\w+ )?CPU|CPU|wall|against \d)"
    r"|\bspent \d+(?:\.\d+)? ?s\b"
    r"|τ(?:max)? (?:≈ ?)?\d[\d ]*(?:steps )?(?:after|against|vs|→)"
    r"|\d+(?:\.\d+)? ?[MG]B (?:of |instead of \d)"
    r"|(?<![\w/.])\d(?:\.\d+)? instead of \d"
    r"|\b\d+ of \d[\d ]* (?:days|rooms|replicates|seeds|chains)\b"
    r"|\bmean z [+−-]\d"
    r"|\bcoverage (?:rose|fell) from \d"
)


def _attribute_docs(text: str):
    """(line, text) of every ``#:`` comment block (an attribute's docstring)."""
    block: list[str] = []
    start = 0
    for i, line in enumerate([*text.splitlines(), ""], 1):
        s = line.strip()
        if s.startswith("#:"):
            start = start if block else i
            block.append(s[2:].strip())
        elif block:
            yield start, " ".join(block)
            block = []


def test_the_measured_note_finder_finds_notes():
    notes = [
        "made the MAP search 8x slower (measured: 37 s against 4.5 s).",
        "Measured on the demo's thermal_4a (``benchmarks/bench_coordinates.py demo_4a``)",
        "its MAP validation FIT of Ti was 76.7 % against 78.0 % with H",
        "validated at 61 % FIT Ti against 80 % with a year",
        "MAP simulation FIT 68 % vs 81 % with iid",
        "had not converged at 74 500 steps (τmax 648, 543 s of sampling CPU)",
        "(τmax 2 285 against 1 919 steps at 40 000)",
        "take 8.6 MB instead of 87 MB", "7.3 MB of the demo's 25.6 MB ``posterior.nc``",
        "Measured: the TRH-1 attic 0 of 581 days (free-running)",
        "measured by ``benchmarks/bench_sbc.py``: the gain from Te",
        "Measured on the Ørholm store's logger file (2012-2020, UTC+1)",
        "measured 1.013-1.020 on converged 4a and 1c runs",
        "The demo misses 4 of 11 with its logger-noise seed 7",
        "(a population of 130 000 spent 540 s there)",
        "gain from Pe above the truth in 7 of 8 (mean z +1.36)",
        "the solar gain's coverage rose from 0.81 to 0.86",
        "(a 3-d Gaussian: posterior sd 0.002 instead of 1 after 20 000 steps)",
    ]  # fmt: skip
    science = [
        "the measured indoor temperature ``Ti``", "measured : (N,) array",
        "(measured: docs/science/benchmarks.md, \"Bounded chains\")",
        "accuracy_failures` (FIT below 50 % on the validation)",
        "τmax 1311 asks for about 65 550 steps (50 τ) with a stable τ",
        "a 100 MB line in a logger file", "(10.5 MB for 262 770 h)",
        "the 90 % interval", "or use 1/3 instead of 1.3",
        "Offset of the file's clock measured on each usable day",
        "hours with RH > 80 % and T > 0 °C [h/year]", "a margin of 2 FIT points",
        "the time budget ran out after 68 000 steps", "differential evolution 80 %",
    ]  # fmt: skip
    assert [s for s in notes if not MEASURED_NOTE.search(s)] == []
    assert [s for s in science if MEASURED_NOTE.search(s)] == []


def test_no_docstring_or_setting_description_holds_a_measured_note():
    """A figure measured on particular data ages with every commit; its home is a page
    of ``docs/science/`` with its command, and the docstring points there."""
    bad = [
        f"{path.relative_to(SRC)}:{line}: {m.group()!r}"
        for path, line, text, _ in _package_prose()
        for m in MEASURED_NOTE.finditer(" ".join(text.split()))
    ]
    assert bad == [], bad


MAX_FUNCTION_LINES = 120

# Functions above MAX_FUNCTION_LINES code lines today, each with its present length as a ceiling:
# none may grow, and an entry leaves the list as soon as its function is split (the test
# below fails while a short function is still listed, so the list stays true).
LONG_FUNCTIONS: dict[str, int] = {}


def function_lengths(root: Path = SRC) -> dict[str, int]:
    """``"path::Qual.name"`` -> code lines of every ``def`` under ``root``.

    A function's length is the count of lines from the first statement of its body after
    the docstring to its last line: the signature and the docstring (the contract, which
    may be long) do not count, the code does, blank and comment lines included. Nested
    functions and methods are counted on their own as well, under their qualified name.
    """
    lengths: dict[str, int] = {}

    def walk(node: ast.AST, prefix: str, rel: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                key = f"{rel}::{prefix}{child.name}"
                body = child.body
                if len(body) > 1 and ast.get_docstring(child, clean=False) is not None:
                    body = body[1:]
                n = child.end_lineno - body[0].lineno + 1
                lengths[key] = max(lengths.get(key, 0), n)
                walk(child, f"{prefix}{child.name}.", rel)
            elif isinstance(child, ast.ClassDef):
                walk(child, f"{prefix}{child.name}.", rel)
            else:
                walk(child, prefix, rel)

    for path in sorted(root.rglob("*.py")):
        walk(ast.parse(path.read_text(encoding="utf-8")), "", path.relative_to(root).as_posix())
    return lengths


def test_function_lengths_count_code_lines_of_nested_defs(tmp_path):
    (tmp_path / "m.py").write_text(
        "class A:\n"
        "    def f(self):\n"
        '        """Doc."""\n'
        "        def g():\n"
        "            return 1\n"
        "        return g()\n"
    )
    assert function_lengths(tmp_path) == {"m.py::A.f": 3, "m.py::A.f.g": 1}


def test_functions_are_of_readable_length():
    """No function above ~120 lines; the long ones of today may only shrink."""
    lengths = function_lengths()
    too_long = {k: n for k, n in lengths.items() if n > LONG_FUNCTIONS.get(k, MAX_FUNCTION_LINES)}
    assert too_long == {}, (
        f"functions over {MAX_FUNCTION_LINES} lines (or over their listed ceiling): "
        f"{too_long}; split them into named steps"
    )
    stale = {k: lengths.get(k) for k in LONG_FUNCTIONS if lengths.get(k, 0) <= MAX_FUNCTION_LINES}
    assert stale == {}, (
        f"listed in LONG_FUNCTIONS but now at most {MAX_FUNCTION_LINES} lines or gone: {stale}; "
        "remove them from the list"
    )
