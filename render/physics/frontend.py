"""Memos for Taichi's compiler front end, which turns each kernel's Python into Taichi's IR.

It runs for every kernel of every new instance of a data-oriented class (each Canvas, Hud, System), even when
the compiled kernel then comes from the offline cache, since the cache is keyed by that IR. Much of it is work
whose result never changes while the process runs: the text of an error message for every statement, and the
source of every Taichi function. Each memo below gives the same result as the work it replaces. A one-frame
render of rigid_chaos in a process that rendered before (what every render pays besides its frames) took
1.01-1.04 s, 0.52-0.53 s of it in the front end, with the memos of the source and its wrapping alone; with the
error messages and the source's tabs remembered too, 0.88-0.91 s, 0.38-0.40 s in the front end (`python
benchmarks/fixed_cost.py`, twice each, renders 1-3; 2-core Xeon, AVX-512, 2026-12-07). Imported by
render/physics/runtime.py, before any kernel compiles.
"""
import functools
import textwrap

from taichi.lang import kernel_impl
from taichi.lang.ast import ast_transformer_utils


@functools.lru_cache(maxsize=1 << 16)
def _wrapped(text: str, width: int) -> tuple[str, ...]:
    return tuple(textwrap.TextWrapper(width=width).wrap(text))


class _RememberingWrapper:
    """Taichi's compiler front end builds, for every statement of every kernel it compiles, the text of an error
    message that is almost never shown: the source line and a ^^^ hint under it, each wrapped by a new
    TextWrapper. That wrapping was 28 % of the time of rendering every preset small in one process (35 s of
    127, cProfile), because each system instance compiles its kernels afresh and the same lines are wrapped
    again each time. This wrapper gives the same lists, remembered by their text."""

    def __init__(self, width: int = 70):
        self.width = width

    def wrap(self, text: str) -> list[str]:
        return list(_wrapped(text, self.width))


if ast_transformer_utils.TextWrapper is textwrap.TextWrapper:  # taichi 1.7.4 (pyproject.toml pins it)
    ast_transformer_utils.TextWrapper = _RememberingWrapper


# The same front end reads each Taichi function's source afresh every time a kernel that calls it is compiled:
# inspect.getsourcelines tokenizes the whole function again (and getsourcefile searches sys.modules), once per
# call site per kernel instance. A source file does not change under a running process, so each function's
# lines are read once; the front end copies them before it changes anything.
_getsourcelines, _getsourcefile = kernel_impl.getsourcelines, kernel_impl.getsourcefile


@functools.lru_cache(maxsize=None)
def _source_lines(func) -> tuple[tuple[str, ...], int]:
    lines, first = _getsourcelines(func)
    return tuple(lines), first


def _remembered_lines(func):
    lines, first = _source_lines(func)
    return list(lines), first


class _RememberedText:
    """What the front end asks of textwrap for each source line (fill, to expand its tabs) and each function's
    source (dedent), remembered by the text: 3,500 fills a one-frame render."""
    fill = staticmethod(functools.lru_cache(maxsize=1 << 16)(textwrap.fill))
    dedent = staticmethod(functools.lru_cache(maxsize=1 << 12)(textwrap.dedent))


if kernel_impl.getsourcelines.__module__ == "taichi.lang._wrap_inspect":  # taichi 1.7.4, as above
    kernel_impl.getsourcelines = _remembered_lines
    kernel_impl.getsourcefile = functools.lru_cache(maxsize=None)(_getsourcefile)
    kernel_impl.textwrap = _RememberedText


# Before it builds each statement the front end writes that error message (file, line, function, the source and
# its ^^^ hint), about 7 µs each, for some 27,000 statements in a one-frame render of rigid_chaos. The message is
# a function of the statement's place in its source and of the function it is in, so each is written once.
_pos_info = ast_transformer_utils.ASTTransformerContext.get_pos_info
_BODY_ENDS = ("For", "While", "FunctionDef", "If")  # whose message stops where their body starts
_positions: dict[tuple, str] = {}


def _pos_info_once(ctx, node) -> str:
    kind = node.__class__.__name__
    key = (ctx.file, ctx.lineno_offset, ctx.indent, ctx.func.func.__name__, kind, node.lineno, node.end_lineno,
           node.col_offset, node.end_col_offset, node.body[0].lineno if kind in _BODY_ENDS else 0)
    info = _positions.get(key)
    if info is None:
        info = _positions[key] = _pos_info(ctx, node)
    return info


if _pos_info.__module__ == "taichi.lang.ast.ast_transformer_utils":  # taichi 1.7.4, as above
    ast_transformer_utils.ASTTransformerContext.get_pos_info = _pos_info_once
