"""The import rules of the package layout (README, "Layout"), checked on the source with ``ast``:
every ``import`` counts, at module level, inside functions and under ``TYPE_CHECKING``.

- the stages that see observations only (perception, io, mapping, language, retrieval, planning,
  explore)
  import neither the simulator (``sim``: the scene truth) nor the evaluation (``eval``), nor
  anything built on top of them;
- ``core`` imports only ``core``; ``sim`` (the world) imports no stage that builds or reads maps;
- the product pipeline (``pipeline``), the library face (``api``), the demo and the server (``serve``)
  never import ``eval``;
- no import circles between modules.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "src"
TOP = ("api", "cli", "core", "demo", "eval", "explore", "io", "language", "mapping", "perception", "pipeline",
       "planning", "retrieval", "serve", "sim", "viz")
OBSERVATION_STAGES = ("perception", "io", "mapping", "language", "retrieval", "planning", "explore")
ABOVE = ("eval", "pipeline", "demo", "cli", "serve", "api")
FORBIDDEN: dict[str, tuple[str, ...]] = {
    **{stage: ("sim", *ABOVE) for stage in OBSERVATION_STAGES},
    "core": tuple(t for t in TOP if t != "core"),
    "sim": ("mapping", "language", "retrieval", "planning", *ABOVE),
    "pipeline": ("eval", "demo", "cli", "serve", "api"),
    "demo": ("eval", "cli", "serve"),
    "api": ("eval", "demo", "cli", "serve"),
    "serve": ("eval", "demo", "cli", "sim"),
    "viz": ("eval", "demo", "cli", "serve", "pipeline"),  # it draws the api's answers
}


def modules() -> dict[str, tuple[Path, bool]]:
    out = {}
    for p in sorted((SRC / "capnav").rglob("*.py")):
        parts = list(p.relative_to(SRC).with_suffix("").parts)
        pkg = parts[-1] == "__init__"
        out[".".join(parts[:-1] if pkg else parts)] = (p, pkg)
    return out


MODULES = modules()


def _resolve(name: str) -> str | None:
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def imports(module: str) -> Iterator[tuple[str, int]]:
    """(imported capnav module, line) for every import statement of ``module``."""
    path, pkg = MODULES[module]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = module if pkg else module.rpartition(".")[0]
                for _ in range(node.level - 1):
                    anchor = anchor.rpartition(".")[0]
                base = f"{anchor}.{base}" if base else anchor
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in MODULES else base for a in node.names]
        else:
            continue
        for t in targets:
            if t.startswith("capnav"):
                r = _resolve(t)
                if r is not None and r != module:
                    yield r, node.lineno


GRAPH = {m: dict(imports(m)) for m in MODULES}


def layer(module: str) -> str:
    parts = module.split(".")
    if parts[1:] == ["__main__"]:
        return "cli"  # ``python -m capnav`` is the command line
    return parts[1] if len(parts) > 1 else ""


def test_every_package_has_rules_or_is_top_level() -> None:
    assert {layer(m) for m in MODULES} - {""} == set(TOP), "a new package: add it to TOP (and FORBIDDEN)"


def test_layers_import_only_what_they_may() -> None:
    bad = [f"{MODULES[m][0].relative_to(SRC)}:{line} imports {t}"
           for m, deps in GRAPH.items() for t, line in deps.items()
           if layer(t) in FORBIDDEN.get(layer(m), ())]
    assert not bad, "layering rules broken:\n" + "\n".join(bad)


def test_no_import_circles() -> None:
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    circles: list[list[str]] = []

    def visit(v: str) -> None:  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in GRAPH[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                circles.append(sorted(comp))

    for v in GRAPH:
        if v not in index:
            visit(v)
    assert not circles, f"import circles: {circles}"


def test_the_checker_sees_lazy_and_type_checking_imports() -> None:
    # guards against a checker that silently sees nothing: these imports exist and are of each kind
    assert "capnav.sim" in GRAPH["capnav.pipeline.simulated"]  # module level
    assert "capnav.language" in GRAPH["capnav.pipeline.simulated"]  # inside a function
    assert "capnav.sim.config" in GRAPH["capnav.sim.agent"]  # under TYPE_CHECKING
    assert "capnav.eval.generate" in GRAPH["capnav.eval.pipeline"]


#: What a user runs to navigate: none of it may reach the evaluation, directly or through another module.
NAVIGATING = ("capnav.cli.navigate", "capnav.cli.demo", "capnav.demo", "capnav.api", "capnav.serve",
              "capnav.pipeline.drive")


def test_navigating_never_reaches_the_evaluation() -> None:
    bad = []
    for root in (m for m in MODULES if m.startswith(NAVIGATING)):
        seen, todo, via = {root}, [root], {root: root}
        while todo:
            v = todo.pop()
            for w in GRAPH[v]:
                if w not in seen:
                    seen.add(w)
                    via[w] = v
                    todo.append(w)
        for w in sorted(m for m in seen if layer(m) == "eval"):
            chain = [w]
            while chain[-1] != root:
                chain.append(via[chain[-1]])
            bad.append(" <- ".join(chain))
    assert not bad, "navigation reaches the evaluation:\n" + "\n".join(bad)
