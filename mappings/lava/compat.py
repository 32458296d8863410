"""Import-time compatibility fix that lets lava-nc 0.10 import on Python 3.11.

lava-nc 0.10.0 (the last release) declares ``Python >=3.10,<3.11``. Installed anyway
(``pip install --ignore-requires-python lava-nc==0.10.0``), it fails at ``import`` in exactly
one place: ``lava/magma/compiler/var_model.py`` declares dataclass fields whose default is an
instance of another dataclass::

    @dataclass
    class CoreEncoder:
        x: ByteEncoder = ByteEncoder()

Python 3.11 rejects every unhashable default (a dataclass with ``eq=True`` has ``__hash__ = None``)
with ``ValueError: mutable default <class '...ByteEncoder'> for field x is not allowed: use
default_factory``; Python 3.10 only rejected ``list``, ``dict`` and ``set``.

The fix leaves the installed files (and their ``__pycache__``) alone. :func:`install` puts a
finder at the front of :data:`sys.meta_path` that handles only that one module: it reads the
installed source, rewrites each such field in the syntax tree to
``dataclasses.field(default_factory=ByteEncoder)`` and compiles the result under the original file
name (tracebacks still point at the installed file). Nothing is written to disk. The only change
in behaviour: each ``CoreEncoder``/``ChipEncoder``/``AxonEncoder`` gets its own ``ByteEncoder``
instead of all instances sharing one (the shared default was a latent aliasing bug; the encoders
are only used when compiling for Loihi hardware, which the CPU simulation never does).

Lava's ``multiprocessing`` message infrastructure also calls ``multiprocessing.set_start_method
("fork")`` at import, which raises ``RuntimeError: context has already been set`` when the
process already used ``multiprocessing`` (e.g. a test suite). The same rewrite passes
``force=True`` there when the current start method already is ``fork`` (Linux's default on 3.11),
so importing Lava late is harmless; any other start method is left to fail loudly.

Use :func:`import_lava` (which installs the finder) before importing anything from ``lava``;
importing :mod:`mappings.lava` installs it too. On Python 3.10 the rewrite is harmless (the
same fields with a per-instance default).
"""

from __future__ import annotations

import ast
import importlib.abc
import importlib.machinery
import importlib.util
import multiprocessing
import sys

#: Modules whose source the finder rewrites.
PATCHED_MODULES = (
    "lava.magma.compiler.var_model",
    "lava.magma.runtime.message_infrastructure.multiprocessing",
)

#: How to install the Lava extra on Python 3.11 (lava-nc declares Python < 3.11).
INSTALL_HINT = "pip install --ignore-requires-python -e '.[lava]'"


class LavaImportError(ImportError, ValueError):
    """lava-nc is missing or cannot be imported; the message says how to install it. A
    ``ValueError`` too, so command-line tools report it like any other bad input."""


def _dataclass_names(tree: ast.Module) -> set[str]:
    """Names of the module-level classes decorated with ``@dataclass`` (with or without
    arguments, as ``dataclass`` or ``dataclasses.dataclass``)."""

    def is_dataclass(node: ast.expr) -> bool:
        target = node.func if isinstance(node, ast.Call) else node
        return (isinstance(target, ast.Name) and target.id == "dataclass") or (
            isinstance(target, ast.Attribute) and target.attr == "dataclass"
        )

    return {
        node.name
        for node in tree.body
        if isinstance(node, ast.ClassDef) and any(map(is_dataclass, node.decorator_list))
    }


class _Rewriter(ast.NodeTransformer):
    """``x: T = D()`` (``D`` a dataclass of the module) -> ``x: T = field(default_factory=D)``
    inside dataclasses; ``set_start_method("fork")`` -> ``set_start_method("fork", force=...)``."""

    FIELD = "_spll_hw_dataclass_field"

    def __init__(self, dataclasses: set[str]) -> None:
        self.dataclasses = dataclasses
        self.changes = 0

    def visit_ClassDef(self, node: ast.ClassDef) -> ast.ClassDef:
        if node.name not in self.dataclasses:
            return node
        for stmt in node.body:
            value = getattr(stmt, "value", None)
            if (
                isinstance(stmt, ast.AnnAssign)
                and isinstance(value, ast.Call)
                and isinstance(value.func, ast.Name)
                and value.func.id in self.dataclasses
                and not value.args
                and not value.keywords
            ):
                stmt.value = ast.Call(
                    func=ast.Name(self.FIELD, ast.Load()),
                    args=[],
                    keywords=[ast.keyword("default_factory", ast.Name(value.func.id, ast.Load()))],
                )
                self.changes += 1
        return node

    def visit_Call(self, node: ast.Call) -> ast.Call:
        self.generic_visit(node)
        func = node.func
        if (
            isinstance(func, ast.Attribute)
            and func.attr == "set_start_method"
            and [getattr(a, "value", None) for a in node.args] == ["fork"]
            and not node.keywords
        ):
            # force only when fork is what the process uses already (no behaviour change).
            node.keywords = [
                ast.keyword("force", ast.Constant(multiprocessing.get_start_method() == "fork"))
            ]
            self.changes += 1
        return node


def rewrite_source(source: bytes | str, filename: str) -> ast.Module:
    """The patched syntax tree of one of :data:`PATCHED_MODULES` (``filename`` for messages)."""
    tree = ast.parse(source, filename)
    rewriter = _Rewriter(_dataclass_names(tree))
    tree = rewriter.visit(tree)
    if rewriter.changes == 0:
        raise LavaImportError(
            f"{filename}: the Lava compatibility fix found nothing to patch; this lava-nc is not "
            "0.10.0 (pin lava-nc==0.10.0, see mappings/lava/compat.py)"
        )
    # after the docstring and ``from __future__`` imports, which must come first
    position = 0
    while position < len(tree.body) and (
        (position == 0 and isinstance(tree.body[0], ast.Expr))
        or (isinstance(tree.body[position], ast.ImportFrom)
            and tree.body[position].module == "__future__")
    ):  # fmt: skip
        position += 1
    tree.body.insert(
        position, ast.ImportFrom("dataclasses", [ast.alias("field", _Rewriter.FIELD)], 0)
    )
    return ast.fix_missing_locations(tree)


class _PatchingLoader(importlib.machinery.SourceFileLoader):
    """Loads the installed source through :func:`rewrite_source`; never reads or writes the
    ``__pycache__`` (so the installed files stay untouched and stale bytecode is never used)."""

    def get_code(self, fullname: str):
        path = self.get_filename(fullname)
        return compile(rewrite_source(self.get_data(path), path), path, "exec", dont_inherit=True)


class LavaCompatFinder(importlib.abc.MetaPathFinder):
    """Meta-path finder that routes :data:`PATCHED_MODULES` through :class:`_PatchingLoader`."""

    def find_spec(self, fullname, path, target=None):
        if fullname not in PATCHED_MODULES:
            return None
        spec = importlib.machinery.PathFinder.find_spec(fullname, path)
        if spec is None or spec.origin is None or not spec.origin.endswith(".py"):
            return spec
        loader = _PatchingLoader(fullname, spec.origin)
        return importlib.util.spec_from_file_location(fullname, spec.origin, loader=loader)


def install() -> None:
    """Put :class:`LavaCompatFinder` first on :data:`sys.meta_path` (idempotent). Must run
    before the first import of ``lava.magma``; raises if a patched module is already imported
    without the fix."""
    if any(isinstance(f, LavaCompatFinder) for f in sys.meta_path):
        return
    for name in PATCHED_MODULES:
        module = sys.modules.get(name)
        if module is not None and not isinstance(getattr(module, "__loader__", None),
                                                 _PatchingLoader):  # fmt: skip
            raise LavaImportError(
                f"{name} was imported before the compatibility fix; import mappings.lava (or call "
                "mappings.lava.compat.install()) before anything from lava"
            )
    sys.meta_path.insert(0, LavaCompatFinder())


def import_lava():
    """Install the fix and import ``lava``; a missing or broken install raises
    :class:`LavaImportError` naming the install command."""
    install()
    try:
        import lava
        import lava.magma.core.process.process  # noqa: F401  (imports var_model)
        import lava.magma.runtime.message_infrastructure.multiprocessing  # noqa: F401
    except ModuleNotFoundError as exc:
        if exc.name is not None and exc.name.split(".")[0] == "lava":
            raise LavaImportError(
                f"the Lava backend needs lava-nc 0.10, which is not installed: {INSTALL_HINT} "
                "(lava-nc declares Python < 3.11, hence --ignore-requires-python)"
            ) from exc
        raise LavaImportError(
            f"lava-nc is installed but a dependency is missing ({exc}); {INSTALL_HINT}"
        ) from exc
    return lava
