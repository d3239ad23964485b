"""The model's source as text, its marked blocks, and the state block for a set of terms.

The head ``kernel.py`` and its parts mark three blocks (``# <name>`` … ``# </name>``)
that ``compose`` writes for each set: the layout's constants, the state's tuple helpers
(this module writes them: numba builds a tuple only from an expression of fixed length,
so each set gets its own) and the added effects' forces. The helpers' arithmetic is the
same for every set, component by component, so a state's value never depends on which
others exist.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

from sim.effects.info import EffectInfo
from sim.physics import layout

__all__ = [
    "HOOKS",
    "SPLICED",
    "STATE_HOOKS",
    "added_file",
    "composed_functions",
    "hooks_block",
    "splice",
    "splice_sites",
    "state_block",
    "term_files",
    "text",
]

_NJIT = '@njit(cache=True, error_model="numpy")'


#: The parts of the model's text after its head (``kernel.py``), in order.
PARTS = ("fibre.py", "integrator.py", "runners.py")


#: The hooks a term may define (``<symbol>_<hook>`` in its ``terms.py``), and how the
#: composed set calls them in the registry's order: the arguments, then what each term
#: passes on to the next and the last returns; None: a yes/no, yes if any term says so;
#: (): called for its effect on c.
HOOKS: dict[str, tuple[tuple[str, ...], tuple[str, ...] | None]] = {
    # derived constants into c; the oscillations (RK4's, the exponential step's) and
    # decays the term brings, 1/s (maxima)
    "pack": (("c", "osc", "osc_exp", "real"), ("osc", "osc_exp", "real")),
    "replaces_friction": (("c",), None),  # its law replaces the table's friction
    "zoned": (("c",), None),  # friction has the baseline's branches
    "extension": (("c", "y", "ext1", "rate1", "ext2", "rate2"), ("ext1", "rate1", "ext2", "rate2")),
    "branch": (("c", "y", "q1", "q2"), ("q1", "q2")),  # force in each segment's tension law
    "friction_law": (("c", "y", "v", "replaced", "fric", "zd"), ("replaced", "fric", "zd")),
    "friction": (("c", "v", "zone", "t2", "fric"), ("fric",)),  # added guide friction, N
    "weight": (("c", "y", "v", "t2", "drive"), ("drive",)),  # force on the weight, N, up
    "decay": (("c", "v", "rate"), ("rate",)),  # its state's decay for the exponential step
    # this interval's oscillations and decays, 1/s (maxima)
    "substeps": (
        ("c", "y", "dt", "t_est", "osc", "osc_exp", "real", "real_exp"),
        ("osc", "osc_exp", "real", "real_exp"),
    ),
    "after_part": (("c", "y", "x", "xd", "h"), ()),  # discrete state after a part
    "given_start": (("c", "given"), None),  # follows a recorded input this run
    "given_at": (("c", "value"), ()),  # the input over the next interval
    "given_end": (("c",), ()),
    "start": (("c", "y", "x", "xd", "m"), ()),  # discrete state at a measured start
    # a term that splits the fibre: each segment's (δ, F, δ̇)
    "segments": (
        ("c", "y", "xa", "xb", "xd", "n", "ext1", "rate1", "ext2", "rate2", "q1", "q2",
         "d1", "f1", "d2", "f2", "dd1", "dd2"),
        ("d1", "f1", "d2", "f2", "dd1", "dd2"),
    ),
    "settle": (("c", "y", "x", "xd", "h"), ()),  # discrete state after a part, first
}  # fmt: skip
#: The hooks that give a term's own states (``layout.STATES``, in their order): its
#: values at rest, their rates, their values at a measured start. The composed set's
#: ``_terms_<hook>`` builds the whole state: the extra arguments give the baseline's
#: (and the pulley rim's) entries, a term not composed in gives zeros.
STATE_HOOKS: dict[str, tuple[tuple[str, ...], tuple[str, ...], dict[str, str]]] = {
    "rest": (("c",), (), {"U": "0.0", "V": "0.0"}),
    "rates": (("c", "y", "sg", "t1", "t2", "zd"), ("v", "acc"), {"U": "v", "V": "acc"}),
    "start_state": (("c", "x", "xd", "u", "v", "force", "taut", "m"), (), {"U": "u", "V": "v"}),
}


#: The hooks on the right-hand side's path (every RK stage, every bisection step of an
#: event): their bodies are written into the marked sites (``# <splice HOOK>``) of the
#: parts instead of being called. A call there that passes the state tuple kept numba
#: and LLVM from simplifying the segments' and forces' arithmetic (measured: the union
#: ran 3–4.5× slower with these hooks called, even with ``inline="always"``).
SPLICED = (
    "extension", "branch", "segments", "friction_law", "friction", "weight", "rates",
    "settle", "after_part", "substeps",
)  # fmt: skip

Added = tuple[EffectInfo, ...]


def term_files(terms: tuple[str, ...], added: Added = ()) -> list[tuple[str, Path]]:
    """(symbol, path) of the composed terms' files, the built-in ones', then the added ones'.

    A built-in term lives in its effect's folder, an added effect's in its one file.
    """
    effects = Path(__file__).parent.parent / "effects"
    found = []
    for info in layout.PLACED:
        path = effects / info.name / "terms.py"
        if info.symbol in terms and path.exists():
            found.append((info.symbol, path))
    return found + [(info.symbol, added_file(info)) for info in added if info.terms]


def added_file(info: EffectInfo) -> Path:
    """The file of an added effect's terms (``EffectInfo.terms``, a module's name)."""
    assert info.terms is not None
    module = importlib.import_module(info.terms)
    if module.__file__ is None:
        raise ValueError(f"{info.name}: its terms' module {info.terms} has no file")
    return Path(module.__file__)


def composed_functions(path: Path, symbol: str) -> list[ast.FunctionDef]:
    """An added effect's functions that the model composes in: ``<sym>_…`` and ``_<sym>_…``."""
    prefix = f"{symbol.lower()}_"
    return [
        node
        for node in ast.parse(path.read_text(encoding="utf-8")).body
        if isinstance(node, ast.FunctionDef) and node.name.removeprefix("_").startswith(prefix)
    ]


def _body(path: Path, symbol: str = "") -> str:
    """A built-in term file's text after its imports; an added effect's composed functions."""
    source = path.read_text(encoding="utf-8")
    if not symbol:
        return source.split("# </imports>\n", 1)[1]
    lines = source.splitlines()
    texts = []
    for node in composed_functions(path, symbol):  # from its decorator to its end
        first = node.decorator_list[0].lineno if node.decorator_list else node.lineno
        texts.append("\n".join(lines[first - 1 : node.end_lineno]))
    return "\n\n\n".join(texts) + "\n"


def text(terms: tuple[str, ...] = layout.TERMS, added: Added = ()) -> str:
    """The model's whole text: the head, each part, each composed term's file (no imports)."""
    here = Path(__file__).parent
    texts = [(here / "kernel.py").read_text(encoding="utf-8")]
    texts += [_body(here / name) for name in PARTS]
    texts += [_body(path) for _, path in term_files(terms)]
    texts += [_body(added_file(info), info.symbol) for info in added if info.terms]
    return "\n".join(texts)


def _def(name: str, args: tuple[str, ...]) -> list[str]:
    """A def line (wrapped as the formatter wraps it, the annotation comment kept on top)."""
    line = f"def {name}({', '.join(args)}):  # type: ignore[no-untyped-def]"
    if len(line) <= 100:
        return [line]
    return [f"def {name}(  # type: ignore[no-untyped-def]", f"    {', '.join(args)}", "):"]


def hooks_block(terms: tuple[str, ...], added: Added = ()) -> str:
    """``_terms_<hook>``: each hook of the composed terms' files, called in order."""
    defined = {
        symbol: {n.name for n in ast.parse(path.read_text(encoding="utf-8")).body
                 if isinstance(n, ast.FunctionDef)}
        for symbol, path in term_files(terms, added)
    }  # fmt: skip
    states = layout.every_state(added)
    lines = [f"# <hooks>: written by ``kernel_source.hooks_block`` for: {', '.join(defined)}."]
    flags = "".join(f" + c[R_{symbol}_ON]" for symbol in defined)
    lines += ["", "", _NJIT, "def _terms_on(c):  # type: ignore[no-untyped-def]",
              '    """How many of the composed terms are on (> 0: any)."""',
              f"    return 0.0{flags}"]  # fmt: skip
    for hook, (args, passed) in HOOKS.items():
        calls = [f"{s.lower()}_{hook}" for s in defined if f"{s.lower()}_{hook}" in defined[s]]
        call_args = ", ".join(args)
        body = []
        if passed is None:
            body.append("    said = False")
            for func in calls:
                body += [f"    this = {func}({call_args})", "    said = said or this"]
            body.append("    return said")
        elif passed:
            out = ", ".join(passed)
            body += [f"    {out} = {func}({call_args})" for func in calls]
            body.append(f"    return {out}")
        else:
            body += [f"    {func}({call_args})" for func in calls] or ["    return"]
        lines += ["", "", _NJIT, *_def(f"_terms_{hook}", args),
                  f'    """The composed terms\' ``{hook}`` hooks."""', *body]  # fmt: skip
    for hook, (args, extra, given) in STATE_HOOKS.items():
        body = []
        value = dict(given)
        for symbol, functions in defined.items():
            func = f"{symbol.lower()}_{hook}"
            own = [name.lower() for name, owner in states if owner == symbol]
            if func in functions and own:
                targets = ", ".join(f"r_{n}" for n in own)
                body.append(f"    ({targets},) = {func}({', '.join(args)})")
                value.update({n.upper(): f"r_{n}" for n in own})
        every = ", ".join(value.get(name, "0.0") for name, _ in states)
        doc = f"The whole state: the composed terms' ``{hook}`` hooks give their own."
        lines += ["", "", _NJIT, *_def(f"_terms_{hook}", args + extra),
                  f'    """{doc}"""', *body, f"    return _state({every})"]  # fmt: skip
    return "\n".join(lines) + "\n\n\n"


def splice(source: str, name: str, block: str) -> str:
    """``source`` with its block ``name`` (from its opening marker to its closing one) replaced."""
    start = source.index(f"# <{name}>")
    end = source.index(f"# </{name}>")
    return source[:start] + block + source[end:]


def block(source: str, name: str) -> str:
    """The block ``name`` of ``source`` as ``splice`` replaces it."""
    return source[source.index(f"# <{name}>") : source.index(f"# </{name}>")]


def state_block(terms: tuple[str, ...], added: Added = ()) -> str:
    """The tuple helpers for the states of a set of terms (``layout.state_names``)."""
    names = layout.state_names(terms, added)
    n = len(names)
    at = {name: i for i, name in enumerate(names)}
    every = [name for name, _ in layout.every_state(added)]
    carried = [at[name] for name in layout.carried(added) if name in at]

    def tup(items: list[str]) -> str:
        return "(" + ", ".join(items) + ("," if len(items) == 1 else "") + ")"

    def func(signature: str, doc: str, body: list[str]) -> list[str]:
        return ["", "", _NJIT, f"def {signature}:  # type: ignore[no-untyped-def]",
                f'    """{doc}"""', *body]  # fmt: skip

    lines = [
        f"# <state>: written by ``kernel_source.state_block`` for the states {', '.join(names)}.",
        f"ZERO = {tup(['0.0'] * n)}",
        f"NCARRY = {len(carried)}  # states carried from segment to segment",
    ]
    lines += func("_axpy(y, a, k)", "y + a·k, component by component.",
                  [f"    return {tup([f'y[{i}] + a * k[{i}]' for i in range(n)])}"])  # fmt: skip
    rk4 = [f"y[{i}] + a * (k1[{i}] + 2.0 * k2[{i}] + 2.0 * k3[{i}] + k4[{i}])" for i in range(n)]
    lines += func("_combine(y, a, k1, k2, k3, k4)",
                  "The RK4 update y + a·(k1 + 2k2 + 2k3 + k4), component by component.",
                  [f"    return {tup(rk4)}"])  # fmt: skip
    herm = [f"a * y0[{i}] + b * h * f0[{i}] + d * y1[{i}] + e * h * f1[{i}]" for i in range(n)]
    lines += func("_hermite(a, b, d, e, h, y0, f0, y1, f1)",
                  "The cubic Hermite interpolant's state from its four weights.",
                  [f"    return {tup(herm)}"])  # fmt: skip
    lines += func("_tuple_of(state)", "The state tuple from its array.",
                  [f"    return {tup([f'state[{i}]' for i in range(n)])}"])  # fmt: skip
    lines += func(f"_state({', '.join(name.lower() for name in every)})",
                  "The set's state from every state's value (those it lacks are dropped).",
                  [f"    return {tup([name.lower() for name in names])}"])  # fmt: skip
    stiff = [
        "sd" if name == "SD" else "z" if name == "Z" else f"y[{i}]" for i, name in enumerate(names)
    ]
    lines += func("_stiff_set(y, sd, z)", "y with the rim's velocity and the bristle replaced.",
                  [f"    return {tup(stiff)}"])  # fmt: skip
    out = [f"    carried[{j}] = state[{i}]" for j, i in enumerate(carried)] or ["    return"]
    lines += func("_carry_out(state, carried)", "The carried states of a state array.", out)
    where = {i: j for j, i in enumerate(carried)}
    back = [f"carried[{where[i]}]" if i in where else f"y[{i}]" for i in range(n)]
    lines += func("_with_carried(y, carried)", "y with the carried states replaced.",
                  [f"    return {tup(back)}"])  # fmt: skip
    return "\n".join(lines) + "\n\n\n"


def _hook_body(path: Path, func: str, args: tuple[str, ...], targets: str) -> list[str]:
    """A hook's body as lines (docstring dropped), its one final ``return X`` as ``targets = X``.

    The hook's parameters must be named as the site's variables (``HOOKS``), and it may
    return only at its end (a hook called for its effect, ``targets`` empty, not at all):
    its body then runs in place of the call, unchanged.
    """
    source = path.read_text(encoding="utf-8")
    node = next(
        n for n in ast.parse(source).body if isinstance(n, ast.FunctionDef) and n.name == func
    )
    if tuple(a.arg for a in node.args.args) != args:
        raise ValueError(f"{path}: {func} must take ({', '.join(args)})")
    body = node.body
    if isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        body = body[1:]  # the docstring
    lines = source.splitlines()
    if not targets:
        if any(isinstance(n, ast.Return) for stmt in body for n in ast.walk(stmt)):
            raise ValueError(f"{path}: {func} is called for its effect and returns nothing")
        every = lines[body[0].lineno - 1 : body[-1].end_lineno]
        indent = min(len(line) - len(line.lstrip()) for line in every if line.strip())
        return [line[indent:] for line in every]
    last = body[-1]
    returns = [n for stmt in body for n in ast.walk(stmt) if isinstance(n, ast.Return)]
    if not isinstance(last, ast.Return) or last.value is None or returns != [last]:
        raise ValueError(f"{path}: {func} must return once, at its end")
    value = ast.get_source_segment(source, last.value)
    if value is None or "\n" in value:
        raise ValueError(f"{path}: {func}'s return must fit one line")
    head = [] if len(body) == 1 else lines[body[0].lineno - 1 : body[-2].end_lineno]
    indent = min(len(line) - len(line.lstrip()) for line in head if line.strip()) if head else 0
    return [line[indent:] for line in head] + [f"{targets} = {value}"]


def splice_sites(source: str, terms: tuple[str, ...], added: Added = ()) -> str:
    """``source`` with each ``SPLICED`` hook's call replaced by the composed terms' bodies."""
    files = term_files(terms, added)
    states = layout.every_state(added)
    for hook in SPLICED:
        start = source.index(f"# <splice {hook}>")
        end = source.index(f"# </splice {hook}>")
        site = source[start:end]
        indent = source[source.rindex("\n", 0, start) + 1 : start]
        lines = site.split("\n")
        written: list[str] = []
        if hook in HOOKS:
            args, passed = HOOKS[hook]
            targets = ", ".join(passed or ())
            for symbol, path in files:
                if f"def {symbol.lower()}_{hook}(" in path.read_text(encoding="utf-8"):
                    written += _hook_body(path, f"{symbol.lower()}_{hook}", args, targets)
        else:
            args, _, given = STATE_HOOKS[hook]
            value = dict(given)
            for symbol, path in files:
                own = [name for name, owner in states if owner == symbol]
                func = f"{symbol.lower()}_{hook}"
                if own and f"def {func}(" in path.read_text(encoding="utf-8"):
                    targets = "(" + ", ".join(f"r_{n.lower()}" for n in own) + ",)"
                    written += _hook_body(path, func, args, targets)
                    value.update({n: f"r_{n.lower()}" for n in own})
            every = ", ".join(value.get(name, "0.0") for name, _ in states)
            written.append(f"return _state({every})")
        # The marker, the written bodies in place of the call's statement, the indent.
        body = [indent + line if line else line for line in written]
        source = source[:start] + "\n".join([lines[0], *body, lines[-1]]) + source[end:]
    return source
