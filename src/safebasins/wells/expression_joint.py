"""``dV_V(q) = (V'(q), V(q))`` of an expression well from its generated ``V`` and ``dV``, with their bits.

The engines' split step (numerics.scheme_code) needs V' and V at the same q once per step (the
last kick and the energy test).  :func:`joint_source` writes one function computing both from
the generated source of ``V(q)`` and ``dV(q)`` (wells.expression), sharing what they have in
common without changing an operation:

* each function's statements are kept as they are (locals renamed apart), the calls of sin, cos,
  exp, expm1 and exp_expm1 named first (pure functions: naming a call does not change what it
  computes);
* a statement computing what an earlier one computed (the same text over the same values) is
  not repeated;
* sin and cos of one argument come from one ``sincos``, exp and expm1 of one argument from one
  ``exp_expm1``: wells.elementary gives these pairs the bits of the single functions (tested
  there), so the result is ``(dV(q), V(q))`` bit for bit.
"""
from __future__ import annotations

import ast
import copy

__all__ = ["joint_source"]

#: calls named and shared, and the pair function that gives each its bits: name -> (pair, index)
_PAIRS = {"sin": ("sincos", 0), "cos": ("sincos", 1), "exp": ("exp_expm1", 0), "expm1": ("exp_expm1", 1)}
_SHARED = (*_PAIRS, "exp_expm1")


def _body(source: str, name: str) -> list[ast.stmt]:
    fn = next(n for n in ast.parse(source).body if isinstance(n, ast.FunctionDef) and n.name == name)
    return fn.body


class _Rename(ast.NodeTransformer):
    """Locals of one function renamed with a prefix (``q`` and the called names kept)."""

    def __init__(self, prefix: str, local: set[str]) -> None:
        self.prefix, self.local = prefix, local

    def visit_Name(self, node: ast.Name) -> ast.Name:
        return ast.Name(self.prefix + node.id, node.ctx) if node.id in self.local else node


def _shared_call(node: ast.AST) -> bool:
    return isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in _SHARED


class _Hoist(ast.NodeTransformer):
    """Calls of :data:`_SHARED` (innermost first) and their arguments named by new locals, assigned
    before the statement (a statement that is such a call keeps it, its argument named)."""

    def __init__(self, prefix: str) -> None:
        self.prefix, self.out, self.n = prefix, list[ast.Assign](), 0

    def _name(self, value: ast.expr) -> ast.Name:
        self.n += 1
        name = f"{self.prefix}c{self.n}"
        self.out.append(ast.Assign([ast.Name(name, ast.Store())], value, lineno=0))
        return ast.Name(name, ast.Load())

    def arguments(self, node: ast.Call) -> ast.Call:
        node.args = [a if isinstance(a, (ast.Name, ast.Constant)) else self._name(self.visit(a)) for a in node.args]
        return node

    def visit_Call(self, node: ast.Call) -> ast.expr:
        if not _shared_call(node):
            self.generic_visit(node)
            return node
        return self._name(self.arguments(node))


def _statements(source: str, name: str, prefix: str) -> tuple[list[ast.Assign], ast.expr]:
    """(assignments, returned expression) of ``name`` in ``source``, locals prefixed, shared calls named."""
    body = _body(source, name)
    local = {t.id for s in body if isinstance(s, ast.Assign) for t in ast.walk(s.targets[0]) if isinstance(t, ast.Name)}
    out: list[ast.Assign] = []
    hoist = _Hoist(prefix)
    ret: ast.expr | None = None
    for s in body:
        s = _Rename(prefix, local).visit(s)
        if isinstance(s, ast.Return) and s.value is not None:
            ret = hoist.visit(s.value)
        elif isinstance(s, ast.Assign) and len(s.targets) == 1:
            s.value = hoist.arguments(s.value) if isinstance(s.value, ast.Call) and _shared_call(s.value) else \
                hoist.visit(s.value)
        else:
            raise ValueError(f"joint_source: unexpected statement in {name}: {ast.unparse(s)}")
        out += hoist.out
        hoist.out = []
        if isinstance(s, ast.Assign):
            out.append(s)
    assert ret is not None, f"{name} returns nothing"
    return out, ret


class _Alias(ast.NodeTransformer):
    def __init__(self, alias: dict[str, str]) -> None:
        self.alias = alias

    def visit_Name(self, node: ast.Name) -> ast.Name:
        return ast.Name(self.alias.get(node.id, node.id), node.ctx)


class _Expand(ast.NodeTransformer):
    """An expression with every local replaced by what it computes (its value's identity)."""

    def __init__(self, defs: dict[str, ast.expr]) -> None:
        self.defs = defs

    def visit_Name(self, node: ast.Name) -> ast.expr:
        return self.defs.get(node.id, node)


def _identity(value: ast.expr, defs: dict[str, ast.expr]) -> ast.expr:
    return _Expand(defs).visit(copy.deepcopy(value))  # type: ignore[no-any-return]  # an expression


def _targets(a: ast.Assign) -> list[str]:
    t = a.targets[0]
    return [e.id for e in t.elts if isinstance(e, ast.Name)] if isinstance(t, ast.Tuple) else \
        [t.id] if isinstance(t, ast.Name) else []


def joint_source(source: str) -> str:
    """Source of ``def dV_V(q)`` returning ``(dV(q), V(q))`` of the source of ``V`` and ``dV`` (module docstring)."""
    d, d_ret = _statements(source, "dV", "d_")
    v, v_ret = _statements(source, "V", "v_")
    alias: dict[str, str] = {}
    defs: dict[str, ast.expr] = {}                   # a local -> the expression it computes (of q)
    seen: dict[str, list[str]] = {}
    stmts: list[ast.Assign] = []
    groups: dict[tuple[str, str], list[int]] = {}     # the calls of a pair's functions on one argument
    for a in d + v:
        a.value = _Alias(alias).visit(a.value)
        ts = _targets(a)
        if isinstance(a.value, ast.Name) and len(ts) == 1:     # a copy
            alias[ts[0]] = a.value.id
            continue
        value = _identity(a.value, defs)
        text = ast.unparse(value)
        if text in seen and len(seen[text]) == len(ts):      # the same value computed before
            alias.update(zip(ts, seen[text]))
            continue
        seen[text] = ts
        defs.update({ts[0]: value} if len(ts) == 1 else
                    {t: ast.Subscript(value, ast.Constant(i), ast.Load()) for i, t in enumerate(ts)})
        call = a.value
        if isinstance(call, ast.Call) and _shared_call(call) and isinstance(call.func, ast.Name):
            pair = _PAIRS[call.func.id][0] if call.func.id in _PAIRS else call.func.id
            groups.setdefault((pair, ast.unparse(_identity(call.args[0], defs))), []).append(len(stmts))
        stmts.append(a)
    drop = set()
    for (pair, _), idx in groups.items():
        calls = [stmts[i].value for i in idx]
        if len({c.func.id for c in calls if isinstance(c, ast.Call) and isinstance(c.func, ast.Name)}) < 2:
            continue                                   # one function of the pair: nothing to share
        names = [f"j{idx[0]}_0", f"j{idx[0]}_1"]
        for i in idx:
            f = calls[idx.index(i)].func.id            # type: ignore[attr-defined]  # a call (grouped above)
            ts = _targets(stmts[i])
            alias.update(zip(ts, names) if f == pair else [(ts[0], names[_PAIRS[f][1]])])
            drop.add(i)
        arg = calls[0].args[0]                         # type: ignore[attr-defined]
        stmts[idx[0]] = ast.Assign([ast.Tuple([ast.Name(n, ast.Store()) for n in names], ast.Store())],
                                   ast.Call(ast.Name(pair, ast.Load()), [arg], []), lineno=0)
        drop.discard(idx[0])
    lines = [f"    {ast.unparse(_Alias(alias).visit(a))}" for i, a in enumerate(stmts) if i not in drop]
    ret = f"{ast.unparse(_Alias(alias).visit(d_ret))}, {ast.unparse(_Alias(alias).visit(v_ret))}"
    return "def dV_V(q):\n" + "\n".join([*lines, f"    return {ret}"]) + "\n"
